#include "pipeline/worlds.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "mesh4d/angles.h"
#include "mesh4d/box.h"
#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/latest_crossing.h"
#include "mesh4d/motion/worldline.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

// pathSpanSeen's refinement of an accelerated body's latest crossing (mesh4d/motion/latest_crossing.h):
// it stops within kLatestTolerance x the slabs' offset (in the body's time) of the latest crossing
// computed, or after kLatestMaxSplits splits (the bound is sound either way; a looser one costs
// slabs, at most a few at the spacing of the slab grid).
constexpr double kLatestTolerance = 4;
constexpr size_t kLatestMaxSplits = 4096;
// buildWorld's pad of an accelerated body is at most kPadReach / |a| of its time: e^64 = 6e27.
constexpr double kPadReach = 64;

// The rest mesh `*mesh` in the frame of the cut, rotated in place where that needs it (as
// restInCameraFrame, without the copy).
const mesh4d::RestMesh& rotateInCameraFrame(mesh4d::RestMesh* mesh, const mesh4d::MotionInCameraFrame& m) {
    if (m.rotated)
        for (Vec3& p : mesh->positions) p = mesh4d::apply(m.rotation, p);
    return *mesh;
}

// extrudeSeen; with `take` (then `rest` is *take) the mesh is handed to the world, not copied.
mesh4d::World4D extrudeSeenFrom(const ObjectSpec& s, const mesh4d::RestMesh& rest, mesh4d::RestMesh* take,
                                const mesh4d::Motion& motion, const mesh4d::ViewSurface& first,
                                const mesh4d::ViewSurface& last) {
    // Step: the proper-time span the requested frames can see, padded by the object's own light
    // crossing time so that rounding in the vertex crossings never reaches an artificial cap.
    const mesh4d::ProperTimeSpan seen = mesh4d::spanSeen(rest, motion, first, last);
    mesh4d::EventBox box;
    for (const Vec3& p : rest.positions) box.addPoint(p);
    // Interior points of a triangle can emit up to diag (1 + b) / (1 - b^2) = diag / (1 - b) later or
    // earlier than its vertices (the crossing time's slope along the surface is at most 1/(1 - b)).
    const double diag = box.diagonal();
    // A keyframed path: b is its fastest vertex's speed in its own frame (keyed.h), not V's.
    double b = motion.beta, one_minus_b2 = motion.one_minus_beta2;
    if (motion.keyed) {
        for (const Vec3& p : rest.positions) b = std::max(b, mesh4d::maxKeyedSpeed(*motion.keyed, p).speed);
        b = std::min(b, 1 - 1e-9);  // the stage refused faster (finite, relativistic); instant has no limit
        one_minus_b2 = (1 - b) * (1 + b);
    }
    // An acceleration: b is the fastest speed over the seen span. At one s every point moves with
    // the origin's lab velocity (Born-rigid: the momentary rest frame's; Galilean: the carry's), and
    // its gamma is gamma_V before t0, then gamma_V sqrt(1 - B^2) cosh(|a| s + atanh B) (B = V.k):
    // it falls, if at all, only back to gamma_V before it rises, so the fastest is at an end of the
    // span. That pad is capped at kPadReach / |a| of the object's time (worldline events stay below
    // e^kPadReach / |a|, their squares finite); the span proven sound (pathSpanSeen,
    // mesh4d/motion/latest_crossing.h for Born-rigid bodies) is held whatever the pad.
    const double a = mesh4d::norm(motion.acceleration);
    double speed_cap = INFINITY;
    mesh4d::ProperTimeSpan sound = seen;
    if (a > 0 && std::isfinite(seen.lo) && std::isfinite(seen.hi)) {
        for (double at : {seen.lo, seen.hi}) b = std::max(b, mesh4d::norm(mesh4d::worldlineVelocity(motion, at, Vec3{0, 0, 0})));
        b = std::min(b, 1 - 1e-9);
        one_minus_b2 = (1 - b) * (1 + b);
        speed_cap = kPadReach / a;
        // (An offset of 1e-3 diag, as the raytracer's slabs: it widens the span by a few of it and
        // ends the refinement within 4e-3 diag of the latest crossing, not at its split budget.)
        const SeenSpan proven = pathSpanSeen(rest, motion, first, last, 1e-3 * diag);
        if (proven.ok) sound = proven.span;
    }
    const double rounding = 1e-9 * std::max(std::fabs(seen.lo), std::fabs(seen.hi));
    const double pad = std::min(diag * (1 + b) / one_minus_b2, speed_cap) + rounding;
    const double open_a = std::min(seen.lo - pad, sound.lo - rounding), open_b = std::max(seen.hi + pad, sound.hi + rounding);
    // Step: clip the span to the object's existence; only those ends are real caps.
    const bool cap_a_real = s.exists_from > open_a;
    const bool cap_b_real = s.exists_to < open_b;
    const double tau_a = cap_a_real ? s.exists_from : open_a;
    const double tau_b = cap_b_real ? s.exists_to : open_b;
    if (!(tau_a < tau_b)) {
        mesh4d::World4D empty;
        empty.motion = motion;
        return empty;
    }
    if (take) return mesh4d::extrude(std::move(*take), motion, tau_a, tau_b, cap_a_real, cap_b_real);
    return mesh4d::extrude(rest, motion, tau_a, tau_b, cap_a_real, cap_b_real);
}

}  // namespace

