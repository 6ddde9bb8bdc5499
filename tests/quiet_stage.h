// For tests and benchmarks: a scene's stage loaded as `apparent render` loads it, with nothing
// printed (pipeline/stage.h loadStage with quiet options).
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "pipeline/stage.h"

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

}  // namespace apparent
