// End to end: the `apparent` command run in-process on shipped scenes and fixtures. Checks the
// output layout, exit codes, one-line errors, no partial files, and reads the outputs back with
// the libraries that wrote them (OpenMesh for PLY/OBJ, tinygltf for GLB).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>
#include <fstream>
#include <cstring>
#include <sstream>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "mesh4d/event.h"
#include "pipeline/commands/cli.h"
#include "run_command.h"
#include "pipeline/input/scene.h"

namespace fs = std::filesystem;

namespace {

using testcli::apparentRun;
using testcli::CommandResult;
using testcli::source;
using testcli::TempDir;

std::vector<std::string> listFiles(const fs::path& dir) {
    std::vector<std::string> names;
    if (!fs::exists(dir)) return names;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) names.push_back(fs::relative(e.path(), dir).string());
    std::sort(names.begin(), names.end());
    return names;
}

struct PlyTraits : OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
};
typedef OpenMesh::TriMesh_ArrayKernelT<PlyTraits> PlyMesh;

}  // namespace

TEST(Cli, HelpAndVersionExitZero) {
    CommandResult r = apparentRun({"--help"});
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("render"), std::string::npos);
    r = apparentRun({"render", "--help"});
    EXPECT_EQ(r.code, 0);
    for (const char* opt : {"--out", "--model", "--format", "--tolerance", "--frames", "relativistic", "quality"})
        EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
    EXPECT_EQ(apparentRun({"--version"}).code, 0);
}

