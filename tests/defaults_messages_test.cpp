// The default tolerance follows each object's size, the output-size
// estimate stops a run before it writes, and the messages for the mistakes new users make.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "pipeline/input/mesh_input.h"
#include "pipeline/input/obj_reader.h"
#include "pipeline/input/scene.h"
#include "pipeline/run/frame_loop.h"
#include "pipeline/stage/stage.h"
#include "run_command.h"
#include "quiet_stage.h"
#include "temp_dir.h"

namespace {

namespace fs = std::filesystem;
using testcli::apparentRun;
using testcli::CommandResult;
using testcli::source;

class Folder {
public:
    Folder() {
        static int counter = 0;
        path_ = testio::tempPath() / ("apparent_people_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~Folder() { fs::remove_all(path_); }
    fs::path operator/(const std::string& s) const { return path_ / s; }

private:
    fs::path path_;
};

size_t lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

// The box of edge 1 (data/meshes/box.obj) 2 ls from the camera at 0.9c, every length and time
// multiplied by `k`: the same picture at another scale.
std::string writeBoxScene(const Folder& dir, const std::string& name, double k, const std::string& extra = "") {
    fs::copy_file(source("data/meshes/box.obj"), dir / "box.obj", fs::copy_options::overwrite_existing);
    std::ostringstream s;
    s.precision(17);
    s << R"({ "camera": { "position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_deg": 90 },)"
      << R"( "frames": { "start": 0, "end": )" << 4 * k << R"(, "fps": )" << 10 / k << " }," << extra
      << R"( "objects": [ { "name": "box", "mesh": "box.obj", "scale": )" << k << R"(, "position": [0, 0, )" << -2 * k
      << R"(], "velocity": [0.9, 0, 0] } ] })";
    std::ofstream(dir / name) << s.str();
    return (dir / name).string();
}

// Records each frame's triangle count.
class CountingSink : public apparent::FrameSink {
public:
    bool begin(const apparent::SequenceInfo&, std::string*) override { return true; }
    apparent::PendingOutput pending(const apparent::ExportFrame&) override { return {}; }
    bool add(const apparent::ExportFrame& frame, const apparent::PreparedFrame*, std::vector<std::string>*,
             std::string*) override {
        counts.push_back(frame.triangleCount());
        return true;
    }
    bool finish(apparent::SinkSummary*, std::string*) override { return true; }
    std::vector<size_t> counts;
};

std::vector<size_t> triangleCounts(const std::string& scene, double* tolerance) {
    apparent::Stage stage;
    std::string error;
    EXPECT_TRUE(apparent::loadQuietStage(scene, &stage, &error)) << error;
    std::ostringstream log;  // the frame loop's progress (off)
    EXPECT_EQ(stage.tolerances.size(), 1u);
    *tolerance = stage.tolerances.empty() ? 0 : stage.tolerances[0];
    CountingSink sink;
    apparent::OutputBudget budget(0);
    apparent::FrameLoopSettings settings;
    settings.progress = false;
    apparent::FrameLoopResult result;
    EXPECT_TRUE(apparent::runFrameLoop(stage, apparent::Model::Relativistic, settings, {&sink}, &budget, log, &result,
                                       &error))
        << error;
    return sink.counts;
}

}  // namespace

// Item 1: with no tolerance given, each object's is 1e-3 of its bounding-box diagonal, so the same
// scene at scale 1 and 1000 is cut into the same triangles frame by frame (an absolute default
// would refine the small one 1000 times more finely than the large one, or not at all).
TEST(Defaults, ToleranceFollowsTheObjectsSize) {
    Folder dir;
    double t1 = 0, t1000 = 0;
    const std::vector<size_t> small = triangleCounts(writeBoxScene(dir, "s1.json", 1), &t1);
    const std::vector<size_t> large = triangleCounts(writeBoxScene(dir, "s1000.json", 1000), &t1000);
    EXPECT_NEAR(t1, 1e-3 * std::sqrt(3.0), 1e-15);  // the unit box's diagonal is sqrt(3)
    EXPECT_NEAR(t1000, 1.0 * std::sqrt(3.0), 1e-12);
    ASSERT_EQ(small.size(), 40u);
    EXPECT_EQ(small, large);
    EXPECT_GT(*std::max_element(small.begin(), small.end()), 12u * 20);  // refined, not vertex mode's 12
    // An absolute tolerance is still taken as given: the default's value at scale 1000, written in
    // light-seconds, gives the default's triangles.
    std::vector<size_t> absolute;
    {
        double t = 0;
        absolute = triangleCounts(writeBoxScene(dir, "abs.json", 1000, R"( "tolerance": 1.7320508075688772,)"), &t);
        EXPECT_EQ(t, 1.7320508075688772);
    }
    EXPECT_EQ(absolute, large);
    // The relative form on the command line and in the scene.
    const std::string s1 = writeBoxScene(dir, "rel.json", 1, R"( "tolerance": "1e-2x",)");
    double t = 0;
    const std::vector<size_t> coarse = triangleCounts(s1, &t);
    EXPECT_NEAR(t, 1e-2 * std::sqrt(3.0), 1e-15);
    EXPECT_LT(*std::max_element(coarse.begin(), coarse.end()), *std::max_element(small.begin(), small.end()));
    CommandResult r = apparentRun({"render", s1, "--out", (dir / "o").string(), "--tolerance", "2x", "--quiet"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--tolerance: '2x' is neither"), std::string::npos) << r.err;
    r = apparentRun({"render", s1, "--out", (dir / "o").string(), "--tolerance", "1e-9x", "--quiet"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("1.0000000000000001e-09x is below the floor of 9.9999999999999995e-07x"), std::string::npos) << r.err;
}

// Item 1: the size estimate from the first frames stops a run that would pass the budget before
// anything is written (the folder it would have created included); --max-output-bytes raises the
// budget and 0 removes it.
TEST(Defaults, SizeEstimateStopsTheRunBeforeItWrites) {
    Folder dir;
    // 10 000 frames of the box at 1e-5 of its size: more by the first frames' count, more
    // than the default budget of 2 GiB.
    const std::string big = writeBoxScene(dir, "big.json", 1);
    {
        std::ifstream in(big);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        text.replace(text.find(R"("fps": 10 })"), 11, R"("fps": 2500 })");
        std::ofstream(big) << text;
    }
    CommandResult r = apparentRun({"render", big, "--out", (dir / "big").string(), "--tolerance", "1e-5x"});
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    for (const char* way : {"--tolerance", "--frames", "--compress", "--max-output-bytes", "nothing was written",
                            "more than the limit of 2147483648", "estimated from 4 of 10000 frames"})
        EXPECT_NE(r.err.find(way), std::string::npos) << way << " in " << r.err;
    EXPECT_FALSE(fs::exists(dir / "big"));

    // A small run against a small limit: stopped the same way, every format, nothing left behind.
    const std::string small = writeBoxScene(dir, "small.json", 1);
    r = apparentRun({"render", small, "--out", (dir / "small").string(), "--format", "glb,ply", "--max-output-bytes", "100000"});
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.err.find("nothing was written"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "small"));
    // An existing folder is kept, and holds no temporary files.
    fs::create_directories(dir / "kept");
    r = apparentRun({"render", small, "--out", (dir / "kept").string(), "--format", "ply,obj,glb", "--max-output-bytes", "100000"});
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_TRUE(fs::is_empty(dir / "kept"));
    // 0: no limit.
    r = apparentRun({"render", small, "--out", (dir / "small").string(), "--format", "glb,ply", "--max-output-bytes", "0", "--quiet"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_GT(fs::file_size(dir / "small/relativistic.glb"), 100000u);
    r = apparentRun({"render", small, "--out", (dir / "small").string(), "--max-output-bytes", "-1"});
    EXPECT_EQ(r.code, 2) << r.err;
}

// Item 6: one line naming the file, the field or element, and the problem.
TEST(Messages, MissingMeshNamesTheField) {
    Folder dir;
    std::ofstream(dir / "scene.json") << R"({ "objects": [ { "mesh": "box.obj" }, { "mesh": "cueb.obj" } ] })";
    fs::copy_file(source("data/meshes/box.obj"), dir / "box.obj");
    const CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("scene.json: objects[1].mesh: \"cueb.obj\" not found (" + (dir / "cueb.obj").string() + ")"),
              std::string::npos) << r.err;
}

TEST(Messages, MeshGivenAsTheScene) {
    for (const char* mesh : {"data/fixtures/tetra.obj", "data/meshes/box.obj"}) {
        const CommandResult r = apparentRun({"render", source(mesh), "--out", "/nonexistent/never"});
        EXPECT_EQ(r.code, 2);
        EXPECT_EQ(lines(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find(std::string(mesh) + " is an OBJ mesh, not a scene: name it in a scene's objects[].mesh"),
                  std::string::npos) << r.err;
    }
}

TEST(Messages, UnknownCommandSuggestsTheNearest) {
    CommandResult r = apparentRun({"rendr", "scene.json"});
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, "error: unknown command 'rendr'; did you mean render? (commands: render, raytrace, figure, trade, measure, merge; "
                     "run 'apparent --help')\n");
    r = apparentRun({"fgure"});
    EXPECT_NE(r.err.find("did you mean figure?"), std::string::npos) << r.err;
    r = apparentRun({"xyzzy"});
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err.find("did you mean"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("unknown command 'xyzzy'"), std::string::npos) << r.err;
    // render --help names every scene format.
    r = apparentRun({"render", "--help"});
    EXPECT_EQ(r.code, 0);
    for (const char* format : {"JSON (.json", "glTF (.gltf or .glb"}) EXPECT_NE(r.out.find(format), std::string::npos) << r.out;
}

TEST(Messages, GltfOneIsNamed) {
    Folder dir;
    // The shape of a glTF 1.0 file: asset.version "1.0", meshes as a dictionary.
    std::ofstream(dir / "old.gltf") << R"({ "asset": { "version": "1.0" }, "meshes": { "m": { "primitives": [] } },
        "nodes": { "n": { "meshes": ["m"] } }, "scene": "s", "scenes": { "s": { "nodes": ["n"] } } })";
    std::ofstream(dir / "scene.json") << R"({ "objects": [ { "mesh": "old.gltf" } ] })";
    for (const std::string& scene : {(dir / "old.gltf").string(), (dir / "scene.json").string()}) {
        const CommandResult r = apparentRun({"render", scene, "--out", (dir / "out").string()});
        EXPECT_EQ(r.code, 2);
        EXPECT_EQ(lines(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("old.gltf: asset.version: glTF 1.0 is not supported; convert with"), std::string::npos) << r.err;
    }
}

TEST(Messages, RepeatedVertexIsNamed) {
    Folder dir;
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 0\nv 1 0 1\nv 0 1 1\n";
    std::ofstream(dir / "some.obj") << v << "f 1 2 3\nf 1 2 4\nf 5 7 7\n";
    std::ofstream(dir / "all.obj") << v << "# every face\nf 1 2 2\nf 3 3 4\n";
    mesh4d::RestMesh m;
    apparent::MeshWarnings w;
    ASSERT_TRUE(apparent::readObj((dir / "some.obj").string(), {}, &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 2u);
    ASSERT_EQ(w.other.size(), 1u);
    EXPECT_EQ(w.other[0], "face 3 repeats vertex 7 (line 10): dropped (a face may use a vertex once)");
    const apparent::Status s = apparent::readObj((dir / "all.obj").string(), {}, &m, &w);
    EXPECT_FALSE(s.ok);
    EXPECT_EQ(s.message, (dir / "all.obj").string() +
                             ": no usable faces ('f' lines): face 1 repeats vertex 2 (line 9) (and 1 more faces repeat a vertex)");
}

TEST(Messages, Utf16ObjIsNamed) {
    Folder dir;
    const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for (const bool bom : {true, false}) {
        std::string utf16 = bom ? std::string("\xFF\xFE", 2) : std::string();
        for (char c : text) utf16 += std::string{c, '\0'};
        std::ofstream(dir / "wide.obj", std::ios::binary) << utf16;
        mesh4d::RestMesh m;
        apparent::MeshWarnings w;
        const apparent::Status s = apparent::readObj((dir / "wide.obj").string(), {}, &m, &w);
        EXPECT_FALSE(s.ok);
        EXPECT_EQ(s.message, (dir / "wide.obj").string() + ": UTF-16 text; save as UTF-8 (OBJ is read as ASCII / UTF-8)");
    }
}

TEST(Messages, SkinsAndAnimationsAreIgnoredWithAWarning) {
    Folder dir;
    // One triangle (three float32 positions in tri.bin), skinned to its own node and animated.
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const float times[2] = {0, 1};
    const float moves[6] = {0, 0, 0, 1, 0, 0};
    std::ofstream bin(dir / "tri.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(p), sizeof p);
    bin.write(reinterpret_cast<const char*>(times), sizeof times);
    bin.write(reinterpret_cast<const char*>(moves), sizeof moves);
    bin.close();
    std::ofstream(dir / "rig.gltf") << R"({ "asset": { "version": "2.0" },
      "buffers": [ { "uri": "tri.bin", "byteLength": 68 } ],
      "bufferViews": [ { "buffer": 0, "byteOffset": 0, "byteLength": 36 }, { "buffer": 0, "byteOffset": 36, "byteLength": 8 },
                       { "buffer": 0, "byteOffset": 44, "byteLength": 24 } ],
      "accessors": [ { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0] },
                     { "bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1] },
                     { "bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3" } ],
      "meshes": [ { "primitives": [ { "attributes": { "POSITION": 0 } } ] } ],
      "skins": [ { "joints": [1] } ],
      "animations": [ { "samplers": [ { "input": 1, "output": 2 } ], "channels": [ { "sampler": 0, "target": { "node": 1, "path": "translation" } } ] } ],
      "nodes": [ { "mesh": 0, "skin": 0 }, { "name": "joint" } ],
      "scenes": [ { "nodes": [0, 1] } ], "scene": 0 })";
    std::ofstream(dir / "scene.json") << R"({ "frames": { "start": 10, "end": 10.2, "fps": 10 },
      "objects": [ { "mesh": "rig.gltf", "position": [0, 0, -10], "velocity": [0.5, 0, 0] } ] })";
    const CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + (dir / "rig.gltf").string() +
                         ": 1 skins and 1 animations: skin and animation ignored: the bind pose is used\n"),
              std::string::npos) << r.err;
}

