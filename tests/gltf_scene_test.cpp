// Scenes authored in glTF (pipeline/input/gltf_scene.h) against their JSON twins: every object field
// in node extras gives the same object as in a JSON scene, with the same errors; unknown and
// misspelt keys are warnings that name the key and the known fields; a node left out for
// near-misses is reported; and the file is parsed once however many objects it carries
// (pipeline/input/gltf_document.h), also when the file changes between reads.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "pipeline/input/gltf_document.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/scene.h"
#include "pipeline/input/scene_fields.h"
#include "temp_dir.h"

using namespace apparent;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A fresh folder for the files of one test, removed at the end.
class Folder {
public:
    Folder() {
        static int counter = 0;
        path_ = testio::tempPath() / ("apparent_gltf_scene_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~Folder() { fs::remove_all(path_); }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(file(name), std::ios::binary) << text;
        return file(name);
    }

private:
    fs::path path_;
};

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const uint32_t n = (uint32_t(bytes[i]) << 16) | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                           (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0);
        out += digits[(n >> 18) & 63];
        out += digits[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? digits[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? digits[n & 63] : '=';
    }
    return out;
}

// The tetrahedron (1,1,1), (-1,-1,1), (-1,1,-1), (1,-1,-1) as one glTF mesh: 4 float VEC3
// positions (48 bytes) then 12 unsigned-short indices (24 bytes), in a data: URI buffer.
json tetraGltf() {
    const float p[12] = {1, 1, 1, -1, -1, 1, -1, 1, -1, 1, -1, -1};
    const uint16_t idx[12] = {0, 1, 3, 0, 2, 1, 0, 3, 2, 1, 2, 3};
    std::vector<unsigned char> bytes(72);
    std::memcpy(bytes.data(), p, 48);
    std::memcpy(bytes.data() + 48, idx, 24);
    json g;
    g["asset"] = {{"version", "2.0"}};
    g["buffers"] = json::array({{{"byteLength", 72}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}});
    g["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                                    {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 24}}});
    g["accessors"] = json::array({{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"},
                                   {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}},
                                  {{"bufferView", 1}, {"componentType", 5123}, {"count", 12}, {"type", "SCALAR"}}});
    g["meshes"] = json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}})}}});
    g["nodes"] = json::array();
    g["scenes"] = json::array({{{"nodes", json::array()}}});
    g["scene"] = 0;
    return g;
}

// Adds a root node carrying the tetrahedron, with `extras` (skipped when null).
void addNode(json* g, const std::string& name, const std::array<double, 3>& translation, const json& extras) {
    json node = {{"name", name}, {"mesh", 0}, {"translation", translation}};
    if (!extras.is_null()) node["extras"] = extras;
    (*g)["scenes"][0]["nodes"].push_back((*g)["nodes"].size());
    (*g)["nodes"].push_back(node);
}

// The JSON twin of one object node: the same fields, plus name, mesh and position.
std::string jsonTwin(const Folder& dir, const json& fields, const std::array<double, 3>& position) {
    std::ofstream(dir.file("tetra.obj")) << "v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\nf 1 2 4\nf 1 3 2\nf 1 4 3\nf 2 3 4\n";
    json obj = fields;
    obj["name"] = "thing";
    obj["mesh"] = "tetra.obj";
    obj["position"] = position;
    return dir.write("twin.json", json({{"objects", json::array({obj})}}).dump());
}

// The one-object glTF scene with those fields in the node's extras.
std::string gltfScene(const Folder& dir, const json& fields, const std::array<double, 3>& position,
                      const json& scene_extras = nullptr) {
    json g = tetraGltf();
    addNode(&g, "thing", position, fields);
    if (!scene_extras.is_null()) g["scenes"][0]["extras"] = scene_extras;
    return dir.write("scene.gltf", g.dump());
}