TEST(Cli, BadUsageExitsTwo) {
    const std::string scene = source("data/fixtures/scene_tetra.json");
    EXPECT_EQ(apparentRun({}).code, 2);
    EXPECT_EQ(apparentRun({"render"}).code, 2);
    EXPECT_EQ(apparentRun({"render", scene, "--bogus"}).code, 2);
    CommandResult r = apparentRun({"render", scene, "--model", "newtonian"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--model: unknown model 'newtonian'"), std::string::npos) << r.err;
    r = apparentRun({"render", scene, "--format", "stl"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--format: unknown format 'stl'"), std::string::npos) << r.err;
    r = apparentRun({"render", scene, "--frames", "3-4"});
    EXPECT_EQ(r.code, 2);
    r = apparentRun({"render", scene, "--tolerance", "-1"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--tolerance"), std::string::npos) << r.err;
}

// The layout the issue spells out: DIR/<model>.glb and DIR/<model>/frame_NNNNN.ply|.obj, with
// --frames A:B keeping global frame numbers.
TEST(Cli, OutputLayoutAndFrameNumbers) {
    TempDir dir;
    const CommandResult r = apparentRun({"render", source("data/fixtures/scene_tetra.json"), "--out", dir.str(), "--model",
                               "all", "--format", "glb,ply,obj", "--frames", "2:4", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::vector<std::string> expected;
    for (const char* m : {"contracted", "finite", "instant", "relativistic"}) {
        expected.push_back(std::string(m) + ".glb");
        for (const char* f : {"frame_00002", "frame_00003"})
            for (const char* ext : {".obj", ".ply"}) expected.push_back(std::string(m) + "/" + f + ext);
    }
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(listFiles(dir / ""), expected);  // and no temporary files left behind
}

// PLY: binary little-endian, per-vertex `quality` = emission time, which OpenMesh reads back;
// each vertex satisfies |y - C| = t_c - t_e to float precision (positions are float in PLY).
TEST(Cli, PlyCarriesEmissionTimeAsQuality) {
    TempDir dir;
    ASSERT_EQ(apparentRun({"render", source("data/fixtures/scene_tetra.json"), "--out", dir.str(), "--format", "ply",
                           "--tolerance", "vertex", "--quiet"}).code, 0);
    const fs::path ply = dir / "relativistic/frame_00001.ply";
    std::ifstream head(ply, std::ios::binary);
    std::string header((std::istreambuf_iterator<char>(head)), {});
    header = header.substr(0, header.find("end_header"));
    EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos) << header;
    EXPECT_NE(header.find("property double quality"), std::string::npos) << header;

    PlyMesh m;
    OpenMesh::IO::Options opt(OpenMesh::IO::Options::Custom);
    ASSERT_TRUE(OpenMesh::IO::read_mesh(m, ply.string(), opt));
    OpenMesh::VPropHandleT<double> quality;
    ASSERT_TRUE(m.get_property_handle(quality, "quality"));
    EXPECT_EQ(m.n_faces(), 4u);
    const double t_c = 10.1;  // frame 1 of the scene: start 10, fps 10
    for (auto v : m.vertices()) {
        const auto p = m.point(v);
        const double dist = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        EXPECT_NEAR(dist, t_c - m.property(quality, v), 1e-5 * dist);
    }
}

// GLB: one node and mesh per frame, one STEP scale channel per node, positions relative to the
// node's translation; the file reloads with tinygltf and records the frame times in extras.
TEST(Cli, GlbHoldsEveryFrameAsAStepAnimation) {
    TempDir dir;
    ASSERT_EQ(apparentRun({"render", source("data/fixtures/scene_tetra.json"), "--out", dir.str(), "--quiet"}).code, 0);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, (dir / "relativistic.glb").string())) << err;
    ASSERT_EQ(model.nodes.size(), 6u);  // the camera, then one node per frame
    EXPECT_EQ(model.nodes[0].name, "camera");
    EXPECT_EQ(model.nodes[0].camera, 0);
    ASSERT_EQ(model.animations.size(), 1u);
    ASSERT_EQ(model.animations[0].channels.size(), 5u);
    for (size_t k = 0; k < 5; ++k) {
        const auto& ch = model.animations[0].channels[k];
        EXPECT_EQ(ch.target_node, int(k + 1));
        EXPECT_EQ(ch.target_path, "scale");
        EXPECT_EQ(model.animations[0].samplers[ch.sampler].interpolation, "STEP");
        const auto& node = model.nodes[k + 1];
        EXPECT_EQ(node.name, "frame_0000" + std::to_string(k));
        ASSERT_GE(node.mesh, 0);
        EXPECT_EQ(node.translation.size(), 3u);
        const auto& prim = model.meshes[node.mesh].primitives.at(0);
        for (const char* attr : {"POSITION", "NORMAL", "_EMISSION_TIME"}) EXPECT_TRUE(prim.attributes.count(attr)) << attr;
        EXPECT_EQ(prim.material, 0);
    }
    const auto& extras = model.scenes[0].extras;
    ASSERT_TRUE(extras.Has("frame_times"));
    EXPECT_DOUBLE_EQ(extras.Get("frame_times").Get(2).GetNumberAsDouble(), 10.2);
    EXPECT_EQ(extras.Get("model").Get<std::string>(), "relativistic");
}

// Mirrors: the reflections of each frame are their own node, a child of the frame
// node named "frame_NNNNN mirror <mirror>", with no transform of its own (the frame's origin and
// animation apply), one primitive per reflected object with that reflection's material; the
// animation still targets the frame nodes 1 + k. Checked against the frame's PLY (same triangle
// count over the frame node and its child) and the geometry: reflections lie behind the mirror
// plane z = -23.675, everything else in front of it.
TEST(Cli, ReflectionsAreChildNodesOfTheirFrames) {
    TempDir dir;
    ASSERT_EQ(apparentRun({"render", source("data/scenes/flanges.json"), "--out", dir.str(), "--format", "glb,ply",
                           "--frames", "95:105", "--quiet"}).code, 0);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, (dir / "relativistic.glb").string())) << err;
    const size_t frames = 10;
    ASSERT_EQ(model.nodes.size(), 1 + 2 * frames);  // camera, frame nodes, one reflection node per frame
    ASSERT_EQ(model.animations.at(0).channels.size(), frames);
    const std::vector<int>& roots = model.scenes.at(0).nodes;
    auto readPositions = [&](const tinygltf::Primitive& p) {
        const auto& acc = model.accessors[p.attributes.at("POSITION")];
        const auto& view = model.bufferViews[acc.bufferView];
        const uint8_t* base = model.buffers[view.buffer].data.data() + view.byteOffset + acc.byteOffset;
        std::vector<std::array<float, 3>> out(acc.count);
        for (size_t i = 0; i < acc.count; ++i) std::memcpy(out[i].data(), base + i * acc.ByteStride(view), 12);
        return out;
    };
    const double mirror_z = -23.675;
    for (size_t k = 0; k < frames; ++k) {
        EXPECT_EQ(model.animations[0].channels[k].target_node, int(1 + k));
        const tinygltf::Node& frame = model.nodes[1 + k];
        const std::string name = (k < 5 ? "frame_000" : "frame_00") + std::to_string(95 + k);
        ASSERT_EQ(frame.name, name);
        ASSERT_EQ(frame.children.size(), 1u) << name;
        const int ci = frame.children[0];
        EXPECT_GT(ci, int(frames));  // after every frame node
        EXPECT_EQ(std::count(roots.begin(), roots.end(), ci), 0) << "a child is no scene root";
        const tinygltf::Node& child = model.nodes[size_t(ci)];
        EXPECT_EQ(child.name, name + " mirror backdrop");
        EXPECT_EQ(child.extras.Get("mirror").Get<std::string>(), "backdrop");
        EXPECT_TRUE(child.translation.empty() && child.rotation.empty() && child.scale.empty() && child.matrix.empty());
        ASSERT_GE(child.mesh, 0);
        ASSERT_GE(frame.mesh, 0);
        size_t triangles = 0;
        for (const bool reflection : {false, true}) {
            const tinygltf::Mesh& mesh = model.meshes[size_t(reflection ? child.mesh : frame.mesh)];
            for (const auto& prim : mesh.primitives) {
                triangles += model.accessors[size_t(prim.indices)].count / 3;
                const std::string& material = model.materials.at(size_t(prim.material)).name;
                EXPECT_EQ(material.find("(mirror backdrop)") != std::string::npos, reflection) << material;
                for (const auto& p : readPositions(prim)) {
                    const double z = frame.translation[2] + double(p[2]);
                    if (reflection) EXPECT_LT(z, mirror_z + 1e-4) << material;
                    else EXPECT_GT(z, mirror_z - 1e-4) << material;
                }
            }
        }
        PlyMesh ply;
        OpenMesh::IO::Options opt;
        ASSERT_TRUE(OpenMesh::IO::read_mesh(ply, (dir / ("relativistic/" + name + ".ply")).string(), opt));
        EXPECT_EQ(triangles, ply.n_faces()) << name;
    }
}

// Bad input: exit 2, one line naming file and field, and nothing written at all.
TEST(Cli, BadInputExitsTwoAndWritesNothing) {
    const std::pair<const char*, const char*> cases[] = {
        {"scene_superluminal.json", "objects[0].velocity"},
        {"scene_malformed.json", "invalid JSON"},
        {"scene_missing_mesh.json", "objects[0].mesh: \"does_not_exist.obj\" not found"},
        {"scene_unknown_field.json", "objects[0].velocty"},
    };
    for (const auto& [file, expected] : cases) {
        TempDir dir;
        const CommandResult r = apparentRun({"render", source(std::string("data/fixtures/") + file), "--out", dir.str()});
        EXPECT_EQ(r.code, 2) << file;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_TRUE(listFiles(dir / "").empty()) << file;
    }
    // A malformed mesh behind a valid scene.
    TempDir dir;
    fs::create_directories(dir / "");
    fs::copy_file(source("data/fixtures/bad_index.obj"), dir / "bad_index.obj");
    std::ofstream(dir / "scene.json") << R"({ "objects": [ { "mesh": "bad_index.obj" } ] })";
    const CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("bad_index.obj:5: f: vertex index 9 is out of range"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));
}

// An object existing for proper time [0, 3] appears, shows clipped (open) frames and disappears.
TEST(Cli, ExistenceWindowGivesClippedFrames) {
    TempDir dir;
    ASSERT_EQ(apparentRun({"render", source("data/fixtures/scene_exists_window.json"), "--out", dir.str(), "--format",
                           "ply", "--tolerance", "vertex", "--quiet"}).code, 0);
    int empty = 0, full = 0, partial = 0;
    for (int k = 0; k < 120; ++k) {
        char name[64];
        std::snprintf(name, sizeof name, "relativistic/frame_%05d.ply", k);
        PlyMesh m;
        OpenMesh::IO::Options opt;
        ASSERT_TRUE(OpenMesh::IO::read_mesh(m, (dir / name).string(), opt)) << name;
        if (m.n_faces() == 0) ++empty;
        else if (m.n_faces() == 4 && m.n_vertices() == 4) ++full;
        else ++partial;
    }
    EXPECT_GT(empty, 0);
    EXPECT_GT(full, 0);
    EXPECT_GT(partial, 0);
}

// The default scene renders in every model.
TEST(Cli, DefaultSceneRendersInEveryModel) {
    TempDir dir;
    const CommandResult r = apparentRun({"render", source("data/scenes/flanges.json"), "--out", dir.str(), "--model", "all",
                               "--frames", "95:105"});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* m : {"instant", "finite", "relativistic", "contracted"})
        EXPECT_TRUE(fs::exists(dir / (std::string(m) + ".glb"))) << m;
    EXPECT_NE(r.out.find("relativistic: 10 frames"), std::string::npos) << r.out;
}

// Draco: the file is smaller, reloads through tinygltf's Draco decoder, and every decoded
// position is within the quantization bound of a position of the plain export (Draco reorders
// points, so each decoded point is matched to the nearest original of the same primitive).
TEST(Cli, DracoRoundTripWithinQuantizationBound) {
    TempDir plain_dir, draco_dir;
    const std::string scene = source("data/scenes/flanges.json");
    ASSERT_EQ(apparentRun({"render", scene, "--out", plain_dir.str(), "--frames", "90:110", "--quiet"}).code, 0);
    const CommandResult r = apparentRun({"render", scene, "--out", draco_dir.str(), "--frames", "90:110", "--draco",
                                         "--draco-bits", "12"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("with Draco"), std::string::npos) << r.out;

    auto load = [](const fs::path& p, tinygltf::Model* m) {
        tinygltf::TinyGLTF loader;
        std::string err, warn;
        return loader.LoadBinaryFromFile(m, &err, &warn, p.string());
    };
    tinygltf::Model plain, draco;
    ASSERT_TRUE(load(plain_dir / "relativistic.glb", &plain));
    ASSERT_TRUE(load(draco_dir / "relativistic.glb", &draco));
    ASSERT_EQ(draco.extensionsRequired, std::vector<std::string>{"KHR_draco_mesh_compression"});
    ASSERT_EQ(plain.meshes.size(), draco.meshes.size());
    auto positions = [](const tinygltf::Model& m, const tinygltf::Primitive& p) {
        const auto& acc = m.accessors[p.attributes.at("POSITION")];
        const auto& view = m.bufferViews[acc.bufferView];
        const uint8_t* base = m.buffers[view.buffer].data.data() + view.byteOffset + acc.byteOffset;
        const size_t stride = acc.ByteStride(view);
        std::vector<std::array<float, 3>> out(acc.count);
        for (size_t i = 0; i < acc.count; ++i) std::memcpy(out[i].data(), base + i * stride, 12);
        return out;
    };
    double worst_ratio = 0;
    for (size_t mi = 0; mi < plain.meshes.size(); ++mi) {
        ASSERT_EQ(plain.meshes[mi].primitives.size(), draco.meshes[mi].primitives.size());
        for (size_t pi = 0; pi < plain.meshes[mi].primitives.size(); ++pi) {
            const auto a = positions(plain, plain.meshes[mi].primitives[pi]);
            const auto b = positions(draco, draco.meshes[mi].primitives[pi]);
            // The bound: half a step of a 12-bit grid over the primitive's largest extent.
            float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (const auto& p : a)
                for (int c = 0; c < 3; ++c) { lo[c] = std::min(lo[c], p[c]); hi[c] = std::max(hi[c], p[c]); }
            const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
            const double bound = 0.5 * extent / 4095.0 * std::sqrt(3.0) + 1e-6;
            for (const auto& q : b) {
                double best = INFINITY;
                for (const auto& p : a)
                    best = std::min(best, std::sqrt(std::pow(double(p[0] - q[0]), 2) + std::pow(double(p[1] - q[1]), 2) +
                                                    std::pow(double(p[2] - q[2]), 2)));
                EXPECT_LE(best, bound) << "mesh " << mi << " primitive " << pi;
                worst_ratio = std::max(worst_ratio, best / bound);
            }
        }
    }
    EXPECT_GT(worst_ratio, 0.0);  // quantization did happen: the test can see an error
}

namespace {

// The JSON chunk of a .glb (read directly: tinygltf cannot load files requiring EXT_meshopt_compression).
nlohmann::json glbJson(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_GE(bytes.size(), 20u) << p;
    if (bytes.size() < 20) return nlohmann::json::object();
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return nlohmann::json::parse(bytes.substr(20, length));
}

// A scene folder with an icosphere (`sphere`, a file of data/meshes) passing the camera at 0.9c
// through the whole sequence (never clipped: it exists at all times), and a box at rest beside it.
void writePassingSphereScene(const fs::path& dir, const std::string& sphere) {
    fs::create_directories(dir);
    fs::copy_file(source("data/meshes/" + sphere), dir / "sphere.obj");
    fs::copy_file(source("data/meshes/box.obj"), dir / "box.obj");
    std::ofstream(dir / "scene.json") << R"({
  "camera": { "position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_deg": 60 },
  "frames": { "start": 0, "end": 2.4, "fps": 10 },
  "model": "relativistic",
  "objects": [ { "name": "sphere", "mesh": "sphere.obj", "position": [-2, 0, -10], "velocity": [0.9, 0, 0] },
               { "name": "box", "mesh": "box.obj", "position": [0, -2, -10] } ] })";
}

}  // namespace

