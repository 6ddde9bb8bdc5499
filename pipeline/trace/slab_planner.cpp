#include "pipeline/trace/slab_planner.h"

#include <string>
#include <vector>

#include "mesh4d/box.h"
#include "mesh4d/motion/kinds.h"
#include "pipeline/trace/raytrace.h"

namespace apparent {

using mesh4d::Vec3;

// The slabs' chord in the object's own frame (above) for `mesh` moving with `motion`.
double slabChord(const mesh4d::RestMesh& mesh, const mesh4d::Motion& motion) {
    mesh4d::EventBox box;
    for (const Vec3& p : mesh.positions) box.addPoint(p);
    const double g = 1 / std::sqrt(motion.one_minus_beta2);
    return kSlabChordRelative * box.diagonal() / (g * (1 + motion.beta));
}

// The world of `object` extruded over the union of the spans seen from the camera and from each
// mirror image of the camera, so that reflected rays, which reach further into the past, stay
// inside the history. Existence caps stay real where they clip either span. buildWorld's span,
// padded by the light-crossing time over 1 - b: what a uniform motion is traced over.
mesh4d::World4D traceWorld(const PreparedObject& object, Model model, const Scene& scene,
                           const std::vector<MirrorPlane>& mirrors, long long first, long long last) {
    mesh4d::World4D direct = buildWorld(object, model, scene, first, last);
    if (mirrors.empty()) return direct;
    double tau_a = direct.empty() ? INFINITY : direct.tau_a, tau_b = direct.empty() ? -INFINITY : direct.tau_b;
    bool real_a = direct.cap_a_real, real_b = direct.cap_b_real;
    // A moving camera: the image cameras' views in the frame traced (mirror.h imageView), the rest
    // points as that frame has them (the Thomas-Wigner rotation).
    const bool moving = cameraMotionOf(scene).moving();
    const mesh4d::MotionInCameraFrame in_cut = cutMotionOf(object.spec, model, scene);
    mesh4d::RestMesh rotated;
    const mesh4d::RestMesh& rest = restInCameraFrame(object.rest, in_cut, &rotated);
    for (const MirrorPlane& m : mirrors) {
        Scene image = scene;
        image.camera.position = reflectPoint(m, scene.camera.position);
        const mesh4d::World4D w =
            moving ? extrudeSeen(object.spec, rest, in_cut.motion, imageView(m, scene, model, frameTime(scene.frames, first)),
                                 imageView(m, scene, model, frameTime(scene.frames, last)))
                   : buildWorld(object, model, image, first, last);
        if (w.empty()) continue;
        if (w.tau_a < tau_a) { tau_a = w.tau_a; real_a = w.cap_a_real; }
        if (w.tau_b > tau_b) { tau_b = w.tau_b; real_b = w.cap_b_real; }
    }
    if (!(tau_a < tau_b)) return direct;
    return mesh4d::extrude(rest, direct.motion, tau_a, tau_b, real_a, real_b);
}

namespace {

// The scene field that states a slabbed object's motion (for messages).
std::string motionField(const ObjectSpec& spec, const mesh4d::Motion& motion) {
    switch (mesh4d::kindOf(motion)) {
        case mesh4d::MotionKind::Keyed:
            return spec.keys_field;
        case mesh4d::MotionKind::Spin:
            return spec.field_path + ".angular_velocity";
        case mesh4d::MotionKind::Uniform:
        case mesh4d::MotionKind::Hyperbolic:
            break;
        default:  // a kind answered in its own file (mesh4d/motion/kinds.h)
            return spec.field_path + "." + mesh4d::answersOf(motion)->field;
    }
    return spec.field_path + ".acceleration";
}

// One line when some frame alone would need more slabs than the limits allow (a window of one
// frame, SceneTracer): more than kMaxTraceSlabs of one object, or more prisms than `slab_memory`
// holds; longer ranges are traced in windows.
Status checkTraceSlabs(const Stage& stage, const std::vector<Model>& models, long long first, long long last,
                       long long slab_memory) {
    const size_t max_prisms = slabPrismLimit(slab_memory);
    for (Model model : models) {
        const SlabPlanner planner(stage.scene, stage.objects, stage.mirrors, model, false);
        if (planner.objects().empty()) continue;
        for (long long k = first; k <= last;) {
            const long long end = planner.windowEnd(k, last, kMaxTraceSlabs, max_prisms);
            if (end >= k) {
                k = end + 1;
                continue;
            }
            size_t worst = 0, n = 0, prisms = 0;
            planner.fits(k, k, kMaxTraceSlabs, max_prisms, &worst, &n, &prisms);
            const SlabPlanner::Slabbed& o = planner.objects()[worst];
            const std::string where = stage.scene.path + ": " + motionField(o.prepared.spec, o.motion) + ": the raytracer would need ";
            const std::string model_name = std::string(" for model ") + modelName(model);
            if (n > kMaxTraceSlabs)
                return Status::failure(where + "more than " + std::to_string(kMaxTraceSlabs) + " time slabs of " +
                                       std::to_string(o.rest.triangles.size()) + " prisms for frame " + std::to_string(k) +
                                       " alone (at most " + std::to_string(kMaxTraceSlabs) + " for one object)" +
                                       model_name + ": use `apparent render`");
            return Status::failure(where + std::to_string(n) + " time slabs of " + std::to_string(o.rest.triangles.size()) +
                                   " prisms for frame " + std::to_string(k) + " alone (" + std::to_string(prisms) +
                                   " prisms of time slabs in all, about " +
                                   std::to_string((long long)prisms * kTraceBytesPerPrism >> 20) +
                                   " MiB, more than --max-slab-memory " + std::to_string(slab_memory) + " bytes holds: " +
                                   std::to_string(max_prisms) + " prisms)" + model_name +
                                   ": raise it, or use `apparent render`");
        }
    }
    return Status::success();
}

}  // namespace

Status checkTracedMotions(const Stage& stage, long long slab_memory) {
    return checkTraceSlabs(stage, stage.models, stage.first, stage.last_excl - 1, slab_memory);
}

}  // namespace apparent
