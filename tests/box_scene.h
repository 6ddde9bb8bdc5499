// For tests: a scene whose objects use data/meshes/box.obj, written with the box into a fresh
// folder, and its stage loaded as `apparent render` loads it, quietly.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "quiet_stage.h"

namespace apparent {

struct BoxScene {
    std::filesystem::path dir;
    Stage stage;
};

// Writes box.obj and `scene_json` as scene.json into <temp>/apparent_<tag>_<pid> and loads its
// stage into f (a test failure with the one-line error when it does not load).
inline void loadBoxScene(const std::string& tag, const std::string& scene_json, BoxScene* f) {
    namespace fs = std::filesystem;
    f->dir = fs::temp_directory_path() / ("apparent_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(f->dir);
    fs::create_directories(f->dir);
    fs::copy_file(fs::path(APPARENT_SOURCE_DIR) / "data/meshes/box.obj", f->dir / "box.obj");
    std::ofstream(f->dir / "scene.json") << scene_json;
    std::string error;
    ASSERT_TRUE(loadQuietStage((f->dir / "scene.json").string(), &f->stage, &error)) << error;
}

}  // namespace apparent