// The scene extras "light" (exporters/glb/document.cpp writeLight): the scene's light in the file's
// axes and units, for viewers that light the file (scripts/blender_import.py). Three scenes with a
// box at rest: the default lights, derived here by hand for a camera at the origin looking down -z
// with +y up (forward f = (0, 0, -1), right f x up = (1, 0, 0), up (0, 1, 0); the key light towards
// back 1, left 0.45, up 0.15: (-0.45, 0.15, 1) / sqrt(1.225), weight 0.7; the overhead light +y);
// a distant light given as (0, 2, 0), recorded as the unit (0, 1, 0); a point light in a scene in
// metres, recorded in metres (the input's numbers, through light-seconds and back).
TEST(Cli, GlbSceneExtrasRecordTheLight) {
    TempDir dir;
    fs::create_directories(dir / "scene");
    fs::copy_file(source("data/meshes/box.obj"), dir / "scene/box.obj");
    const std::string head = R"({
  "camera": { "position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_deg": 60 },
  "frames": { "start": 0, "end": 0.2, "fps": 10 }, "model": "instant",
  "objects": [ { "name": "box", "mesh": "box.obj", "position": [0, 0, -10] } ])";
    std::ofstream(dir / "scene/default.json") << head << "}";
    std::ofstream(dir / "scene/distant.json") << head << R"(, "light": { "direction": [0, 2, 0], "ambient": 0.3 } })";
    std::ofstream(dir / "scene/metres.json") << head
                                             << R"(, "units": "m", "light": { "position": [1.5e8, 2, -3e9] } })";
    auto light = [&](const std::string& name) {
        const fs::path out = dir / ("out_" + name);
        const CommandResult r = apparentRun(
            {"render", (dir / "scene" / (name + ".json")).string(), "--out", out.string(), "--quiet"});
        EXPECT_EQ(r.code, 0) << r.err;
        return glbJson(out / "instant.glb")["scenes"][0]["extras"]["light"];
    };
    auto expectVector = [](const nlohmann::json& v, std::array<double, 3> expected, double tolerance) {
        ASSERT_TRUE(v.is_array() && v.size() == 3) << v;
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i].get<double>(), expected[i], tolerance) << v;
    };
    const nlohmann::json d = light("default");
    const double n = std::sqrt(1.225);
    EXPECT_EQ(d["ambient"].get<double>(), 0.2) << d;
    expectVector(d["direction"], {0, 1, 0}, 0);
    expectVector(d["key_direction"], {-0.45 / n, 0.15 / n, 1 / n}, 1e-15);
    EXPECT_EQ(d["key_weight"].get<double>(), 0.7) << d;
    EXPECT_FALSE(d.contains("position")) << d;

    const nlohmann::json s = light("distant");
    EXPECT_EQ(s["ambient"].get<double>(), 0.3) << s;
    expectVector(s["direction"], {0, 1, 0}, 0);
    EXPECT_FALSE(s.contains("key_weight") || s.contains("key_direction") || s.contains("position")) << s;

    const nlohmann::json m = light("metres");
    EXPECT_EQ(m["ambient"].get<double>(), 0.2) << m;
    expectVector(m["position"], {1.5e8, 2, -3e9}, 3e9 * 1e-15);
    EXPECT_FALSE(m.contains("direction") || m.contains("key_weight")) << m;
}

