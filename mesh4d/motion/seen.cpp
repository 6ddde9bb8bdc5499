#include "mesh4d/motion/seen.h"

#include <algorithm>
#include <cmath>

#include "mesh4d/box.h"
#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/kinds.h"
#include "mesh4d/motion/latest_crossing.h"
#include "mesh4d/motion/worldline.h"

namespace mesh4d {

namespace {

// pathSpanSeen's refinement of an accelerated body's latest crossing (latest_crossing.h): it
// stops within kLatestTolerance x the slabs' offset (in the body's time) of the latest crossing
// computed, or after kLatestMaxSplits splits (the bound is sound either way; a looser one costs
// slabs, at most a few at the spacing of the slab grid).
constexpr double kLatestTolerance = 4;
constexpr size_t kLatestMaxSplits = 4096;
// paddedSpanSeen's pad of an accelerated body is at most kPadReach / |a| of its time: e^64 = 6e27.
constexpr double kPadReach = 64;

}  // namespace

ProperTimeSpan paddedSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first,
                              const ViewSurface& last) {
    // Step: the proper-time span the requested frames can see, padded by the object's own light
    // crossing time so that rounding in the vertex crossings never reaches an artificial cap.
    const ProperTimeSpan seen = spanSeen(rest, motion, first, last);
    EventBox box;
    for (const Vec3& p : rest.positions) box.addPoint(p);
    // Interior points of a triangle can emit up to diag (1 + b) / (1 - b^2) = diag / (1 - b) later or
    // earlier than its vertices (the crossing time's slope along the surface is at most 1/(1 - b)).
    const double diag = box.diagonal();
    double b = motion.beta, one_minus_b2 = motion.one_minus_beta2;
    double speed_cap = INFINITY;
    ProperTimeSpan sound = seen;
    switch (kindOf(motion)) {
        case MotionKind::Uniform:
        case MotionKind::Spin:
            break;
        case MotionKind::Keyed:
            // A keyframed path: b is its fastest vertex's speed in its own frame (keyed.h), not V's.
            for (const Vec3& p : rest.positions) b = std::max(b, maxKeyedSpeed(*motion.keyed, p).speed);
            b = std::min(b, 1 - 1e-9);  // the stage refused faster (finite, relativistic); instant has no limit
            one_minus_b2 = (1 - b) * (1 + b);
            break;
        case MotionKind::Hyperbolic: {
            // An acceleration: b is the fastest speed over the seen span. At one s every point moves
            // with the origin's lab velocity (Born-rigid: the momentary rest frame's; Galilean: the
            // carry's), and its gamma is gamma_V before t0, then gamma_V sqrt(1 - B^2) cosh(|a| s +
            // atanh B) (B = V.k): it falls, if at all, only back to gamma_V before it rises, so the
            // fastest is at an end of the span. That pad is capped at kPadReach / |a| of the
            // object's time (worldline events stay below e^kPadReach / |a|, their squares finite);
            // the span proven sound (pathSpanSeen, latest_crossing.h for Born-rigid bodies) is held
            // whatever the pad.
            const double a = norm(motion.acceleration);
            if (a > 0 && std::isfinite(seen.lo) && std::isfinite(seen.hi)) {
                for (double at : {seen.lo, seen.hi}) b = std::max(b, norm(worldlineVelocity(motion, at, Vec3{0, 0, 0})));
                b = std::min(b, 1 - 1e-9);
                one_minus_b2 = (1 - b) * (1 + b);
                speed_cap = kPadReach / a;
                // (An offset of 1e-3 diag, as the raytracer's slabs: it widens the span by a few of
                // it and ends the refinement within 4e-3 diag of the latest crossing, not at its
                // split budget.)
                const SeenSpan proven = pathSpanSeen(rest, motion, first, last, 1e-3 * diag);
                if (proven.ok) sound = proven.span;
            }
            break;
        }
        default: {
            // A kind answered in its own file (kinds.h): b is its fastest vertex's speed in its own
            // frame, as for a keyframed path.
            const KindAnswers* k = answersOf(motion);
            for (const Vec3& p : rest.positions) b = std::max(b, k->fastest(motion, p));
            b = std::min(b, 1 - 1e-9);
            one_minus_b2 = (1 - b) * (1 + b);
            break;
        }
    }
    const double rounding = 1e-9 * std::max(std::fabs(seen.lo), std::fabs(seen.hi));
    const double pad = std::min(diag * (1 + b) / one_minus_b2, speed_cap) + rounding;
    return {std::min(seen.lo - pad, sound.lo - rounding), std::max(seen.hi + pad, sound.hi + rounding)};
}

