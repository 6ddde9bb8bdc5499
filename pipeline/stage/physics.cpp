#include "pipeline/stage/physics.h"

#include <algorithm>
#include <cmath>

#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/kinds.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

mesh4d::Kinematics kinematicsOf(Model m) {
    return (m == Model::Relativistic || m == Model::Contracted) ? mesh4d::Kinematics::Lorentz
                                                                 : mesh4d::Kinematics::Galilean;
}

static mesh4d::Motion uniformMotionOf(const ObjectSpec& s, Model model) {
    const mesh4d::Kinematics kin = kinematicsOf(model);
    switch (s.speed) {
        case ObjectSpec::Speed::Gamma:
            return mesh4d::makeMotionFromGamma(kin, s.t0, s.position, s.direction, s.gamma);
        case ObjectSpec::Speed::Rapidity:
            return mesh4d::makeMotionFromRapidity(kin, s.t0, s.position, s.direction, s.rapidity);
        case ObjectSpec::Speed::Velocity:
            break;
    }
    return mesh4d::makeMotion(kin, s.t0, s.position, s.velocity);
}

mesh4d::Motion motionOf(const ObjectSpec& s, Model model) {
    mesh4d::Motion m = uniformMotionOf(s, model);
    m.angular_velocity = s.angular_velocity;  // worldline.h: a spin about the origin, centre frame
    m.acceleration = s.acceleration;          // worldline.h: Born-rigid, from t0 on
    // keyed.h: the path carried in the frame of its mean velocity (s.velocity, m.velocity).
    if (s.keys) m.keyed = mesh4d::makeKeyedMotion(*s.keys, m.kinematics == mesh4d::Kinematics::Lorentz, m.t0, m.origin, m.velocity);
    m.kinds = s.kinds;  // mesh4d/motion/kinds.h: the kinds answered in their own file
    return m;
}

// A tolerance is bounded for the motions beyond uniform (mesh4d/refine/worldline_refine.h), but not the
// clip curve where the object begins or ends existing within the frames (a real cap of its world),
// nor the reflections of such an object (pipeline/stage/mirror.h: their worlds may have real caps where
// the object's own has none, and would be cut in vertex mode). `field` names the object's field,
// `what` the object ("a spinning object"). Call once every vertex is known to have a worldline.
static Status checkMotionTolerance(const PreparedObject& object, Model model, const Scene& scene, double tolerance,
                                   long long first_frame, long long last_frame, const std::string& field,
                                   const std::string& what) {
    const ObjectSpec& s = object.spec;
    if (tolerance > 0 && std::any_of(scene.objects.begin(), scene.objects.end(), [](const ObjectSpec& o) { return o.mirror; }))
        return Status::failure(field + what + " seen in a mirror is cut in vertex mode only: give --tolerance vertex "
                                          "(or the scene's \"tolerance\": \"vertex\")");
    if (!(tolerance > 0) || (!std::isfinite(s.exists_from) && !std::isfinite(s.exists_to))) return Status::success();
    const mesh4d::World4D w = buildWorld(object, model, scene, first_frame, last_frame);
    if (!w.cap_a_real && !w.cap_b_real) return Status::success();
    return Status::failure(field + what + " that begins or ends existing (exists) is cut in vertex mode only: "
                                      "give --tolerance vertex (or the scene's \"tolerance\": \"vertex\")");
}

// A keyframed path's needs (physics.h).
static Status checkKeyedMotion(const PreparedObject& object, const mesh4d::Motion& m, Model model, const Scene& scene,
                               double tolerance, long long first_frame, long long last_frame) {
    const ObjectSpec& s = object.spec;
    const std::string field = scene.path + ": " + s.keys_field + ": ";
    if (mesh4d::mixedKinds(m))
        return Status::failure(field + "a keyframed path with angular_velocity or acceleration is not modelled (give one)");
    if (cameraMotionOf(scene).moving())
        return Status::failure(field + "a keyframed object needs a camera at rest (camera.velocity is not [0, 0, 0])");
    auto tolerance_ok = [&]() {
        return checkMotionTolerance(object, model, scene, tolerance, first_frame, last_frame, field, "a keyframed object");
    };
    if (model == Model::Instant) return tolerance_ok();
    // Every vertex slower than light over every segment (keyed.h maxKeyedSpeed: the centre's
    // speed and the turn's rim speed together, closed form).
    for (size_t i = 0; i < object.rest.positions.size(); ++i) {
        const mesh4d::KeyedSpeed v = mesh4d::maxKeyedSpeed(*m.keyed, object.rest.positions[i]);
        if (!(v.speed < 1))
            return Status::failure(field + "vertex " + std::to_string(i) + " would move at " + formatNumber(v.speed) +
                                   (m.kinematics == mesh4d::Kinematics::Lorentz ? " (in the frame of the path's mean velocity)" : "") +
                                   " at lab time " + formatNumber(v.lab_time) + " s, which must be < 1 (the speed of light) for model " +
                                   modelName(model));
    }
    return tolerance_ok();
}