// Shared index buffers (gltf.h): in vertex mode with nothing clipped every frame of an object has
// the same triangles, so the .glb holds one index accessor per object, plain and meshopt; each
// frame still has its own vertices (with meshopt, as morph targets of its run's mesh). Read from
// the file's JSON. (The fine sphere keeps every apparent dihedral angle below the exporter's
// 30-degree crease threshold: a coarse mesh
// whose apparent angles cross it from frame to frame changes its vertex split, and so its index
// list, as the refined test below shows.)
TEST(Cli, VertexModeSequenceHoldsOneIndexAccessorPerObject) {
    TempDir dir;
    writePassingSphereScene(dir / "scene", "icosphere20480.obj");
    for (const char* compress : {"none", "meshopt"}) {
        const fs::path out = dir / compress;
        const CommandResult r = apparentRun({"render", (dir / "scene/scene.json").string(), "--out", out.string(),
                                             "--tolerance", "vertex", "--compress", compress, "--quiet"});
        ASSERT_EQ(r.code, 0) << r.err;
        const nlohmann::json j = glbJson(out / "relativistic.glb");
        // Frame by frame (with meshopt, frames after a run's first are morph targets of its mesh:
        // a frame's vertices are its mesh's POSITION with the first `ones` targets added).
        std::map<int, std::set<int>> indices;                      // by material (object)
        std::map<int, std::set<std::pair<int, size_t>>> vertices;  // (POSITION, targets added) by material
        size_t primitives = 0, targets = 0;
        for (const auto& node : j["nodes"]) {
            if (!node.contains("mesh")) continue;
            size_t ones = 0;
            if (node.contains("weights"))
                for (const auto& w : node["weights"]) ones += w.get<double>() == 1 ? 1 : 0;
            for (const auto& prim : j["meshes"][node["mesh"].get<size_t>()]["primitives"]) {
                indices[prim["material"].get<int>()].insert(prim["indices"].get<int>());
                vertices[prim["material"].get<int>()].insert({prim["attributes"]["POSITION"].get<int>(), ones});
                if (prim.contains("targets")) targets = std::max(targets, prim["targets"].size());
                ++primitives;
            }
        }
        EXPECT_EQ(primitives, 2u * 24u) << compress;
        ASSERT_EQ(indices.size(), 2u) << compress;
        for (const auto& [material, set] : indices) EXPECT_EQ(set.size(), 1u) << compress << " material " << material;
        for (const auto& [material, set] : vertices) EXPECT_EQ(set.size(), 24u) << compress << " material " << material;
        // Frame coherence (exporters/gltf.h): meshopt's 24 frames are one mesh and 23 morph targets
        // when the step stays the same, a few runs otherwise; plain frames have a mesh each.
        if (std::string(compress) == "meshopt") {
            EXPECT_LT(j["meshes"].size(), 24u / 2);
            EXPECT_GT(targets, 0u);
        } else {
            EXPECT_EQ(j["meshes"].size(), 24u);
            EXPECT_EQ(targets, 0u);
        }
    }
}

