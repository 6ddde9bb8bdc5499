#include "pipeline/stage.h"

#include <ostream>

#include "pipeline/json_limits.h"

namespace apparent {

bool loadStage(const StageOptions& options, Stage* stage, std::ostream& log, std::string* error) {
    auto fail = [&](const std::string& message) {
        *error = printable(message, 4096);  // one line, whatever a file or key holds
        return false;
    };
    // Step: the scene, the tolerance override and the models it must be valid for.
    Scene& scene = stage->scene;
    if (Status s = loadScene(options.scene_path, &scene); !s.ok) return fail(s.message);
    // Properties the scene reader kept but did not use (a misspelt field in glTF extras): said once.
    if (!options.quiet)
        for (const std::string& w : scene.warnings) log << "warning: " << w << "\n";
    if (options.has_tolerance) scene.tolerance = options.tolerance;
    stage->models = options.models;
    if (options.all_models) stage->models = {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted};
    if (stage->models.empty()) stage->models = {scene.model};
    for (Model m : stage->models)
        if (Status s = checkSceneForModel(scene, m); !s.ok) return fail(s.message);
    // Step: the frames: within the limit, and the requested range within the scene's.
    const long long total_frames = frameCount(scene.frames);
    if (total_frames > options.max_frames)
        return fail(scene.path + ": frames: " + std::to_string(total_frames) + " frames requested, more than the limit of " +
                    std::to_string(options.max_frames) + " (raise it with --max-frames)");
    stage->first = options.frame_from;
    stage->last_excl = options.frame_to < 0 ? total_frames : options.frame_to;
    if (!(stage->first >= 0 && stage->first < stage->last_excl && stage->last_excl <= total_frames))
        return fail("--frames: " + std::to_string(stage->first) + ":" + std::to_string(stage->last_excl) +
                    " is outside the scene's frames 0:" + std::to_string(total_frames));
    // Step: the meshes (once each) with rotation and scale, then the mirror planes.
    if (Status s = prepareObjects(scene, options.limits, &stage->objects, log, options.quiet); !s.ok)
        return fail(s.message);
    if (Status s = findMirrors(stage->objects, scene.path, &stage->mirrors); !s.ok) return fail(s.message);
    return true;
}

}  // namespace apparent
