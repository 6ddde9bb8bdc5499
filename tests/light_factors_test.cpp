// The per-vertex Doppler factor and proper time (mesh4d/light_factors.h), read back from the PLY
// frames `apparent render` writes, against closed forms computed here from the written positions
// and emission times: the line-of-sight factors sqrt((1 + b)/(1 - b)) and sqrt((1 - b)/(1 + b)),
// the transverse 1/g, the classical 1/(1 - b) of the finite model, 1 on the hyperplanes, and the
// clock reading (t_e - t0)/g - g v.z of uniform motion.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <tiny_gltf.h>

#include "mesh4d/event.h"
#include "run_command.h"
#include "temp_dir.h"

using mesh4d::Vec3;
using testcli::apparentRun;
using testcli::CommandResult;
namespace fs = std::filesystem;

namespace {

struct PlyVertex {
    Vec3 x;
    double t = 0, doppler = 0, proper_time = 0;
};

// Reads a binary PLY frame with x y z quality doppler proper_time (doubles, little-endian) and the
// object index (uchar: one object).
std::vector<PlyVertex> readFrame(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t end = bytes.find("end_header\n");
    EXPECT_NE(end, std::string::npos);
    const std::string header = bytes.substr(0, end);
    EXPECT_NE(header.find("property double quality\nproperty double doppler\nproperty double proper_time\nproperty uchar object\n"),
              std::string::npos)
        << header;
    const size_t n = std::stoul(header.substr(header.find("element vertex ") + 15));
    std::vector<PlyVertex> v(n);
    for (size_t i = 0; i < n; ++i) {
        double d[6];
        std::memcpy(d, bytes.data() + end + 11 + 49 * i, 48);  // the test machine is little-endian
        v[i] = {{d[0], d[1], d[2]}, d[3], d[4], d[5]};
    }
    return v;
}

// Renders a one-object scene (a box of edge `size`) to PLY and returns frame 0's vertices.
std::vector<PlyVertex> render(const std::string& name, const std::string& model, double size, const std::string& object_fields,
                              double t_c) {
    const fs::path dir = testio::tempPath() / ("apparent_light_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(testcli::source("data/meshes/box.obj"), dir / "box.obj");
    std::ofstream(dir / "scene.json") << R"({ "frames": { "start": )" << t_c << R"(, "end": )" << t_c + 0.05
                                      << R"(, "fps": 10 }, "model": ")" << model << R"(", "tolerance": "vertex",
        "objects": [ { "mesh": "box.obj", "scale": )" << size << ", " << object_fields << " } ] }";
    const CommandResult r =
        apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "out").string(), "--format", "ply", "--quiet"});
    EXPECT_EQ(r.code, 0) << r.err;
    std::vector<PlyVertex> v = readFrame(dir / "out" / model / "frame_00000.ply");
    fs::remove_all(dir);
    return v;
}

}  // namespace

TEST(LightFactors, LineOfSightDopplerIsTheClosedForm) {
    const double b = 0.9;
    // A box of edge 1e-4 on the -z axis moving towards the camera, then away from it: every
    // vertex sees the camera within 1e-5 rad of the velocity, so D is the on-axis value to 1e-8.
    for (const auto& [sign, expected] : {std::pair{1.0, std::sqrt((1 + b) / (1 - b))}, std::pair{-1.0, std::sqrt((1 - b) / (1 + b))}}) {
        const auto v = render(sign > 0 ? "approach" : "recede", "relativistic", 1e-4,
                              R"("position": [0, 0, -10], "velocity": [0, 0, )" + std::to_string(sign * b) + "]", 0);
        ASSERT_EQ(v.size(), 8u);
        for (const auto& p : v) EXPECT_NEAR(p.doppler / expected, 1.0, 1e-8) << "sign " << sign;
    }
    // The finite model (light at c in the lab, camera at rest): the classical 1/(1 - b).
    const auto f = render("classical", "finite", 1e-4, R"("position": [0, 0, -10], "velocity": [0, 0, 0.5])", 0);
    for (const auto& p : f) EXPECT_NEAR(p.doppler, 2.0, 1e-8);
    // No light travel on the hyperplanes: 1.
    for (const char* model : {"instant", "contracted"}) {
        const auto h = render(std::string("plane_") + model, model, 1e-4, R"("position": [0, 0, -10], "velocity": [0, 0, 0.5])", 0);
        for (const auto& p : h) EXPECT_EQ(p.doppler, 1.0) << model;
    }
}

// Light emitted at right angles to the velocity (in the camera's frame): D = 1/g. A box of edge
// 1e-6 passing x = 0 at t = 0, 4 ls below the camera along -z, is seen at t_c = 4.
TEST(LightFactors, TransverseDopplerIsOneOverGamma) {
    const double b = 0.8, g = 1 / std::sqrt(1 - b * b);
    const auto v = render("transverse", "relativistic", 1e-6, R"("position": [0, 0, -4], "velocity": [0.8, 0, 0])", 4);
    ASSERT_EQ(v.size(), 8u);
    for (const auto& p : v) {
        EXPECT_NEAR(p.doppler * g, 1.0, 1e-6);
        EXPECT_NEAR(p.x.x, 0.0, 1e-6);  // the emission was at x = 0
    }
}