// Item 5: a glTF scene's extras "up": "z" reads the extras' vectors in Blender's axes (the Blender
// round trip itself is ctest blender_round_trip); what has no single axis rule is refused.
TEST(Messages, UpAxisOfGltfExtras) {
    Folder dir;
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(p), sizeof p);
    auto write = [&](const std::string& scene_extras, const std::string& node_extras) {
        std::ofstream(dir / "s.gltf") << R"({ "asset": { "version": "2.0" },
          "buffers": [ { "uri": "tri.bin", "byteLength": 36 } ], "bufferViews": [ { "buffer": 0, "byteLength": 36 } ],
          "accessors": [ { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0] } ],
          "meshes": [ { "primitives": [ { "attributes": { "POSITION": 0 } } ] } ],
          "nodes": [ { "name": "tri", "mesh": 0, "translation": [0, 0, -5], "extras": )" << node_extras << R"( } ],
          "scenes": [ { "nodes": [0], "extras": )" << scene_extras << R"( } ], "scene": 0 })";
        apparent::Scene scene;
        return std::make_pair(apparent::loadScene((dir / "s.gltf").string(), &scene), scene);
    };
    // Blender's [0, 0.5, 0] (into the screen) and light from its +Z (overhead) are glTF's -Z and +Y.
    auto [ok, scene] = write(R"({ "up": "z", "light": { "direction": [0, 0, 2] } })", R"({ "velocity": [0.1, 0.5, 0.2] })");
    ASSERT_TRUE(ok.ok) << ok.message;
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_EQ(scene.objects[0].velocity.x, 0.1);
    EXPECT_EQ(scene.objects[0].velocity.y, 0.2);
    EXPECT_EQ(scene.objects[0].velocity.z, -0.5);
    EXPECT_EQ(scene.light.direction.y, 1.0);
    // Without "up" (or "up": "y") the extras are glTF's axes, as before.
    for (const char* extras : {"{}", R"({ "up": "y" })"}) {
        auto [ok_y, scene_y] = write(extras, R"({ "velocity": [0.1, 0.5, 0.2] })");
        ASSERT_TRUE(ok_y.ok) << ok_y.message;
        EXPECT_EQ(scene_y.objects[0].velocity.y, 0.5);
    }
    const std::string file = (dir / "s.gltf").string();
    auto [bad_up, s1] = write(R"({ "up": "x" })", R"({ "velocity": [0.1, 0, 0] })");
    EXPECT_EQ(bad_up.message, file + ": scenes[0].extras.up: expected \"y\" (glTF's axes, the default) or \"z\" (Blender's), got \"x\"");
    auto [bad_rot, s2] = write(R"({ "up": "z" })", R"({ "velocity": [0.1, 0, 0], "rotation_deg": [90, 0, 0] })");
    EXPECT_NE(bad_rot.message.find("nodes[0].extras.rotation_deg: not read with the scene's \"up\": \"z\""), std::string::npos)
        << bad_rot.message;
}
