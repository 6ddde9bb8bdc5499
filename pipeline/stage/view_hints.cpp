#include "pipeline/stage/view_hints.h"

#include <algorithm>
#include <cmath>

#include "mesh4d/slice.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

bool objectInView(const Stage& stage, Model model, size_t object, long long k) {
    // The bound needs only the motion in the cut's frame and the rest mesh's radius.
    mesh4d::World4D w;
    w.motion = cutMotionOf(stage.objects[object].spec, model, stage.scene).motion;
    w.shape_radius = stage.objects[object].radius;  // the rest mesh may be taken by the worlds by now
    return inCameraView(stage.scene.camera, mesh4d::apparentBound(w, viewForFrame(stage.scene, model, k)));
}

std::vector<long long> frameRange(long long first, long long last_excl) {
    std::vector<long long> frames;
    for (long long k = first; k < last_excl; ++k) frames.push_back(k);
    return frames;
}

namespace {

bool inAnyFrame(const Stage& stage, Model model, size_t object, const std::vector<long long>& frames) {
    if (model != Model::Instant && !checkSceneForModel(stage.scene, model).ok) return false;
    return std::any_of(frames.begin(), frames.end(), [&](long long k) { return objectInView(stage, model, object, k); });
}

// The light delay of the object's origin at frame k: t_c less its emission time.
double lightDelay(const Stage& stage, Model model, size_t object, long long k) {
    const mesh4d::ViewSurface view = viewForFrame(stage.scene, model, k);
    const mesh4d::Motion m = cutMotionOf(stage.objects[object].spec, model, stage.scene).motion;
    return view.t_c - mesh4d::viewAnchor(view, m).time_origin;
}

}  // namespace

std::vector<std::string> outOfViewWarnings(const Stage& stage, Model model, const std::vector<long long>& frames) {
    std::vector<std::string> lines;
    if (frames.empty()) return lines;
    const Scene& scene = stage.scene;
    const long long middle = frames[frames.size() / 2];
    for (size_t i = 0; i < stage.objects.size(); ++i) {
        const ObjectSpec& s = stage.objects[i].spec;
        if (s.mirror || inAnyFrame(stage, model, i, frames)) continue;
        std::string line = scene.path + ": " + s.field_path + " (\"" + s.name + "\"): outside the camera's view in every frame of model " +
                           modelName(model) + " (frames " + std::to_string(frames.front()) + ".." + std::to_string(frames.back()) + "); ";
        const bool hyperplane = model == Model::Instant || model == Model::Contracted;
        const Model light = checkSceneForModel(scene, Model::Relativistic).ok ? Model::Relativistic : Model::Finite;
        if (hyperplane && checkSceneForModel(scene, light).ok && inAnyFrame(stage, light, i, frames)) {
            line += std::string("model ") + modelName(light) + " sees it: model " + modelName(model) +
                    " shows objects where they are at t - camera.instant_delay (" + formatNumber(scene.camera.instant_delay) +
                    " s), and light from it takes about " + formatNumber(lightDelay(stage, light, i, middle)) +
                    " s: set camera.instant_delay to about that";
        } else if (!hyperplane && inAnyFrame(stage, Model::Instant, i, frames)) {
            line += "model instant sees it where it is at these frame times, but its light takes about " +
                    formatNumber(lightDelay(stage, model, i, middle)) +
                    " s to reach the camera: the frames (frames.start, frames.end) come that much too early";
        } else {
            line += "check camera.look_at and " + std::string(scene.camera.orthographic() ? "camera.width" : "camera.fov_deg") +
                    ", the object's position and velocity, and the frames";
        }
        lines.push_back(line);
    }
    return lines;
}

}  // namespace apparent