SeenSpan slabSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first, const ViewSurface& last,
                      double offset) {
    switch (kindOf(motion)) {
        case MotionKind::Spin:
            return {spinSpanSeen(rest, motion, first, last, offset), true};
        case MotionKind::Uniform:
        case MotionKind::Hyperbolic:
        case MotionKind::Keyed:
        default:  // a kind answered in its own file (kinds.h): its vertices' crossings
            break;
    }
    return pathSpanSeen(rest, motion, first, last, offset);
}

ProperTimeSpan spinSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first,
                            const ViewSurface& last, double offset) {
    const bool lorentz = motion.kinematics == Kinematics::Lorentz;
    const bool cone = first.kind == ViewKind::PastCone;
    double r = 0, u = 0;
    for (const Vec3& q : rest.positions) {
        r = std::max(r, norm(q));
        u = std::max(u, spinVertexSpeed(motion, q));
    }
    const Vec3 origin{0, 0, 0};
    auto originCrossing = [&](ViewSurface view, double apex_shift) {
        view.t_c += apex_shift;
        return crossWorldline(view, motion, origin).s;
    };
    ProperTimeSpan span;
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

SeenSpan pathSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first, const ViewSurface& last,
                      double offset) {
    const bool lorentz = motion.kinematics == Kinematics::Lorentz;
    const bool cone = first.kind == ViewKind::PastCone;
    const bool accelerated = kindOf(motion) == MotionKind::Hyperbolic;
    // Step: the slabs' distance from the history in the lab, and the longest rest edge.
    const double d = offset / std::sqrt(motion.one_minus_beta2) * (1 + motion.beta);
    const double slab_shift = cone ? std::sqrt(2.0) * d : d;
    double e = 0;
    for (const auto& t : rest.triangles)
        for (int c = 0; c < 3; ++c) e = std::max(e, norm(rest.positions[t[c]] - rest.positions[t[(c + 1) % 3]]));
    // The largest vertex crossing of `view` with its apex time moved by `shift`, or the least.
    auto crossings = [&](ViewSurface view, double shift, bool least) {
        view.t_c += shift;
        double s = least ? INFINITY : -INFINITY;
        for (const Vec3& q : rest.positions) {
            const double c = crossWorldline(view, motion, q).s;
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
        // (latest_crossing.h).
        ViewSurface moved = last;
        moved.t_c += slab_shift;
        const LatestCrossing latest = latestCrossing(rest, motion, moved, kLatestTolerance * offset, kLatestMaxSplits);
        out.ok = latest.ok;
        hi = std::max(hi, latest.bound);
    } else if (cone && e > 0) {
        // Step: a keyframed path (F_V) or a Galilean carry (the lab): F(s) is one frame for every
        // s, so the vertex within e of a point crosses the view whose apex is moved by e U, U that
        // frame's 4-velocity (boosted with `velocity` for Lorentz), at or after the point.
        Event w{1, {0, 0, 0}};
        if (lorentz && motion.beta > 0) w = {motion.gamma, motion.gamma * motion.velocity};
        ViewSurface moved = last;
        moved.t_c += e * w.t;
        moved.apex = moved.apex + e * w.x;
        hi = crossings(moved, slab_shift, false);
    }
    if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi)) out.ok = false;
    const double widen = 1e-9 * std::max(std::fabs(lo), std::fabs(hi));
    out.span = {lo - widen, hi + widen};
    return out;
}

}  // namespace mesh4d