namespace {

// buildWorld; with `take` (object.rest itself) the rest mesh is moved into the world, rotated in
// place into the camera's frame where that needs it, instead of copied.
mesh4d::World4D buildWorldFrom(const PreparedObject& object, mesh4d::RestMesh* take, Model model, const Scene& scene,
                               long long first_frame, long long last_frame) {
    // In the frame the cut is made in (the camera's rest frame; the lab for finite): its motion
    // and rest points.
    const mesh4d::MotionInCameraFrame in_camera = cutMotionOf(object.spec, model, scene);
    mesh4d::RestMesh rotated;
    const mesh4d::RestMesh& rest = take ? rotateInCameraFrame(take, in_camera) : restInCameraFrame(object.rest, in_camera, &rotated);
    return extrudeSeenFrom(object.spec, rest, take, in_camera.motion, viewForFrame(scene, model, first_frame),
                           viewForFrame(scene, model, last_frame));
}

}  // namespace

mesh4d::World4D buildWorld(const PreparedObject& object, Model model, const Scene& scene, long long first_frame,
                           long long last_frame) {
    return buildWorldFrom(object, nullptr, model, scene, first_frame, last_frame);
}

mesh4d::World4D extrudeSeen(const ObjectSpec& s, const mesh4d::RestMesh& rest, const mesh4d::Motion& motion,
                            const mesh4d::ViewSurface& first, const mesh4d::ViewSurface& last) {
    return extrudeSeenFrom(s, rest, nullptr, motion, first, last);
}

mesh4d::ProperTimeSpan spinSpanSeen(const mesh4d::RestMesh& rest, const mesh4d::Motion& motion,
                                    const mesh4d::ViewSurface& first, const mesh4d::ViewSurface& last, double offset) {
    const bool lorentz = motion.kinematics == mesh4d::Kinematics::Lorentz;
    const bool cone = first.kind == mesh4d::ViewKind::PastCone;
    double r = 0, u = 0;
    for (const Vec3& q : rest.positions) {
        r = std::max(r, mesh4d::norm(q));
        u = std::max(u, lorentz ? mesh4d::spinSpeed(motion, q) : mesh4d::maxGalileanSpeed(motion, q));
    }
    const Vec3 origin{0, 0, 0};
    auto originCrossing = [&](mesh4d::ViewSurface view, double apex_shift) {
        view.t_c += apex_shift;
        return mesh4d::crossWorldline(view, motion, origin).s;
    };
    mesh4d::ProperTimeSpan span;
    if (lorentz) {
        const double reach = cone ? r : motion.beta * r;
        span = {originCrossing(first, 0) - reach, originCrossing(last, 0) + reach};
    } else if (cone) {
        span = {originCrossing(first, -r), originCrossing(last, r)};
    } else {
        span = {originCrossing(first, 0), originCrossing(last, 0)};
    }
    const double widen = 2 * offset / std::max(1e-12, 1 - u) + 1e-9 * std::max(std::fabs(span.lo), std::fabs(span.hi));
    return {span.lo - widen, span.hi + widen};
}

