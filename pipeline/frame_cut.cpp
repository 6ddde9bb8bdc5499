#include "pipeline/frame_cut.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "mesh4d/check.h"
#include "mesh4d/light_factors.h"
#include "pipeline/frame_loop.h"
#include "pipeline/scene_fields.h"
#include "pipeline/worlds.h"

namespace apparent {

void cutFrameAt(const Stage& stage, const std::vector<mesh4d::World4D>& worlds, const MirrorReflections& reflections,
                const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings, bool cull_view,
                bool light_factors, ExportFrame* frame) {
    // Objects in parallel (a short range of frames of a many-object scene), each into its own
    // slot: the result does not depend on the scheduling.
    frame->objects.assign(worlds.size(), {});
    tbb::parallel_for(size_t(0), worlds.size(), [&](size_t o) {
        const mesh4d::World4D& world = worlds[o];
        // --cull-view: an object wholly outside the camera's view is left empty.
        if (cull_view && !inCameraView(stage.scene.camera, mesh4d::apparentBound(world, view))) return;
        mesh4d::SliceSettings own = settings;
        own.tolerance = stage.tolerances[o];  // each object's (pipeline/stage.h)
        frame->objects[o] = mesh4d::sliceWorld(world, view, own);
        if (light_factors) mesh4d::addLightFactors(world, view, &frame->objects[o]);
    });
    // Mirrors add their retarded reflections as further objects (pipeline/mirror.h).
    reflections.append(view, settings, &frame->objects, &stage.tolerances, light_factors);
}

FrameCutter::FrameCutter(const Stage& stage, Model model)
    : stage_(stage), model_(model),
      worlds_(buildWorlds(stage.objects, model, stage.scene, stage.first, stage.last_excl - 1)),
      reflections_(stage.scene, stage.objects, stage.mirrors, model, stage.first, stage.last_excl - 1),
      info_(sequenceInfo(stage, model)), t_first_(frameTime(stage.scene.frames, stage.first)),
      t_last_(frameTime(stage.scene.frames, stage.last_excl - 1)) {
    reflections_.describe(&info_);
}

bool FrameCutter::cut(double t_c, long long max_frame_triangles, ExportFrame* frame, std::string* error) const {
    const Scene& scene = stage_.scene;
    if (!std::isfinite(t_c) || t_c < t_first_ || t_c > t_last_) {
        *error = scene.path + ": camera time " + formatNumber(t_c) + " is outside the frames' times [" +
                 formatNumber(t_first_) + ", " + formatNumber(t_last_) + "] s";
        return false;
    }
    const long long budget = max_frame_triangles > 0 ? max_frame_triangles : defaultFrameTriangleBudget(stage_);
    mesh4d::SliceSettings settings;
    settings.tolerance = scene.tolerance;
    settings.max_triangles = size_t(budget);
    frame->t_c = t_c;
    cutFrameAt(stage_, worlds_, reflections_, viewAt(scene, model_, t_c), settings, false, true, frame);
    APPARENT_CHECK(frame->objects.size(), ==, info_.objects.size());
    // The frame loop's budget: an object's refinement stopped at it, or all objects hold more.
    const bool over = frame->triangleCount() > size_t(budget) ||
                      std::any_of(frame->objects.begin(), frame->objects.end(),
                                  [](const mesh4d::ApparentMesh& o) { return o.over_budget; });
    if (over) {
        *error = scene.path + ": camera time " + formatNumber(t_c) + ": tolerance " + formatNumber(scene.tolerance) +
                 " makes more than " + std::to_string(budget) +
                 " triangles (max_triangles); use a coarser tolerance or raise max_triangles";
        frame->objects.clear();
        return false;
    }
    return true;
}

}  // namespace apparent