// The needs of a kind answered in its own file (mesh4d/motion/kinds.h): one kind at a time, a camera
// at rest, the kind's own refusals, the tolerance.
static Status checkKindMotion(const PreparedObject& object, const mesh4d::Motion& m, const mesh4d::KindAnswers& k,
                              Model model, const Scene& scene, double tolerance, long long first_frame,
                              long long last_frame) {
    const std::string field = scene.path + ": " + object.spec.field_path + "." + k.field + ": ";
    if (mesh4d::mixedKinds(m))
        return Status::failure(field + "give " + k.field + " alone: with angular_velocity, acceleration or a keyframed "
                                                           "path it is not modelled");
    if (cameraMotionOf(scene).moving())
        return Status::failure(field + k.what + " needs a camera at rest (camera.velocity is not [0, 0, 0])");
    const std::string problem = k.problem(m, object.rest.positions);
    if (!problem.empty()) return Status::failure(field + problem);
    return checkMotionTolerance(object, model, scene, tolerance, first_frame, last_frame, field, k.what);
}

// What the orthographic camera's tilted hyperplane (physics.h viewAt) cuts: uniform motion in the
// camera's frame, no mirror, and for finite a camera at rest (its light-speed models only).
static Status checkOrthographicView(const ObjectSpec& s, const mesh4d::Motion& m, Model model, const Scene& scene) {
    if (!scene.camera.orthographic() || !(model == Model::Finite || model == Model::Relativistic)) return Status::success();
    const std::string field = scene.path + ": " + s.field_path;
    const std::string why = " not modelled with camera.projection \"orthographic\" in model " + std::string(modelName(model)) +
                            " (the orthographic camera sees uniform motion; use a perspective camera far away)";
    if (s.mirror) return Status::failure(field + ".mirror: a mirror is" + why);
    if (mesh4d::kindOf(m) != mesh4d::MotionKind::Uniform)
        return Status::failure(field + ": a motion other than uniform (spin, acceleration, orbit or keyframed path) is" + why);
    if (model == Model::Finite && cameraMotionOf(scene).moving())
        return Status::failure(scene.path + ": camera.velocity: a moving camera is" + why);
    return Status::success();
}

Status checkObjectMotion(const PreparedObject& object, Model model, const Scene& scene, double tolerance,
                         long long first_frame, long long last_frame) {
    const ObjectSpec& s = object.spec;
    const mesh4d::Motion m = motionOf(s, model);
    const mesh4d::MotionKind kind = mesh4d::kindOf(m);
    if (Status o = checkOrthographicView(s, m, model, scene); !o.ok) return o;
    switch (kind) {
        case mesh4d::MotionKind::Uniform:
            return Status::success();
        case mesh4d::MotionKind::Keyed:
            return checkKeyedMotion(object, m, model, scene, tolerance, first_frame, last_frame);
        case mesh4d::MotionKind::Spin:
        case mesh4d::MotionKind::Hyperbolic:
            break;
        default:  // a kind answered in its own file (mesh4d/motion/kinds.h)
            return checkKindMotion(object, m, *mesh4d::answersOf(m), model, scene, tolerance, first_frame, last_frame);
    }
    // A spin with an acceleration (two kinds) is named by its spin, and refused below.
    const bool mixed = mesh4d::mixedKinds(m);
    const bool spin = kind == mesh4d::MotionKind::Spin || mixed;
    const std::string field = scene.path + ": " + s.field_path + (spin ? ".angular_velocity: " : ".acceleration: ");
    const std::string what = spin ? "a spinning object" : "an accelerated object";
    // The tolerance (checkMotionTolerance) last, once every vertex is known to have a worldline.
    auto tolerance_ok = [&]() {
        return checkMotionTolerance(object, model, scene, tolerance, first_frame, last_frame, field, what);
    };
    if (mixed)
        return Status::failure(field + "give angular_velocity or acceleration, not both (not modelled together)");
    if (cameraMotionOf(scene).moving())
        return Status::failure(field + what + " needs a camera at rest (camera.velocity is not [0, 0, 0])");
    // The turned angle |w| s stays finite and meaningful over every time a scene can hold.
    if (spin && !(mesh4d::norm(m.angular_velocity) <= 1e12))
        return Status::failure(field + "|angular_velocity| = " + formatNumber(mesh4d::norm(m.angular_velocity)) +
                               " must be <= 1e12 rad/s");
    if (kind == mesh4d::MotionKind::Hyperbolic) {
        // Born-rigid (mesh4d/motion/worldline.h): every vertex ahead of the horizon, q.k > -1/|a|.
        const double a = mesh4d::norm(m.acceleration);
        if (!(a >= 1e-12 && a <= 1e12))
            return Status::failure(field + "|acceleration| = " + formatNumber(a) + " must be in [1e-12, 1e12] (1/ls)");
        for (size_t i = 0; i < object.rest.positions.size(); ++i)
            if (!(mesh4d::horizonDistance(m, object.rest.positions[i]) > 0))
                return Status::failure(field + "vertex " + std::to_string(i) + " lies " +
                                       formatNumber(-mesh4d::dot(object.rest.positions[i], m.acceleration / a)) +
                                       " behind the origin along the acceleration, at or beyond the horizon of a "
                                       "Born-rigid body (1/|acceleration| = " + formatNumber(1 / a) + ")");
        // The origin's rapidity at the frames' ends, within the limit of the gamma field (1e15).
        for (long long k : {first_frame, last_frame}) {
            const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(viewForFrame(scene, model, k), m, {0, 0, 0});
            const double sigma = mesh4d::originTimeAtCrossing(m, c);
            if (!c.ok || !(std::fabs(a * sigma) <= kMaxRapidity))
                return Status::failure(field + "the origin's rapidity |a| tau reaches " + formatNumber(a * sigma) +
                                       " in frame " + std::to_string(k) + ", beyond " + formatNumber(kMaxRapidity) +
                                       " (gamma 1e15, the limit of the gamma field)");
        }
        return tolerance_ok();
    }
    // The fastest vertex (a point inside a triangle is never faster: the speed is convex in q).
    double fastest = 0;
    for (const mesh4d::Vec3& q : object.rest.positions) fastest = std::max(fastest, mesh4d::spinVertexSpeed(m, q));
    if (!std::isfinite(fastest))
        return Status::failure(field + "the speed of a vertex is not finite");
    if (model == Model::Instant) return tolerance_ok();
    if (!(fastest < 1))
        return Status::failure(field + "a vertex would move at " + formatNumber(fastest) +
                               (m.kinematics == mesh4d::Kinematics::Lorentz
                                    ? " (|w x q| in the centre frame)"
                                    : " (|velocity + w x q| in the lab, at the fastest angle)") +
                               ", which must be < 1 (the speed of light) for model " + modelName(model));
    return tolerance_ok();
}

