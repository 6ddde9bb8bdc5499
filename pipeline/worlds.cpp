#include "pipeline/worlds.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "mesh4d/angles.h"
#include "mesh4d/box.h"
#include "mesh4d/keyframes.h"
#include "mesh4d/worldline.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

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
    // A keyframed path: b is its fastest vertex's speed in its own frame (keyframes.h), not V's.
    double b = motion.beta, one_minus_b2 = motion.one_minus_beta2;
    if (motion.keyed) {
        for (const Vec3& p : rest.positions) b = std::max(b, mesh4d::maxKeyedSpeed(*motion.keyed, p).speed);
        b = std::min(b, 1 - 1e-9);  // the stage refused faster (finite, relativistic); instant has no limit
        one_minus_b2 = (1 - b) * (1 + b);
    }
    const double pad = diag * (1 + b) / one_minus_b2 +
                       1e-9 * std::max(std::fabs(seen.lo), std::fabs(seen.hi));
    const double open_a = seen.lo - pad, open_b = seen.hi + pad;
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
    // Step: the slabs' distance from the history in the lab, and the longest rest edge.
    const double d = offset / std::sqrt(motion.one_minus_beta2) * (1 + motion.beta);
    const double slab_shift = cone ? std::sqrt(2.0) * d : d;
    double e = 0;
    for (const auto& t : rest.triangles)
        for (int c = 0; c < 3; ++c) e = std::max(e, mesh4d::norm(rest.positions[t[c]] - rest.positions[t[(c + 1) % 3]]));
    // The least (or largest) vertex crossing of `view` with its apex time moved by `shift`.
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
    if (cone && e > 0) {
        // Step: the apex moved by e W, W the least future vector with W - U(sigma) future causal
        // for every U(sigma) with sigma in [lo', hi'] (lo' the least vertex crossing of the last
        // view, hi' the guess): in the own frame (start frame, F_V; the lab for Galilean)
        // U = (cosh phi, k sinh phi), phi = |a| max(sigma, 0), so in light-cone coordinates
        // W_+ = e^phi_hi, W_- = e^-phi_lo; then boosted with `velocity` (Lorentz).
        const double a = lorentz ? mesh4d::norm(motion.acceleration) : 0;
        const Vec3 k = a > 0 ? motion.acceleration / a : Vec3{0, 0, 0};
        const double phi_lo = a * std::max(crossings(last, slab_shift, true), 0.0);
        auto apexShift = [&](double guess) {
            const double phi_hi = a * std::max(guess, phi_lo / std::max(a, 1e-300));
            const double w_t = 0.5 * (std::exp(phi_hi) + std::exp(-phi_lo));
            const Vec3 w_x = 0.5 * (std::exp(phi_hi) - std::exp(-phi_lo)) * k;
            mesh4d::Event w{w_t, w_x};
            if (lorentz && motion.beta > 0) {
                const double g = motion.gamma;
                const Vec3 u = motion.velocity / motion.beta;
                w = {g * (w_t + mesh4d::dot(motion.velocity, w_x)),
                     w_x + (g - 1) * mesh4d::dot(w_x, u) * u + g * w_t * motion.velocity};
            }
            return w;
        };
        double guess = hi;
        out.ok = false;
        for (int round = 0; round < 8 && !out.ok; ++round) {
            mesh4d::ViewSurface moved = last;
            const mesh4d::Event w = apexShift(guess);
            moved.t_c += e * w.t;
            moved.apex = moved.apex + e * w.x;
            const double next = crossings(moved, slab_shift, false);
            if (next <= guess || a == 0) {
                hi = next;  // without an acceleration W is constant: one round is exact
                out.ok = true;
            } else {
                guess += 2 * (next - guess);  // overshoot; W grows as e^(|a| guess), so this may not close
            }
        }
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
