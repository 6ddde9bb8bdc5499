// For tests and benchmarks: a scene's stage loaded as `apparent render` loads it, with nothing
// printed (pipeline/stage/stage.h loadStage with quiet options).
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "pipeline/stage/stage.h"

namespace apparent {

// Loads `scene` (its own model when `models` is empty); false with the one-line error.
inline bool loadQuietStage(const std::string& scene, Stage* stage, std::string* error, std::vector<Model> models = {}) {
    StageOptions options;
    options.scene_path = scene;
    options.models = std::move(models);
    options.quiet = true;
    std::ostringstream log;
    return loadStage(options, stage, log, error);
}

// Frames [frame_from, frame_to) of `scene` (its own models); false with the one-line error.
inline bool loadQuietFrames(const std::string& scene, long long frame_from, long long frame_to, Stage* stage,
                            std::string* error) {
    StageOptions options;
    options.scene_path = scene;
    options.frame_from = frame_from;
    options.frame_to = frame_to;
    options.quiet = true;
    std::ostringstream log;
    return loadStage(options, stage, log, error);
}

}  // namespace apparent