// Every vertex, any direction: D = sqrt(1 - b^2) / (1 - b cos t), t between the velocity and the
// direction from the written position to the camera; and the clock (t_e - t0)/g - g v.z, z the
// offset of the written position from the origin's worldline at the written emission time.
TEST(LightFactors, EveryVertexMatchesTheTextbookFormsAndTheClock) {
    const Vec3 vel{0.3, -0.5, 0.6};
    const double b2 = mesh4d::dot(vel, vel), g = 1 / std::sqrt(1 - b2), t0 = 2;
    const Vec3 x0{-3, 2, -6};
    const auto v = render("oblique", "relativistic", 1.5,
                          R"("position": [-3, 2, -6], "t0": 2, "velocity": [0.3, -0.5, 0.6], "rotation_deg": [10, 20, 30])", 3);
    ASSERT_EQ(v.size(), 8u);
    for (const auto& p : v) {
        const Vec3 to_camera = Vec3{0, 0, 0} - p.x;
        const double cos_t = mesh4d::dot(vel, to_camera) / (std::sqrt(b2) * mesh4d::norm(to_camera));
        EXPECT_NEAR(p.doppler, std::sqrt(1 - b2) / (1 - std::sqrt(b2) * cos_t), 1e-12 * p.doppler);
        const Vec3 z = p.x - (x0 + vel * (p.t - t0));
        EXPECT_NEAR(p.proper_time, (p.t - t0) / g - g * mesh4d::dot(vel, z), 1e-12 * (1 + std::fabs(p.t)));
    }
}

// --attributes doppler,proper_time: the .glb's _DOPPLER and _PROPER_TIME hold the PLY frame's
// values in float32 (the crease split repeats vertices, so the sets of values are compared), plain
// and in Draco's attribute map; with meshopt the attribute asked for is there and no other.
TEST(LightFactors, GlbAttributesHoldThePlyValues) {
    const fs::path dir = testio::tempPath() / ("apparent_light_glb_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(testcli::source("data/meshes/box.obj"), dir / "box.obj");
    std::ofstream(dir / "scene.json") << R"({ "frames": { "start": 3, "end": 3.05, "fps": 10 }, "tolerance": "vertex",
        "objects": [ { "mesh": "box.obj", "position": [-3, 2, -6], "velocity": [0.3, -0.5, 0.6] } ] })";
    CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "plain").string(), "--format",
                                   "glb,ply", "--attributes", "doppler,proper_time", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    const auto ply = readFrame(dir / "plain/relativistic/frame_00000.ply");
    std::set<float> want_d, want_t;
    for (const auto& p : ply) {
        want_d.insert(float(p.doppler));
        want_t.insert(float(p.proper_time));
    }
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, (dir / "plain/relativistic.glb").string())) << err;
    auto values = [&](int accessor) {
        const tinygltf::Accessor& a = model.accessors[size_t(accessor)];
        const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
        std::set<float> s;
        for (size_t i = 0; i < a.count; ++i) {
            float x;
            std::memcpy(&x, model.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset + 4 * i, 4);
            s.insert(x);
        }
        return s;
    };
    const tinygltf::Primitive& prim = model.meshes.at(0).primitives.at(0);
    ASSERT_TRUE(prim.attributes.count("_DOPPLER") && prim.attributes.count("_PROPER_TIME"));
    EXPECT_EQ(values(prim.attributes.at("_DOPPLER")), want_d);
    EXPECT_EQ(values(prim.attributes.at("_PROPER_TIME")), want_t);

    r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "draco").string(), "--compress", "draco",
                     "--attributes", "doppler", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream in(dir / "draco/relativistic.glb", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(bytes.find(R"("_DOPPLER")"), std::string::npos);
    EXPECT_EQ(bytes.find(R"("_PROPER_TIME")"), std::string::npos);

    // meshopt: in the frame's vertex record (decoded and compared value by value with the plain
    // file by tests/web/meshopt_roundtrip.js, ctest meshopt_roundtrip_npm).
    r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "m").string(), "--compress", "meshopt",
                     "--attributes", "proper_time", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream mesh_in(dir / "m/relativistic.glb", std::ios::binary);
    const std::string mesh_bytes((std::istreambuf_iterator<char>(mesh_in)), std::istreambuf_iterator<char>());
    EXPECT_NE(mesh_bytes.find(R"("_PROPER_TIME")"), std::string::npos);
    EXPECT_EQ(mesh_bytes.find(R"("_DOPPLER")"), std::string::npos);
    fs::remove_all(dir);
}