bool contains(const std::vector<std::string>& lines, const std::string& a, const std::string& b = "") {
    for (const auto& l : lines)
        if (l.find(a) != std::string::npos && l.find(b) != std::string::npos) return true;
    return false;
}

std::string joined(const std::vector<std::string>& lines) {
    std::string s;
    for (const auto& l : lines) s += l + "\n";
    return s;
}

// The problem part of "file: field path: problem".
std::string problemOf(const std::string& message, const std::string& field_path) {
    const auto at = message.find(field_path + ": ");
    return at == std::string::npos ? "(no " + field_path + " in: " + message + ")" : message.substr(at + field_path.size() + 2);
}

}  // namespace

// The object fields a glTF node does not give itself, each set in node extras, give the object
// the JSON scene gives. Speeds stated exactly move the object (the bug: gamma, rapidity and
// direction were dropped, leaving the object at rest).
TEST(GltfScene, EveryObjectFieldInExtrasGivesTheJsonObject) {
    const std::vector<json> cases = {
        {{"velocity", {0.5, 0.25, -0.125}}},
        {{"direction", {0, 0, 2}}, {"gamma", 1e7}},
        {{"direction", {1, 1, 0}}, {"rapidity", 1.5}, {"t0", -3}},
        {{"t0", 2.5}},
        {{"rotation_deg", {10, 20, 30}}, {"velocity", {0, 0, 0}}},
        {{"scale", {1, 2, 3}}, {"t0", 0}},
        {{"scale", 0.5}, {"t0", 0}},
        {{"mirror", true}},
        {{"exists", {nullptr, 5}}, {"velocity", {0.1, 0, 0}}},
        {{"exists", {-1, 2.5}}, {"t0", 1}},
        {{"angular_velocity", {0, 0.5, -0.25}}, {"velocity", {0.3, 0, 0}}},
        {{"acceleration", {0.5, 0, 0.25}}, {"velocity", {0, 0.3, 0}}},
        {{"orbit", {{"center", {1, 0, 0}}, {"axis", {0, 0, 2}}, {"speed", 0.5}, {"orientation", "locked"}}}},
        {{"color", {0.9, 0.1, 0.2}}},
        {{"material", {{"base_color", {0.1, 0.2, 0.3, 0.5}}, {"metallic", 1}, {"roughness", 0.25}, {"emissive", {0, 0.5, 1}}}}},
    };
    // Every key of the table that a node does not give itself is covered by a case above.
    for (const std::string& key : objectMarkerKeys()) {
        bool covered = false;
        for (const json& c : cases) covered = covered || c.contains(key);
        EXPECT_TRUE(covered) << "no case sets " << key;
    }
    const std::array<double, 3> position{3, -2, 1.5};
    for (const json& fields : cases) {
        Folder dir;
        Scene js, gs;
        const Status jst = loadScene(jsonTwin(dir, fields, position), &js);
        const Status gst = loadScene(gltfScene(dir, fields, position), &gs);
        ASSERT_TRUE(jst.ok) << jst.message;
        ASSERT_TRUE(gst.ok) << gst.message;
        EXPECT_TRUE(gs.warnings.empty()) << joined(gs.warnings);
        ASSERT_EQ(gs.objects.size(), 1u);
        const ObjectSpec &j = js.objects[0], &g = gs.objects[0];
        SCOPED_TRACE(fields.dump());
        EXPECT_EQ(g.name, j.name);
        EXPECT_EQ(g.position, j.position);
        EXPECT_EQ(g.t0, j.t0);
        EXPECT_EQ(g.velocity, j.velocity);
        EXPECT_EQ(g.speed, j.speed);
        EXPECT_EQ(g.direction, j.direction);
        EXPECT_EQ(g.gamma, j.gamma);
        EXPECT_EQ(g.rapidity, j.rapidity);
        EXPECT_EQ(g.rotation_deg, j.rotation_deg);
        EXPECT_EQ(g.scale, j.scale);
        EXPECT_EQ(g.exists_from, j.exists_from);
        EXPECT_EQ(g.exists_to, j.exists_to);
        EXPECT_EQ(g.mirror, j.mirror);
        EXPECT_EQ(g.angular_velocity, j.angular_velocity);
        EXPECT_EQ(g.acceleration, j.acceleration);
        EXPECT_EQ(g.material.given, j.material.given);
        EXPECT_EQ(g.material.base_color, j.material.base_color);
        EXPECT_EQ(g.material.metallic, j.material.metallic);
        EXPECT_EQ(g.material.roughness, j.material.roughness);
        EXPECT_EQ(g.material.emissive, j.material.emissive);
        ASSERT_EQ(bool(g.kinds.orbit), bool(j.kinds.orbit));
        if (g.kinds.orbit) {
            EXPECT_EQ(g.kinds.orbit->center, j.kinds.orbit->center);
            EXPECT_EQ(g.kinds.orbit->axis, j.kinds.orbit->axis);
            EXPECT_EQ(g.kinds.orbit->speed, j.kinds.orbit->speed);
            EXPECT_EQ(g.kinds.orbit->locked, j.kinds.orbit->locked);
            EXPECT_TRUE(g.kinds.orbit->locked);
        }
        EXPECT_NE(g.mesh_path.find("scene.gltf#thing"), std::string::npos) << g.mesh_path;
    }
    // Independently of the JSON reader: gamma = 1e7 along +z is b = sqrt(1 - 1e-14), and
    // rapidity 1.5 along (1, 1, 0) is b = tanh(1.5) split over x and y.
    Folder dir;
    Scene s;
    ASSERT_TRUE(loadScene(gltfScene(dir, cases[1], position), &s).ok);
    EXPECT_EQ(s.objects[0].speed, ObjectSpec::Speed::Gamma);
    EXPECT_NEAR(s.objects[0].velocity.z, std::sqrt(1 - 1e-14), 1e-15);
    ASSERT_TRUE(loadScene(gltfScene(dir, cases[2], position), &s).ok);
    EXPECT_EQ(s.objects[0].speed, ObjectSpec::Speed::Rapidity);
    EXPECT_NEAR(s.objects[0].velocity.x, std::tanh(1.5) / std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(s.objects[0].velocity.y, std::tanh(1.5) / std::sqrt(2.0), 1e-15);
    EXPECT_EQ(s.objects[0].t0, -3);
}

// Bad values in extras are refused with the JSON scene's message, at the node's extras path.
TEST(GltfScene, BadFieldsInExtrasGiveTheJsonErrors) {
    const std::vector<std::pair<json, std::string>> cases = {
        {{{"direction", {1, 0, 0}}, {"gamma", 0.5}}, "gamma"},
        {{{"direction", {1, 0, 0}}, {"rapidity", 40}}, "rapidity"},
        {{{"velocity", {0.5, 0, 0}}, {"gamma", 2}}, "velocity"},
        {{{"gamma", 2}}, "direction"},
        {{{"direction", {0, 0, 0}}, {"gamma", 2}}, "direction"},
        {{{"t0", "soon"}}, "t0"},
        {{{"velocity", {0.5, 0}}}, "velocity"},
        {{{"scale", 0}, {"t0", 0}}, "scale"},
        {{{"rotation_deg", {1, 2, "x"}}, {"t0", 0}}, "rotation_deg[2]"},
        {{{"mirror", "yes"}}, "mirror"},
        {{{"mirror", true}, {"velocity", {0.1, 0, 0}}}, "mirror"},
        {{{"exists", {3, 1}}}, "exists"},
        {{{"exists", 4}}, "exists"},
    };
    for (const auto& [fields, field] : cases) {
        SCOPED_TRACE(fields.dump());
        Folder dir;
        Scene js, gs;
        const Status jst = loadScene(jsonTwin(dir, fields, {0, 0, 0}), &js);
        const Status gst = loadScene(gltfScene(dir, fields, {0, 0, 0}), &gs);
        ASSERT_FALSE(jst.ok);
        ASSERT_FALSE(gst.ok);
        EXPECT_EQ(gst.message.find('\n'), std::string::npos);
        EXPECT_EQ(problemOf(gst.message, "nodes[0].extras." + field), problemOf(jst.message, "objects[0]." + field))
            << gst.message << "\n" << jst.message;
    }
}

// Misspelt and unknown keys in an object node's or the scene's extras are warnings that name the
// key, the field it resembles and the known fields; the scene still loads. Keys a node gives
// itself (name, mesh, position) are ignored with a warning.
TEST(GltfScene, UnknownAndMisspeltExtrasKeysAreWarnings) {
    Folder dir;
    Scene s;
    const json fields = {{"velocity", {0.25, 0, 0}}, {"velocty", {0.5, 0, 0}}, {"blender_id", 7}, {"position", {9, 9, 9}},
                         {"_note", "comments are fine"}};
    const json scene_extras = {{"modle", "finite"}, {"frames", {{"start", 0}, {"end", 2}, {"fps", 5}}}};
    const Status st = loadScene(gltfScene(dir, fields, {1, 2, 3}, scene_extras), &s);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(s.objects[0].velocity, (mesh4d::Vec3{0.25, 0, 0}));
    EXPECT_EQ(s.objects[0].position, (mesh4d::Vec3{1, 2, 3}));
    EXPECT_EQ(s.model, Model::Relativistic);  // "modle" is not read
    EXPECT_EQ(frameCount(s.frames), 10);
    const std::string w = joined(s.warnings);
    EXPECT_EQ(s.warnings.size(), 4u) << w;
    EXPECT_TRUE(contains(s.warnings, "scene.gltf: nodes[0].extras.velocty: unknown field, ignored (did you mean velocity?)",
                         "known fields: name, mesh, position, t0, velocity, direction, gamma, rapidity, rotation_deg, scale, mirror, exists"))
        << w;
    EXPECT_TRUE(contains(s.warnings, "nodes[0].extras.blender_id: unknown field, ignored; known fields: name")) << w;
    EXPECT_TRUE(contains(s.warnings, "nodes[0].extras.position: ignored", "world translation")) << w;
    EXPECT_TRUE(contains(s.warnings, "scenes[0].extras.modle: unknown field, ignored (did you mean model?)",
                         "known fields: frames, light, model, tolerance"))
        << w;
    // A JSON scene refuses the same typo, with the same suggestion.
    Scene js;
    const Status jst = loadScene(jsonTwin(dir, {{"velocty", {0.5, 0, 0}}}, {0, 0, 0}), &js);
    ASSERT_FALSE(jst.ok);
    EXPECT_NE(jst.message.find("objects[0].velocty: unknown field (did you mean velocity?; known: name, mesh,"),
              std::string::npos)
        << jst.message;
}

// A node whose extras hold only near-misses of object fields is not an object, and says so; a
// file where that leaves no object is refused with the near-miss in the message.
TEST(GltfScene, NodeWithOnlyMisspeltObjectFieldsIsReported) {
    Folder dir;
    json g = tetraGltf();
    addNode(&g, "good", {0, 0, 0}, {{"velocity", {0.1, 0, 0}}});
    addNode(&g, "typo", {5, 0, 0}, {{"Velocity", {0.5, 0, 0}}, {"exist", {0, 1}}});
    addNode(&g, "plain", {9, 0, 0}, {{"author", "someone"}});  // other tools' properties: silent
    Scene s;
    const Status st = loadScene(dir.write("two.gltf", g.dump()), &s);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(s.objects[0].name, "good");
    const std::string w = joined(s.warnings);
    EXPECT_EQ(s.warnings.size(), 2u) << w;
    EXPECT_TRUE(contains(s.warnings, "nodes[1].extras.Velocity: looks like the object field velocity", "not an object")) << w;
    EXPECT_TRUE(contains(s.warnings, "nodes[1].extras.exist: looks like the object field exists", "not an object")) << w;

    json only = tetraGltf();
    addNode(&only, "typo", {5, 0, 0}, {{"velocty", {0.5, 0, 0}}});
    const Status none = loadScene(dir.write("none.gltf", only.dump()), &s);
    ASSERT_FALSE(none.ok);
    EXPECT_NE(none.message.find("nodes: no node carries object extras"), std::string::npos) << none.message;
    EXPECT_NE(none.message.find("nodes[0].extras.velocty looks like a misspelt velocity"), std::string::npos) << none.message;
}

// A glTF scene of 3000 object nodes (about 300 KB) is parsed once, not once per object: loading
// the scene and then every object's mesh, as the render command does, reads the file once.
TEST(GltfScene, ThreeThousandObjectNodesParseTheFileOnce) {
    Folder dir;
    json g = tetraGltf();
    for (int i = 0; i < 3000; ++i)
        addNode(&g, "object-" + std::to_string(i), {double(i % 60) * 3, double(i / 60) * 3, -50},
                {{"velocity", {0.001 * (i % 7), 0, 0}}, {"t0", 0.5 * (i % 3)}, {"exists", {nullptr, 10 + i}}});
    const std::string path = dir.write("many.gltf", g.dump());
    EXPECT_GT(fs::file_size(path), 250'000u);
    const size_t parses_before = gltfParseCount();
    const auto start = std::chrono::steady_clock::now();
    Scene s;
    const Status st = loadScene(path, &s);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(s.objects.size(), 3000u);
    for (const ObjectSpec& o : s.objects) {
        LoadedMesh m;
        MeshWarnings w;
        const Status ms = readMesh(o.mesh_path, {}, &m, &w);
        ASSERT_TRUE(ms.ok) << ms.message;
        ASSERT_EQ(m.mesh.triangles.size(), 4u);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(gltfParseCount() - parses_before, 1u);
    std::cout << "3000 object nodes, " << fs::file_size(path) << " bytes: scene and meshes loaded in " << seconds << " s\n";
    EXPECT_EQ(s.objects[2999].exists_to, 10 + 2999);
}

// The cache never serves stale data: a file rewritten with different bytes of the same size, and
// an external buffer changed under an unchanged .gltf, are parsed again.
TEST(GltfScene, ChangedFilesAreParsedAgain) {
    Folder dir;
    json g = tetraGltf();
    addNode(&g, "a", {0, 0, 0}, {{"t0", 1}});
    const std::string path = dir.write("s.gltf", g.dump());
    Scene s;
    ASSERT_TRUE(loadScene(path, &s).ok);
    const size_t n = gltfParseCount();
    ASSERT_TRUE(loadScene(path, &s).ok);
    EXPECT_EQ(gltfParseCount(), n);  // unchanged: served from the cache
    g["nodes"][0]["extras"]["t0"] = 7;  // same length
    dir.write("s.gltf", g.dump());
    ASSERT_TRUE(loadScene(path, &s).ok);
    EXPECT_EQ(gltfParseCount(), n + 1);
    EXPECT_EQ(s.objects[0].t0, 7);

    // An external buffer: the positions scaled by 2 (same size), the .gltf untouched.
    const std::string fixture = std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/gltf/";
    fs::copy_file(fixture + "triangle.gltf", dir.file("triangle.gltf"));
    fs::copy_file(fixture + "triangle.bin", dir.file("triangle.bin"));
    LoadedMesh before, after;
    MeshWarnings w;
    ASSERT_TRUE(readMesh(dir.file("triangle.gltf"), {}, &before, &w).ok);
    std::vector<float> bin(fs::file_size(dir.file("triangle.bin")) / 4);
    {
        std::ifstream in(dir.file("triangle.bin"), std::ios::binary);
        in.read(reinterpret_cast<char*>(bin.data()), std::streamsize(bin.size() * 4));
    }
    for (size_t i = 0; i < 9 && i < bin.size(); ++i) bin[i] *= 2;  // the 3 positions come first
    {
        std::ofstream out(dir.file("triangle.bin"), std::ios::binary);
        out.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size() * 4));
    }
    ASSERT_TRUE(readMesh(dir.file("triangle.gltf"), {}, &after, &w).ok);
    ASSERT_EQ(after.mesh.positions.size(), before.mesh.positions.size());
    // Vertex 0 is the local origin, so the node's translation cancels in the differences.
    for (size_t i = 0; i < before.mesh.positions.size(); ++i)
        EXPECT_EQ(after.mesh.positions[i] - after.mesh.positions[0], (before.mesh.positions[i] - before.mesh.positions[0]) * 2.0) << i;
}

// camera.velocity in a glTF-authored scene: the camera node's extras (glTF's axes, like every
// vector in extras), read as the JSON scene's camera.velocity; an impossible one is refused.
TEST(GltfScene, CameraNodeExtrasGiveTheCameraVelocity) {
    Folder dir;
    json g = tetraGltf();
    addNode(&g, "thing", {0, 0, -5}, json{{"velocity", {0.5, 0, 0}}});
    g["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}}});
    g["scenes"][0]["nodes"].push_back(g["nodes"].size());
    g["nodes"].push_back({{"name", "cam"}, {"camera", 0}, {"extras", {{"velocity", {0, 0.25, -0.5}}}}});
    Scene scene;
    Status st = loadScene(dir.write("scene.gltf", g.dump()), &scene);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(scene.camera.velocity, (mesh4d::Vec3{0, 0.25, -0.5}));
    g["nodes"].back()["extras"]["velocity"] = {0, 1.5, 0};
    st = loadScene(dir.write("scene.gltf", g.dump()), &scene);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find(".velocity: |velocity| = 1.5 must be < 1 (the speed of light)"), std::string::npos) << st.message;
}

// The camera node's extras look_at and up (the web file writes them, pipeline/run/web_file.h) are
// the camera's as written when they look the way the node does: an up that is not orthogonal to
// the view stays as given (the default light follows it); one that turns the view is a warning.
TEST(GltfScene, CameraNodeExtrasKeepLookAtAndUp) {
    Folder dir;
    json g = tetraGltf();
    addNode(&g, "thing", {0, 0, -5}, json{{"velocity", {0.5, 0, 0}}});
    g["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}}});
    g["scenes"][0]["nodes"].push_back(g["nodes"].size());
    // The node at (1, 2, 3) looks down its -Z (no rotation): look_at (1, 2, -7) and up (0, 1, 1).
    g["nodes"].push_back({{"name", "cam"}, {"camera", 0}, {"translation", {1, 2, 3}},
                          {"extras", {{"look_at", {1, 2, -7}}, {"up", {0, 1, 1}}}}});
    Scene scene;
    Status st = loadScene(dir.write("scene.gltf", g.dump()), &scene);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(scene.camera.look_at, (mesh4d::Vec3{1, 2, -7}));
    EXPECT_EQ(scene.camera.up, (mesh4d::Vec3{0, 1, 1}));
    EXPECT_TRUE(scene.warnings.empty());
    // The default light is overhead along the given up, normalised: (0, 1, 1) / sqrt(2).
    EXPECT_NEAR(scene.light.direction.y, std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(scene.light.direction.z, std::sqrt(0.5), 1e-15);
    // Looking along +X instead: ignored, with a warning; the node's view stays.
    g["nodes"].back()["extras"]["look_at"] = {5, 2, 3};
    st = loadScene(dir.write("scene.gltf", g.dump()), &scene);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(scene.camera.look_at, (mesh4d::Vec3{1, 2, 2}));
    EXPECT_EQ(scene.camera.up, (mesh4d::Vec3{0, 1, 0}));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("look_at and up ignored"), std::string::npos) << scene.warnings[0];
}
