#include "pipeline/stage/frame_cut.h"

#include <algorithm>
#include <cmath>
#ifdef __GLIBC__
#include <malloc.h>  // mallopt
#endif

#include "mesh4d/check.h"
#include "mesh4d/light_factors.h"
#include "mesh4d/parallel.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

long long defaultFrameTriangleBudget(const Stage& stage) {
    long long input = 0;
    for (const PreparedObject& o : stage.objects) input += (long long)o.rest.triangles.size();
    input *= 1 + (long long)stage.mirrors.size();
    return std::max(kMinFrameTriangleBudget, 4 * input);
}

SequenceInfo sequenceInfo(const Stage& stage, Model model) {
    const Scene& scene = stage.scene;
    SequenceInfo info;
    info.model = modelName(model);
    const double u = unitsPerLightSecond(scene.units);  // the outputs' lengths (cutFrameAt)
    info.tolerance = scene.tolerance * u;
    info.units = unitsText(scene.units);
    info.fps = scene.frames.fps;
    info.scene_path = scene.path;
    for (size_t i = 0; i < stage.objects.size(); ++i) {
        ExportObject o;
        o.name = stage.objects[i].spec.name;
        o.base_color = objectBaseColor(stage.objects, i);
        o.metallic = stage.objects[i].spec.material.metallic;
        o.roughness = stage.objects[i].spec.material.roughness;
        o.emissive = stage.objects[i].spec.material.emissive;
        if (stage.objects[i].look) {
            o.look = stage.objects[i].look;
            o.rest = std::make_shared<const mesh4d::RestMesh>(stage.objects[i].rest);
        }
        info.objects.push_back(o);
    }
    info.camera.position = scene.camera.position * u;
    info.camera.look_at = scene.camera.look_at * u;
    info.camera.up = scene.camera.up;
    info.camera.fov_deg = scene.camera.fov_deg;
    if (scene.camera.orthographic()) info.camera.width = scene.camera.width;
    info.light.point = scene.light.kind == LightSpec::Kind::Point;
    info.light.position = scene.light.position * u;
    info.light.direction = scene.light.direction;
    info.light.ambient = scene.light.ambient;
    info.light.key_direction = scene.light.key_direction;
    info.light.key_weight = scene.light.key_weight;
    return info;
}

void keepFreedMemory() {
#ifdef __GLIBC__
    ::mallopt(M_MMAP_THRESHOLD, kFreedMemoryKeep);
    ::mallopt(M_TRIM_THRESHOLD, kFreedMemoryKeep);
#endif
}

void cutFrameAt(const Stage& stage, const std::vector<mesh4d::World4D>& worlds, const MirrorReflections& reflections,
                const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings, bool cull_view,
                bool light_factors, ExportFrame* frame) {
    // Objects in parallel (a short range of frames of a many-object scene), each into its own
    // slot: the result does not depend on the scheduling.
    frame->objects.assign(worlds.size(), {});
    mesh4d::parallelFor(size_t(0), worlds.size(), [&](size_t o) {
        const mesh4d::World4D& world = worlds[o];
        // --cull-view: an object wholly outside the camera's view is left empty.
        if (cull_view && !inCameraView(stage.scene.camera, mesh4d::apparentBound(world, view))) return;
        mesh4d::SliceSettings own = settings;
        own.tolerance = stage.tolerances[o];  // each object's (pipeline/stage/stage.h)
        if (o < stage.attribute_tolerances.size()) own.attribute_tolerance = stage.attribute_tolerances[o];
        frame->objects[o] = mesh4d::sliceWorld(world, view, own);
        if (light_factors) mesh4d::addLightFactors(world, view, &frame->objects[o]);
    });
    // Mirrors add their retarded reflections as further objects (pipeline/stage/mirror.h).
    reflections.append(view, settings, &frame->objects, &stage.tolerances, light_factors,
                       stage.attribute_tolerances.empty() ? nullptr : &stage.attribute_tolerances);
    // Step: the outputs' lengths in the scene's units (pipeline/input/units.h).
    frame->units.clear();
    if (const double u = unitsPerLightSecond(stage.scene.units); u != 1) {
        frame->units = unitsText(stage.scene.units);
        for (mesh4d::ApparentMesh& m : frame->objects) {
            m.origin = m.origin * u;
            for (mesh4d::Vec3& p : m.positions) p = p * u;
        }
    }
}

struct FrameCutter::Histories {
    std::vector<mesh4d::World4D> worlds;
    MirrorReflections reflections;

    // As the frame loop builds them for frames [first, last] of `scene` (global numbers).
    Histories(const Stage& stage, const Scene& scene, Model model, long long first, long long last)
        : worlds(buildWorlds(stage.objects, model, scene, first, last)),
          reflections(scene, stage.objects, stage.mirrors, model, first, last) {}
};

FrameCutter::FrameCutter(const Stage& stage, Model model)
    : stage_(stage), model_(model),
      range_(std::make_shared<const Histories>(stage, stage.scene, model, stage.first, stage.last_excl - 1)),
      info_(sequenceInfo(stage, model)), t_first_(frameTime(stage.scene.frames, stage.first)),
      t_last_(frameTime(stage.scene.frames, stage.last_excl - 1)) {
    range_->reflections.describe(&info_);
}

FrameCutter::~FrameCutter() = default;

std::shared_ptr<const FrameCutter::Histories> FrameCutter::historiesFor(double t_c, std::string* error) const {
    if (t_c >= t_first_ && t_c <= t_last_) return range_;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const auto& kept : spans_)
            if (kept.first == t_c) return kept.second;
    }
    // Step: the scene with its frames moved to one frame at t_c, and the command's checks of it.
    Scene moved = stage_.scene;
    moved.frames.start = t_c;
    moved.frames.end = t_c + 0.5 / moved.frames.fps;
    if (Status s = checkViewedTime(moved, 0); !s.ok) {
        *error = s.message;
        return nullptr;
    }
    for (size_t i = 0; i < stage_.objects.size(); ++i)
        if (Status s = checkObjectMotion(stage_.objects[i], model_, moved, stage_.tolerances[i], 0, 0); !s.ok) {
            *error = s.message;
            return nullptr;
        }
    // Step: its histories, built outside the lock (two threads may build the same; one is kept).
    auto built = std::make_shared<const Histories>(stage_, moved, model_, 0, 0);
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& kept : spans_)
        if (kept.first == t_c) return kept.second;
    spans_.emplace_back(t_c, built);
    if (spans_.size() > kSpansKept) spans_.pop_front();
    return built;
}

bool FrameCutter::cut(double t_c, long long max_frame_triangles, ExportFrame* frame, std::string* error) const {
    const Scene& scene = stage_.scene;
    if (!std::isfinite(t_c)) {
        *error = scene.path + ": camera time " + formatNumber(t_c) + " is not finite";
        return false;
    }
    const std::shared_ptr<const Histories> histories = historiesFor(t_c, error);
    if (!histories) return false;
    const long long budget = max_frame_triangles > 0 ? max_frame_triangles : defaultFrameTriangleBudget(stage_);
    mesh4d::SliceSettings settings;
    settings.tolerance = scene.tolerance;
    settings.max_triangles = size_t(budget);
    frame->t_c = t_c;
    cutFrameAt(stage_, histories->worlds, histories->reflections, viewAt(scene, model_, t_c), settings, false, true, frame);
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
