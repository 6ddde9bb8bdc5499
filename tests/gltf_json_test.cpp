// The .glb's JSON writer (exporters/gltf_json.h): its text is nlohmann's dump() of the same
// document (parsed by nlohmann and dumped again, the text comes back unchanged: keys in byte order
// at every level, nlohmann's number and string forms), every field holds the value put in, and the
// fields glTF leaves optional are left out as tinygltf left them out (a zero byteOffset, a
// byteStride below 4; integer min/max for integer components).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <nlohmann/json.hpp>

#include "exporters/gltf_json.h"

using namespace apparent::gltfjson;

namespace {

// A document of every record kind, with the optional fields on and off.
std::string sampleDocument() {
    Text t;
    t.open('{');
    t.key("accessors");
    t.open('[');
    Accessor positions;
    positions.view = 0;
    positions.component = 5126;  // FLOAT
    positions.vec3 = true;
    positions.count = 3;
    positions.bounds = 3;
    const double lo[3] = {-0.5, 1e-7, -0.0}, hi[3] = {2.0, 0.1f, 1.0 / 3.0};
    std::copy(lo, lo + 3, positions.min);
    std::copy(hi, hi + 3, positions.max);
    write(&t, positions);
    Accessor quantized;  // SHORT: integer bounds; at an offset; normalized
    quantized.view = 1;
    quantized.component = 5122;
    quantized.vec3 = true;
    quantized.count = 7;
    quantized.offset = 16;
    quantized.normalized = true;
    quantized.bounds = 3;
    const double qlo[3] = {-32767, -2, 0}, qhi[3] = {32767, 5, 1};
    std::copy(qlo, qlo + 3, quantized.min);
    std::copy(qhi, qhi + 3, quantized.max);
    write(&t, quantized);
    Accessor draco;  // no view, scalar, no bounds
    draco.component = 5125;
    draco.count = 12;
    write(&t, draco);
    t.close(']');
    t.key("bufferViews");
    t.open('[');
    BufferView plain;
    plain.length = 36;
    plain.target = 34962;
    write(&t, plain);
    BufferView meshopt;
    meshopt.buffer = 1;
    meshopt.offset = 40;
    meshopt.length = 112;
    meshopt.stride = 16;
    meshopt.target = 34962;
    meshopt.meshopt = true;
    meshopt.ext = {8, 57, 16, 7, false, true};
    write(&t, meshopt);
    BufferView indices;
    indices.buffer = 1;
    indices.offset = 152;
    indices.length = 24;
    indices.stride = 2;  // below 4: not written
    indices.target = 34963;
    indices.meshopt = true;
    indices.ext = {68, 9, 2, 12, true, false};
    write(&t, indices);
    t.close(']');
    t.key("meshes");
    t.open('[');
    Mesh mesh;
    mesh.name = "frame_00001";
    Primitive p;
    p.attributes[kPosition] = 0;
    p.attributes[kNormal] = 1;
    p.attributes[kEmissionTime] = 2;
    p.attributes[kColor0] = 3;
    p.indices = 4;
    p.material = 0;
    std::array<int, kAttributes> target;
    target.fill(-1);
    target[kPosition] = 5;
    target[kNormal] = 6;
    target[kEmissionTime] = 7;
    p.targets = {target, target};
    mesh.primitives.push_back(p);
    Primitive coded;
    coded.attributes[kPosition] = 8;
    coded.attributes[kDoppler] = 9;
    coded.attributes[kProperTime] = 10;
    coded.indices = 11;
    coded.draco_view = 2;
    coded.draco_ids[kPosition] = 0;
    coded.draco_ids[kDoppler] = 3;
    coded.draco_ids[kProperTime] = 4;
    mesh.primitives.push_back(coded);
    write(&t, mesh);
    t.close(']');
    t.key("nodes");
    t.open('[');
    Node camera;
    camera.name = "camera";
    camera.camera = 0;
    camera.has_translation = camera.has_rotation = true;
    camera.translation[0] = 1e21;
    camera.rotation[3] = 0.7071067811865476;
    write(&t, camera);
    Node frame;
    frame.name = "frame_00001";
    frame.mesh = 0;
    frame.has_scale = true;
    frame.scale[0] = frame.scale[1] = frame.scale[2] = 0.0009765625;
    frame.children = {3};
    frame.weights = {1, 1, 0};
    write(&t, frame);
    Node reflection;
    reflection.name = "frame_00001 mirror \"back\\drop\"\t\x01";
    reflection.mesh = 1;
    reflection.has_mirror = true;
    reflection.mirror = "Spiegel \xc3\xa4";
    write(&t, reflection);
    t.close(']');
    t.key("scene");
    t.value(0);
    t.close('}');
    return t.out;
}

}  // namespace

TEST(GltfJson, TextIsNlohmannsDumpOfTheSameDocument) {
    const std::string text = sampleDocument();
    const nlohmann::json j = nlohmann::json::parse(text);
    EXPECT_EQ(j.dump(), text);
}

