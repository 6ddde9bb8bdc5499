#include "pipeline/stage/stage.h"

#include <algorithm>
#include <cmath>
#include <ostream>

#include "mesh4d/box.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/physics.h"

#include "pipeline/input/json_limits.h"

namespace apparent {

Status checkViewedTime(const Scene& scene, long long k) {
    auto outOfRange = [](double v) { return !(std::fabs(v) <= kMaxCoordinate); };
    if (outOfRange(frameTime(scene.frames, k)) || outOfRange(frameTime(scene.frames, k) - scene.camera.instant_delay))
        return Status::failure(scene.path + ": frames, camera.instant_delay: the viewed time of frame " + std::to_string(k) +
                               " is not finite or beyond " + formatNumber(kMaxCoordinate) + " s");
    return Status::success();
}

bool loadStage(const StageOptions& options, Stage* stage, std::ostream& log, std::string* error) {
    auto fail = [&](const std::string& message) {
        *error = printable(message, 4096);  // one line, whatever a file or key holds
        return false;
    };
    // Step: the scene's file name goes into the outputs (the .glb's extras are JSON, UTF-8 only):
    // checked before any work, printed escaped.
    if (!isValidUtf8(options.scene_path))
        return fail(options.scene_path + ": the file name is not valid UTF-8 (it is written into the outputs; rename the file)");
    // Step: the scene, the tolerance override and the models it must be valid for.
    Scene& scene = stage->scene;
    if (Status s = loadScene(options.scene_path, &scene); !s.ok) return fail(s.message);
    // Properties the scene reader kept but did not use (a misspelt field in glTF extras): said once.
    if (!options.quiet)
        for (const std::string& w : scene.warnings) log << "warning: " << w << "\n";
    if (options.has_tolerance) {
        scene.tolerance = options.tolerance * lightSecondsPer(scene.units);  // --tolerance T: in the scene's units
        scene.tolerance_relative = options.tolerance_relative;
    }
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
    // Step: what the inputs derive, before any work: finite and in range, bounded in number.
    if (options.max_object_frames <= 0) return fail("--max-object-frames: must be positive");
    const long long frames = stage->last_excl - stage->first;
    const long long slices_per_frame = (long long)stage->objects.size() * (1 + (long long)stage->mirrors.size());
    if (slices_per_frame > options.max_object_frames / frames)
        return fail(scene.path + ": objects: " + std::to_string(stage->objects.size()) + " objects x " +
                    std::to_string(1 + stage->mirrors.size()) + " (themselves and " + std::to_string(stage->mirrors.size()) +
                    " mirrors' reflections) x " + std::to_string(frames) + " frames exceed the limit of " +
                    std::to_string(options.max_object_frames) + " object-frames (raise it with --max-object-frames)");
    auto outOfRange = [](double v) { return !(std::fabs(v) <= kMaxCoordinate); };
    for (const long long k : {stage->first, stage->last_excl - 1})
        if (Status s = checkViewedTime(scene, k); !s.ok) return fail(s.message);
    double largest = 0;
    std::vector<double> sizes;  // each object's bounding-box diagonal
    for (const PreparedObject& o : stage->objects) {
        // Beyond 1e9 degrees an angle has no fractional degree left in a double.
        const mesh4d::Vec3& r = o.spec.rotation_deg;
        if (!(std::fabs(r.x) <= 1e9 && std::fabs(r.y) <= 1e9 && std::fabs(r.z) <= 1e9))
            return fail(scene.path + ": " + o.spec.field_path + ".rotation_deg: beyond 1e9 degrees (no precision left)");
        mesh4d::EventBox box;
        for (size_t i = 0; i < o.rest.positions.size(); ++i) {
            const mesh4d::Vec3& p = o.rest.positions[i];
            if (outOfRange(p.x) || outOfRange(p.y) || outOfRange(p.z) || outOfRange(p.x + o.spec.position.x) ||
                outOfRange(p.y + o.spec.position.y) || outOfRange(p.z + o.spec.position.z))
                return fail(scene.path + ": " + o.spec.field_path + ": vertex " + std::to_string(i) +
                            " after scale, rotation_deg and position is not finite or beyond " + formatNumber(kMaxCoordinate) +
                            " light-seconds");
            box.addPoint(p);
        }
        sizes.push_back(o.rest.positions.empty() ? 0.0 : box.diagonal());
        largest = std::max(largest, sizes.back());
    }
    // Step: each object's tolerance; a relative one follows the object's own size, so the same
    // scene at any scale gives the same triangles.
    stage->tolerances.assign(stage->objects.size(), scene.tolerance);
    if (scene.tolerance_relative > 0) {
        double smallest = 0;
        for (size_t i = 0; i < sizes.size(); ++i) {
            // Never below the floor of the largest object (a speck beside a huge backdrop).
            stage->tolerances[i] = std::max(scene.tolerance_relative * (sizes[i] > 0 ? sizes[i] : largest),
                                            kToleranceFloorRelative * largest);
            if (stage->tolerances[i] > 0 && (smallest == 0 || stage->tolerances[i] < smallest)) smallest = stage->tolerances[i];
        }
        scene.tolerance = smallest;
        if (!(smallest > 0))
            return fail(scene.path + ": tolerance: every object has size 0, so a tolerance relative to the size is 0; "
                        "give one in light-seconds (--tolerance T) or 'vertex'");
    }
    // Step: each object's attribute tolerance (--attribute-tolerance), as its tolerance is made.
    stage->attribute_tolerances.assign(stage->objects.size(), INFINITY);
    for (size_t i = 0; i < sizes.size(); ++i) {
        if (options.attribute_tolerance_relative > 0)
            stage->attribute_tolerances[i] = std::max(options.attribute_tolerance_relative * (sizes[i] > 0 ? sizes[i] : largest),
                                                      kToleranceFloorRelative * largest);
        else if (options.attribute_tolerance > 0)
            stage->attribute_tolerances[i] = options.attribute_tolerance * lightSecondsPer(scene.units);  // in the scene's units
    }
    const double floor = kToleranceFloorRelative * largest;
    if (scene.tolerance_relative > 0 && scene.tolerance_relative < kToleranceFloorRelative)
        return fail(scene.path + ": tolerance (or --tolerance): " + formatNumber(scene.tolerance_relative) +
                    "x is below the floor of " + formatNumber(kToleranceFloorRelative) +
                    "x (float32 output cannot show finer): use a coarser --tolerance, or 'vertex'");
    if (scene.tolerance_relative == 0 && scene.tolerance > 0 && scene.tolerance < floor)
        return fail(scene.path + ": tolerance (or --tolerance): " + formatNumber(scene.tolerance) + " light-seconds is below the floor of " +
                    formatNumber(floor) + " (1e-6 of the largest object's size, " + formatNumber(largest) +
                    "; float32 output cannot show finer): use a coarser --tolerance, or 'vertex'");
    // Step: motions beyond uniform (spin, acceleration): what they need, per model.
    for (Model m : stage->models)
        for (size_t i = 0; i < stage->objects.size(); ++i)
            if (Status s = checkObjectMotion(stage->objects[i], m, scene, stage->tolerances[i], stage->first,
                                             stage->last_excl - 1);
                !s.ok)
                return fail(s.message);
    return true;
}

std::vector<long long> sampledFrames(const Stage& stage, bool all) {
    std::vector<long long> frames;
    if (all) {
        for (long long k = stage.first; k < stage.last_excl; ++k) frames.push_back(k);
        return frames;
    }
    const long long total = stage.last_excl - stage.first;
    const long long n = std::min<long long>(5, total);
    for (long long i = 0; i < n; ++i) frames.push_back(stage.first + (n == 1 ? 0 : i * (total - 1) / (n - 1)));
    return frames;
}

}  // namespace apparent