SeenSpan pathSpanSeen(const mesh4d::RestMesh& rest, const mesh4d::Motion& motion, const mesh4d::ViewSurface& first,
                      const mesh4d::ViewSurface& last, double offset) {
    const bool lorentz = motion.kinematics == mesh4d::Kinematics::Lorentz;
    const bool cone = first.kind == mesh4d::ViewKind::PastCone;
    const bool accelerated = mesh4d::norm(motion.acceleration) > 0;
    // Step: the slabs' distance from the history in the lab, and the longest rest edge.
    const double d = offset / std::sqrt(motion.one_minus_beta2) * (1 + motion.beta);
    const double slab_shift = cone ? std::sqrt(2.0) * d : d;
    double e = 0;
    for (const auto& t : rest.triangles)
        for (int c = 0; c < 3; ++c) e = std::max(e, mesh4d::norm(rest.positions[t[c]] - rest.positions[t[(c + 1) % 3]]));
    // The largest vertex crossing of `view` with its apex time moved by `shift`, or the least.
    auto crossings = [&](mesh4d::ViewSurface view, double shift, bool least) {
        view.t_c += shift;
        double s = least ? INFINITY : -INFINITY;
        for (const Vec3& q : rest.positions) {
            const double c = mesh4d::crossWorldline(view, motion, q).s;
            s = least ? std::min(s, c) : std::max(s, c);
        }
        return s;
    };
    SeenSpan out;
    const double lo = crossings(first, -slab_shift, true);
    double hi = crossings(last, slab_shift, false);
    if (cone && lorentz && accelerated) {
        // Step: Born-rigid acceleration, the latest crossing of any point of the triangles, bounded
        // in the body's own (Rindler) time and refined to within kLatestTolerance offsets
        // (mesh4d/motion/latest_crossing.h).
        mesh4d::ViewSurface moved = last;
        moved.t_c += slab_shift;
        const mesh4d::LatestCrossing latest = mesh4d::latestCrossing(rest, motion, moved, kLatestTolerance * offset,
                                                                     kLatestMaxSplits);
        out.ok = latest.ok;
        hi = std::max(hi, latest.bound);
    } else if (cone && e > 0) {
        // Step: a keyframed path (F_V) or a Galilean carry (the lab): F(s) is one frame for every
        // s, so the vertex within e of a point crosses the view whose apex is moved by e U, U that
        // frame's 4-velocity (boosted with `velocity` for Lorentz), at or after the point.
        mesh4d::Event w{1, {0, 0, 0}};
        if (lorentz && motion.beta > 0) w = {motion.gamma, motion.gamma * motion.velocity};
        mesh4d::ViewSurface moved = last;
        moved.t_c += e * w.t;
        moved.apex = moved.apex + e * w.x;
        hi = crossings(moved, slab_shift, false);
    }
    if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi)) out.ok = false;
    const double widen = 1e-9 * std::max(std::fabs(lo), std::fabs(hi));
    out.span = {lo - widen, hi + widen};
    return out;
}

std::vector<mesh4d::World4D> buildWorlds(const std::vector<PreparedObject>& objects, Model model, const Scene& scene,
                                         long long first_frame, long long last_frame) {
    std::vector<mesh4d::World4D> worlds;
    worlds.reserve(objects.size());
    for (const PreparedObject& o : objects) worlds.push_back(buildWorld(o, model, scene, first_frame, last_frame));
    return worlds;
}

std::vector<mesh4d::World4D> takeWorlds(std::vector<PreparedObject>* objects, Model model, const Scene& scene,
                                        long long first_frame, long long last_frame) {
    std::vector<mesh4d::World4D> worlds;
    worlds.reserve(objects->size());
    for (PreparedObject& o : *objects) {
        worlds.push_back(buildWorldFrom(o, &o.rest, model, scene, first_frame, last_frame));
        o.rest = {};  // left valid and empty whether or not the world took it
    }
    return worlds;
}

bool inCameraView(const CameraSpec& camera, const mesh4d::BoundingSphere& bound) {
    const Vec3 d = bound.center - camera.position;
    const double dist = mesh4d::norm(d);
    if (!(dist > bound.radius)) return true;  // the camera is inside the sphere (or NaN: keep it)
    const Vec3 f = camera.look_at - camera.position;
    const double cos_angle = std::clamp(mesh4d::dot(d, f) / (dist * mesh4d::norm(f)), -1.0, 1.0);
    const double angle = std::acos(cos_angle);                  // centre off the view axis
    const double angular_radius = std::asin(bound.radius / dist);
    const double half_fov = 0.5 * camera.fov_deg * mesh4d::kPi / 180.0;
    const double half_diagonal = std::atan(std::tan(half_fov) * std::sqrt(1 + kCullAspect * kCullAspect));
    return angle - angular_radius <= half_diagonal;
}

}  // namespace apparent
