// The span of its own time over which a range of views sees a moving body (motion.h, the
// questions asked of a motion): the padded span its history is extruded over, and the span its
// time slabs must cover, answered per kind of motion.
#pragma once

#include "mesh4d/extrude.h"
#include "mesh4d/lightcone.h"
#include "mesh4d/motion/motion.h"

namespace mesh4d {

// A span of the object's time s, and whether it was proven (false only for NaN or infinite
// crossings: the caller then keeps the padded span of paddedSpanSeen).
struct SeenSpan {
    ProperTimeSpan span;
    bool ok = true;
};

// The proper-time span that views `first` .. `last` (a frame range's first and last) can see
// (extrude.h spanSeen), padded by the object's light-crossing time over 1 - b (b its speed; for a
// keyframed path its fastest vertex's in its own frame; for an acceleration the fastest over the
// span, the pad at most 64 / |a|, and the span never short of the one pathSpanSeen proves), so
// that rounding in the vertex crossings never reaches an artificial cap.
ProperTimeSpan paddedSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first,
                              const ViewSurface& last);

// The span of the object's time that views `first` .. `last` can meet on its time slabs, which lie
// within `offset` of the true history: spinSpanSeen for a spin (always ok), pathSpanSeen otherwise.
SeenSpan slabSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first, const ViewSurface& last,
                      double offset);

// The object's times s at which views `first` .. `last` (a frame range's first and last: the
// lab's past cones or instants, the camera at rest) can meet any point of a spinning body
// (Motion::angular_velocity, no acceleration or keys), tight and sound without a search over the
// surface: every point of the body stays within r = max |q| of its origin, in the centre frame
// (Lorentz) and in the lab at each lab instant (Galilean carry). s_o(view) is the origin's
// crossing (worldline.h), increasing with the camera time.
//   Lorentz, past cone: the cone is a cone in the centre frame too, apex (T_c, Y_c); a point at
//     |Y| <= r emits at T_c - s = |Y - Y_c| within |Y_c| -+ r, so s in s_o -+ r (s_o = T_c - |Y_c|).
//   Lorentz, instant t = t_c (contracted): s = (t_c - t0)/g - v.Y, so s in s_o -+ b r.
//   Galilean, past cone (finite): t_c - t = |x(t) - C| is within |origin(t) - C| -+ r, so t lies
//     between the origin's crossings of the cones with apex times t_c - r and t_c + r.
//   Galilean, instant: s = t_c - t0 for every point.
// Widened on both sides by 2 `offset` / (1 - u), u the fastest vertex's speed in the frame of s:
// a traced surface within `offset` of the true history (extrude.h slabSpacing's chord) crosses a
// view at most offset / (1 - u) earlier or later; and by 1e-9 |s| for rounding.
ProperTimeSpan spinSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first,
                            const ViewSurface& last, double offset);

// The object's times s at which views `first` .. `last` (as spinSpanSeen's, the camera at rest) can
// meet any point of an accelerated or keyframed body (Motion::acceleration or Motion::keyed), or
// the traced surface of its time slabs, which lies within `offset` (extrude.h slabSpacing's chord,
// in the object's own frame; at most offset g (1 + b) = d in the lab, b the speed of `velocity`) of
// the true history. Bounded by the vertices' own worldlines, not the centre's: each rest vertex's
// crossing (worldline.h crossWorldline) with the first view, moved earlier, and with the last,
// moved later, as follows. h(s, q) = t_c - t - |x - C| (cone) or t_c - t (hyperplane) is concave in
// q at a fixed s (t and x are affine in q for these motions) and decreases in s.
//   lo: a point p = sum l_i q_i of a triangle has h(s, p) >= sum l_i h(s, q_i), so at the least
//     vertex crossing s_lo every point is still behind the view: no point crosses before any vertex.
//     A slab point Z within d of a true event E: on the cone, t_E >= t_c - sqrt(2) d - |x_E - C|,
//     so E is behind the view whose apex time is t_c - sqrt(2) d (t_c - d on a hyperplane): lo is
//     the least vertex crossing of that view.
//   hi: on a hyperplane h is affine in q, so no point crosses after every vertex. On a cone, with
//     the slabs' d as for lo (the last view's apex time moved by sqrt(2) d):
//     - Born-rigid acceleration (relativistic): latest_crossing.h. The body's own time s is
//       a static (Rindler) time, in which light crosses rest distance at coordinate speed
//       min(1, |a| xi) (xi = 1/|a| + q.k), so two points' crossings differ by at most their
//       distance over that speed: a triangle's points cross at most r / min(1, |a| xi_min) after
//       its latest vertex (r: every point within r of a vertex), a bound refined by branch and
//       bound on sub-triangles to within kLatestTolerance (4) offsets of a crossing computed
//       (seen.cpp; at most 4096 splits). The rocket of data/scenes (2 ls long at 0.5 ls/s^2,
//       tests/raytrace_span_test.cpp): hi at most 0.012 s of its time past the latest emission of
//       its sampled points over frames 0-159, where interior points emit up to 0.009 s after
//       every vertex (frame 80).
//     - Keyframed path or Galilean carry (finite): at a fixed s the body is its rest mesh moved
//       rigidly in one inertial frame F (F_V; the lab) whose simultaneity holds all events at that
//       s. A point p crossing at sigma has a vertex q_i of its triangle within e (the longest rest
//       edge), simultaneous with it in F, so t'_i = t'_p = t'_c - |x'_p - C'| <= t'_c + e -
//       |x'_i - C'|: q_i's event at sigma is behind the cone whose apex is moved by e U (U F's
//       4-velocity, boosted with `velocity` for Lorentz), and q_i crosses that cone at or after
//       sigma: hi is the largest vertex crossing of the moved cone.
// Widened by 1e-9 |s| for the crossings' rounding (worldline.h: 1e-14 relative). ok = false only for
// NaN or infinite crossings: the caller then keeps paddedSpanSeen's span.
SeenSpan pathSpanSeen(const RestMesh& rest, const Motion& motion, const ViewSurface& first, const ViewSurface& last,
                      double offset);

}  // namespace mesh4d