mesh4d::CameraMotion cameraMotionOf(const Scene& scene) {
    return mesh4d::makeCameraMotion(scene.camera.position, scene.camera.velocity);
}

mesh4d::MotionInCameraFrame cameraFrameMotionOf(const ObjectSpec& s, Model model, const Scene& scene) {
    return mesh4d::motionInCameraFrame(motionOf(s, model), cameraMotionOf(scene));
}

mesh4d::MotionInCameraFrame cutMotionOf(const ObjectSpec& s, Model model, const Scene& scene) {
    if (model == Model::Finite) return {motionOf(s, model)};  // cut in the lab, sheared at output (viewAt)
    return cameraFrameMotionOf(s, model, scene);
}

const mesh4d::RestMesh& restInCameraFrame(const mesh4d::RestMesh& rest, const mesh4d::MotionInCameraFrame& m,
                                          mesh4d::RestMesh* storage) {
    if (!m.rotated) return rest;
    *storage = rest;
    for (mesh4d::Vec3& p : storage->positions) p = mesh4d::apply(m.rotation, p);
    return *storage;
}

mesh4d::ViewSurface viewForFrame(const Scene& scene, Model model, long long k) {
    return viewAt(scene, model, frameTime(scene.frames, k));
}

mesh4d::ViewSurface viewAt(const Scene& scene, Model model, double t_c) {
    mesh4d::ViewSurface view;
    view.kind = (model == Model::Finite || model == Model::Relativistic) ? mesh4d::ViewKind::PastCone
                                                                         : mesh4d::ViewKind::Hyperplane;
    view.t_c = t_c;
    // The hyperplane models may look back by the stage's light delay (scene camera.instant_delay).
    if (view.kind == mesh4d::ViewKind::Hyperplane) view.t_c -= scene.camera.instant_delay;
    view.apex = scene.camera.position;
    // The orthographic camera of the light-speed models: the null hyperplane of the light that
    // crosses its image plane at t_c (lightcone.h).
    if (scene.camera.orthographic() && view.kind == mesh4d::ViewKind::PastCone) {
        const mesh4d::Vec3 k = scene.camera.look_at - scene.camera.position;
        view.kind = mesh4d::ViewKind::Hyperplane;
        view.tilt = k / mesh4d::norm(k);
        return view;
    }
    // The finite model with a moving camera: light moves at c in the lab, so the cone is the lab's,
    // from the camera's lab position at t_c (its proper time, the lab's under Galilean kinematics),
    // and the outputs are sheared into the camera's frame, x' = x - v t (slice.h sliceWorld).
    const mesh4d::CameraMotion camera = cameraMotionOf(scene);
    if (model == Model::Finite && camera.moving()) {
        view.apex = camera.position + camera.velocity * t_c;
        view.shear = camera.velocity;
    }
    return view;
}

}  // namespace apparent