TEST(GltfJson, FieldsHoldTheirValuesAndOptionalOnesFollowGltf) {
    const nlohmann::json j = nlohmann::json::parse(sampleDocument());
    const auto& acc = j["accessors"];
    EXPECT_EQ(acc[0]["type"], "VEC3");
    EXPECT_EQ(acc[0]["min"][0].get<double>(), -0.5);
    EXPECT_EQ(acc[0]["min"][1].get<double>(), 1e-7);
    EXPECT_TRUE(std::signbit(acc[0]["min"][2].get<double>()));
    EXPECT_EQ(acc[0]["max"][1].get<double>(), double(0.1f));
    EXPECT_EQ(acc[0]["max"][2].get<double>(), 1.0 / 3.0);
    EXPECT_FALSE(acc[0].contains("byteOffset"));  // 0: left out
    EXPECT_FALSE(acc[0].contains("normalized"));
    EXPECT_TRUE(acc[1]["min"][0].is_number_integer());  // SHORT: integers
    EXPECT_EQ(acc[1]["min"][0].get<int>(), -32767);
    EXPECT_EQ(acc[1]["max"][1].get<int>(), 5);
    EXPECT_EQ(acc[1]["byteOffset"].get<int>(), 16);
    EXPECT_EQ(acc[1]["normalized"], true);
    EXPECT_FALSE(acc[2].contains("bufferView"));
    EXPECT_FALSE(acc[2].contains("min"));
    EXPECT_EQ(acc[2]["type"], "SCALAR");
    const auto& views = j["bufferViews"];
    EXPECT_FALSE(views[0].contains("byteOffset"));
    EXPECT_FALSE(views[0].contains("byteStride"));
    EXPECT_EQ(views[1]["byteStride"].get<int>(), 16);
    const auto& ext = views[1]["extensions"]["EXT_meshopt_compression"];
    EXPECT_EQ(ext["buffer"].get<int>(), 0);
    EXPECT_EQ(ext["byteOffset"].get<int>(), 8);
    EXPECT_EQ(ext["byteLength"].get<int>(), 57);
    EXPECT_EQ(ext["count"].get<int>(), 7);
    EXPECT_EQ(ext["filter"], "OCTAHEDRAL");
    EXPECT_EQ(ext["mode"], "ATTRIBUTES");
    EXPECT_FALSE(views[2].contains("byteStride"));  // 2 < 4
    EXPECT_EQ(views[2]["extensions"]["EXT_meshopt_compression"]["byteStride"].get<int>(), 2);
    EXPECT_EQ(views[2]["extensions"]["EXT_meshopt_compression"]["mode"], "TRIANGLES");
    EXPECT_FALSE(views[2]["extensions"]["EXT_meshopt_compression"].contains("filter"));
    const auto& prims = j["meshes"][0]["primitives"];
    EXPECT_EQ(prims[0]["attributes"], nlohmann::json({{"POSITION", 0}, {"NORMAL", 1}, {"_EMISSION_TIME", 2}, {"COLOR_0", 3}}));
    EXPECT_EQ(prims[0]["targets"][1], nlohmann::json({{"POSITION", 5}, {"NORMAL", 6}, {"_EMISSION_TIME", 7}}));
    EXPECT_EQ(prims[0]["mode"].get<int>(), 4);
    EXPECT_FALSE(prims[1].contains("material"));
    EXPECT_EQ(prims[1]["extensions"]["KHR_draco_mesh_compression"],
              nlohmann::json({{"bufferView", 2}, {"attributes", {{"POSITION", 0}, {"_DOPPLER", 3}, {"_PROPER_TIME", 4}}}}));
    const auto& nodes = j["nodes"];
    EXPECT_EQ(nodes[0]["translation"][0].get<double>(), 1e21);
    EXPECT_EQ(nodes[0]["rotation"][3].get<double>(), 0.7071067811865476);
    EXPECT_FALSE(nodes[0].contains("scale"));
    EXPECT_FALSE(nodes[0].contains("mesh"));
    EXPECT_EQ(nodes[1]["weights"], nlohmann::json({1, 1, 0}));
    EXPECT_EQ(nodes[1]["scale"][2].get<double>(), 0.0009765625);
    EXPECT_EQ(nodes[2]["name"], "frame_00001 mirror \"back\\drop\"\t\x01");
    EXPECT_EQ(nodes[2]["extras"]["mirror"], "Spiegel \xc3\xa4");
}

// Numbers and strings alone, against nlohmann's dump of the same value.
TEST(GltfJson, NumbersAndStringsAsNlohmannWritesThem) {
    std::mt19937_64 rng(7);
    std::vector<double> values = {0.0, -0.0, 1.0, 2.0, 0.8, 1e-5, 1e-300, 1e300, 123456789012345678.0,
                                  std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max(),
                                  std::nan(""), std::numeric_limits<double>::infinity()};
    for (int i = 0; i < 2000; ++i) {
        const double mantissa = std::uniform_real_distribution<double>(-1, 1)(rng);
        values.push_back(std::ldexp(mantissa, std::uniform_int_distribution<int>(-80, 80)(rng)));
        values.push_back(double(float(values.back())));
    }
    for (const double v : values) {
        Text t;
        t.value(v);
        EXPECT_EQ(t.out, nlohmann::json(v).dump()) << v;
    }
    for (const int64_t v : {int64_t(0), int64_t(-1), int64_t(-32768), int64_t(1) << 40}) {
        Text t;
        t.value(v);
        EXPECT_EQ(t.out, nlohmann::json(v).dump());
    }
    std::string every_ascii;
    for (int c = 1; c < 128; ++c) every_ascii += char(c);
    for (const std::string& s : {std::string(), every_ascii, std::string("a\"b\\c/d"), std::string("\xe2\x82\xac 5")}) {
        Text t;
        t.value(s);
        EXPECT_EQ(t.out, nlohmann::json(s).dump());
    }
}