// The coarse sphere with a tolerance, where refinement (and the crease split) change its triangles
// from frame to frame:
// only equal index lists are shared, so the sphere has more than one index accessor.
TEST(Cli, RefinedSequenceSharesOnlyEqualIndexLists) {
    TempDir dir;
    writePassingSphereScene(dir / "scene", "icosphere320.obj");
    const CommandResult r = apparentRun({"render", (dir / "scene/scene.json").string(), "--out", (dir / "out").string(),
                                         "--tolerance", "0.0005", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json j = glbJson(dir / "out/relativistic.glb");
    std::map<int, std::set<int>> indices;
    for (const auto& mesh : j["meshes"])
        for (const auto& prim : mesh["primitives"]) indices[prim["material"].get<int>()].insert(prim["indices"].get<int>());
    EXPECT_GT(indices[0].size(), 1u);  // the sphere, refined differently as it passes
    EXPECT_EQ(indices[1].size(), 1u);  // the box at rest: the same triangles throughout
}

// --compress: meshopt's file requires EXT_meshopt_compression and KHR_mesh_quantization; draco
// is --draco's alias (the same bytes); contradictions and bad values exit with code 2; a
// --meshopt-bits too coarse for the tolerance is warned about, naming the tolerance.
TEST(Cli, CompressOptions) {
    TempDir dir;
    const std::string scene = source("data/scenes/flanges.json");
    auto render = [&](const std::string& sub, std::vector<std::string> extra) {
        std::vector<std::string> args = {"render", scene, "--out", (dir / sub).string(), "--frames", "95:100",
                                         "--model", "relativistic"};
        args.insert(args.end(), extra.begin(), extra.end());
        return apparentRun(args);
    };
    CommandResult r = render("meshopt", {"--compress", "meshopt"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("with meshopt"), std::string::npos) << r.out;
    const nlohmann::json j = glbJson(dir / "meshopt/relativistic.glb");
    EXPECT_EQ(j["extensionsRequired"], nlohmann::json({"EXT_meshopt_compression", "KHR_mesh_quantization"}));
    EXPECT_EQ(j["buffers"].size(), 2u);
    EXPECT_TRUE(j["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"].get<bool>());

    ASSERT_EQ(render("a", {"--draco", "--quiet"}).code, 0);
    ASSERT_EQ(render("b", {"--compress", "draco", "--quiet"}).code, 0);
    auto bytes = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    EXPECT_EQ(bytes(dir / "a/relativistic.glb"), bytes(dir / "b/relativistic.glb"));

    r = render("c", {"--compress", "zstd"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--compress: unknown compression 'zstd'"), std::string::npos) << r.err;
    r = render("c", {"--draco", "--compress", "meshopt"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--draco and --compress meshopt contradict"), std::string::npos) << r.err;
    r = render("c", {"--compress", "meshopt", "--meshopt-bits", "17"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--meshopt-bits: 17 is outside 2..16"), std::string::npos) << r.err;
    r = render("c", {"--meshopt-bits", "12"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--meshopt-bits needs --compress meshopt"), std::string::npos) << r.err;
    r = render("c", {"--draco", "--draco-texcoord-bits", "31"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--draco-texcoord-bits: 31 is outside 1..30"), std::string::npos) << r.err;
    r = render("c", {"--draco-texcoord-bits", "12"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--draco-texcoord-bits needs --compress draco"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "c"));

    // 6 bits over the frame (about 50 light-seconds across): a step near 0.8 ls, far above the
    // scene's tolerance of 0.01 ls.
    r = render("coarse", {"--compress", "meshopt", "--meshopt-bits", "6"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("meshopt position error up to"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("exceeds the tolerance 0.01 ls"), std::string::npos) << r.err;
    r = render("fine", {"--compress", "meshopt"});
    EXPECT_EQ(r.err.find("meshopt position error"), std::string::npos) << r.err;
}

// `apparent render scene.gltf` needs no JSON: the glTF twin of the default scene gives
// byte-identical per-frame output, but for the header's `comment scene:` line naming each file.
TEST(Cli, GltfSceneRendersLikeItsJsonTwin) {
    TempDir a, b;
    ASSERT_EQ(apparentRun({"render", source("data/scenes/flanges.json"), "--out", a.str(), "--format", "ply",
                           "--frames", "90:110", "--quiet"}).code, 0);
    ASSERT_EQ(apparentRun({"render", source("data/scenes/flanges.gltf"), "--out", b.str(), "--format", "ply",
                           "--frames", "90:110", "--quiet"}).code, 0);
    for (int k = 90; k < 110; ++k) {
        char name[64];
        std::snprintf(name, sizeof name, "relativistic/frame_%05d.ply", k);
        std::ifstream fa(a / name, std::ios::binary), fb(b / name, std::ios::binary);
        const std::string da((std::istreambuf_iterator<char>(fa)), {}), db((std::istreambuf_iterator<char>(fb)), {});
        ASSERT_FALSE(da.empty()) << name;
        const std::string scene_a = "comment scene: " + source("data/scenes/flanges.json") + "\n";
        const std::string scene_b = "comment scene: " + source("data/scenes/flanges.gltf") + "\n";
        ASSERT_NE(da.find(scene_a), std::string::npos) << name;
        ASSERT_NE(db.find(scene_b), std::string::npos) << name;
        EXPECT_TRUE(std::string(da).erase(da.find(scene_a), scene_a.size()) ==
                    std::string(db).erase(db.find(scene_b), scene_b.size()))
            << name;
    }
}

// Frames run in parallel, yet the same input gives byte-identical files whatever the thread count.
TEST(Cli, OutputIsIdenticalForAnyThreadCount) {
    TempDir one, two;
    for (const auto& [dir, threads] : {std::pair<const TempDir*, const char*>{&one, "1"}, {&two, "2"}})
        ASSERT_EQ(apparentRun({"render", source("data/scenes/flanges.json"), "--out", dir->str(), "--frames", "90:110",
                               "--model", "finite,relativistic", "--format", "glb,ply", "--threads", threads, "--quiet"})
                      .code,
                  0);
    const auto files = listFiles(one / "");
    ASSERT_EQ(files, listFiles(two / ""));
    ASSERT_EQ(files.size(), 2u + 2u * 20u);
    for (const auto& f : files) {
        std::ifstream a(one / f, std::ios::binary), b(two / f, std::ios::binary);
        const std::string da((std::istreambuf_iterator<char>(a)), {}), db((std::istreambuf_iterator<char>(b)), {});
        EXPECT_EQ(da, db) << f;
    }
}

// The same for the .glb's parallel conversion (crease split, float32, meshopt encoding) on a mesh
// large enough to be split among threads (20480 faces), plain and meshopt, vertex mode and refined.
TEST(Cli, GlbIsIdenticalForAnyThreadCountOnALargeMesh) {
    TempDir dir;
    writePassingSphereScene(dir / "scene", "icosphere20480.obj");
    for (const char* compress : {"none", "meshopt"})
        for (const char* tolerance : {"vertex", "0.002"}) {
            std::string bytes[2];
            for (int t = 0; t < 2; ++t) {
                const fs::path out = dir / (std::string(compress) + tolerance + std::to_string(t));
                ASSERT_EQ(apparentRun({"render", (dir / "scene/scene.json").string(), "--out", out.string(), "--frames",
                                       "0:6", "--tolerance", tolerance, "--compress", compress, "--threads",
                                       t == 0 ? "1" : "2", "--quiet"})
                              .code,
                          0);
                std::ifstream in(out / "relativistic.glb", std::ios::binary);
                bytes[t].assign((std::istreambuf_iterator<char>(in)), {});
            }
            ASSERT_FALSE(bytes[0].empty());
            EXPECT_EQ(bytes[0], bytes[1]) << compress << " " << tolerance;
        }
}

// An absurdly fine tolerance is refused up front (below 1e-6 of the object's size); one just above
// that floor, on a tetrahedron passing 1.6 ls from the camera at 0.99c, stops at the refinement
// limit with a warning, not a crash. (The tetra of scene_tetra.json at 4e-6 is met within 256
// segments: the whole-piece form passes pieces as they are.)
TEST(Cli, AbsurdToleranceHitsTheLimitWithAWarning) {
    TempDir dir;
    CommandResult r = apparentRun({"render", source("data/fixtures/scene_tetra.json"), "--out", dir.str(),
                                   "--frames", "0:1", "--tolerance", "1e-20"});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("light-seconds is below the floor of"), std::string::npos) << r.err;
    r = apparentRun({"render", source("data/fixtures/scene_tetra.json"), "--out", dir.str(), "--frames", "0:1",
                     "--tolerance", "4e-6"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("reached the refinement limit"), std::string::npos) << r.err;
    r = apparentRun({"render", source("data/fixtures/scene_tetra_near.json"), "--out", dir.str(), "--frames", "0:1",
                     "--tolerance", "3.5e-6"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("reached the refinement limit of 256 segments"), std::string::npos) << r.err;
}
