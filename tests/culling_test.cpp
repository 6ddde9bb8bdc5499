// View culling (--cull-view): objects wholly outside the camera's view are left empty in that
// frame; everything in view is rendered exactly as without the option.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "pipeline/commands/render.h"
#include "pipeline/stage/worlds.h"
#include "temp_dir.h"

using namespace apparent;

namespace {
// "element vertex N" of a PLY header.
long long plyVertices(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    while (std::getline(in, line) && line != "end_header")
        if (line.rfind("element vertex ", 0) == 0) return std::stoll(line.substr(15));
    return -1;
}

std::string readAll(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}
}  // namespace

TEST(Culling, ConeAroundTheViewAxis) {
    CameraSpec cam;  // at the origin looking down -z, 60 degrees vertical
    EXPECT_TRUE(inCameraView(cam, {{0, 0, -10}, 1}));
    EXPECT_FALSE(inCameraView(cam, {{0, 0, 10}, 1}));       // behind
    EXPECT_TRUE(inCameraView(cam, {{0, 0, 10}, 11}));       // behind, but the camera is inside it
    EXPECT_FALSE(inCameraView(cam, {{0, 10, 1}, 1}));       // beside, above the frame
    // At the edge: 30 degrees up is the frame's top edge; the corner cone reaches further.
    EXPECT_TRUE(inCameraView(cam, {{0, 10 * std::tan(0.5), -10}, 0.01}));
    EXPECT_FALSE(inCameraView(cam, {{0, 10 * std::tan(1.3), -10}, 0.01}));
}

// A scene with one flange ahead of the camera and one behind it: with --cull-view the frames hold
// the one ahead, vertex for vertex as without the option, and nothing of the one behind.
TEST(Culling, RenderLeavesOnlyWhatIsOutOfViewEmpty) {
    const auto dir = testio::tempPath() / "apparent_culling";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::filesystem::copy_file(std::string(APPARENT_SOURCE_DIR) + "/data/meshes/flange.obj", dir / "flange.obj");
    std::ofstream(dir / "scene.json") << R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
      "frames": {"start": 0, "end": 2, "fps": 2},
      "model": "relativistic", "tolerance": "vertex",
      "objects": [
        {"name": "ahead", "mesh": "flange.obj", "position": [0, 0, -20], "velocity": [0.5, 0, 0]},
        {"name": "behind", "mesh": "flange.obj", "position": [0, 0, 20], "velocity": [0.5, 0, 0]}]})";
    auto run = [&](bool cull, const std::string& out, const std::string& scene) {
        RenderSettings s;
        s.stage.scene_path = (dir / scene).string();
        s.out_dir = (dir / out).string();
        s.formats = {"ply"};
        s.quiet = true;
        s.cull_view = cull;
        std::ostringstream log, err;
        EXPECT_EQ(render(s, log, err), kExitOk) << err.str();
    };
    run(false, "all", "scene.json");
    run(true, "culled", "scene.json");
    // The same scene without the object behind.
    std::string only_ahead = readAll(dir / "scene.json");
    only_ahead = only_ahead.substr(0, only_ahead.find(",\n        {\"name\": \"behind\"")) + "]}";
    std::ofstream(dir / "ahead.json") << only_ahead;
    run(false, "ahead", "ahead.json");
    for (const char* frame : {"frame_00000.ply", "frame_00003.ply"}) {
        const long long all = plyVertices(dir / "all" / "relativistic" / frame);
        const long long culled = plyVertices(dir / "culled" / "relativistic" / frame);
        ASSERT_GT(all, 0);
        EXPECT_EQ(2 * culled, all) << frame;  // the same mesh twice, once culled
        // The same vertices and faces (object 0 in both); the headers differ in the scene's path
        // and the object list.
        const std::string culled_bytes = readAll(dir / "culled" / "relativistic" / frame);
        const std::string ahead_bytes = readAll(dir / "ahead" / "relativistic" / frame);
        EXPECT_EQ(culled_bytes.substr(culled_bytes.find("end_header\n")), ahead_bytes.substr(ahead_bytes.find("end_header\n")));
    }
}
