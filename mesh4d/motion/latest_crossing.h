// The latest time at which any point of a body's triangles, not only a vertex, crosses a view
// surface (a past cone or a hyperplane t = t_c, lightcone.h), bounded from above, for a body that
// is Born-rigidly accelerated or uniform in the relativistic kinematics (worldline.h; Lorentz, no
// spin, no keyframed path). s*(q) is rest point q's crossing in the object's time s (crossWorldline).
//
// The bound (Rindler optics). Mark the events of the history by (s, q). Before t0 (s < 0) the body
// is at rest in the start frame and s is that frame's time: the metric is ds^2 - |dq|^2. From t0
// on, with xi = 1/a + q.k (a = |acceleration|, k its direction), T = xi sinh(a s) and
// X.k = xi cosh(a s) - 1/a give dT^2 - dX^2 = (a xi)^2 ds^2 - dxi^2: the metric is
// (a xi)^2 ds^2 - |dq|^2 (Rindler); a = 0 is the uniform body. So a path q(s) in rest space with
// |dq/ds| <= c(q) = min(1, a xi(q)) is causal (piecewise smooth and continuous across s = 0, where
// both forms give the start-frame event (0, q)). A straight segment from p to q run at
// c_min = min(c(p), c(q)) (xi is affine along it) takes D = |p - q| / c_min of s. The points that
// have not crossed the view yet (h >= 0, worldline.h) are the causal past of the apex (of the
// hyperplane): a set that holds every event in the causal past of one of its events. (s*(q), q)
// is in it, so (s*(q) - D, p), which reaches it along that segment, is too: s*(p) >= s*(q) - D
// (h decreases in s). Swapping p and q:
//     |s*(p) - s*(q)| <= |p - q| / min(1, a xi_min)
// (the body's own time s is a static time: light between two of its points takes the same s
// whenever it is sent). For a = 0 this is spinSpanSeen's s in s_o -+ r (seen.h).
// A triangle: each of its points is within r of a vertex, r the circumradius when the triangle is
// not obtuse, else half its longest edge (min_i |p - q_i| is largest at the circumcentre, when it
// lies in the triangle, or on the boundary, where a point of an edge is within half of it of an
// end). So no point of it crosses after max_i s*(q_i) + r / c_min.
//
// Tightness: that bound exceeds the true latest crossing by up to r / c_min (the rocket of
// data/scenes: r = 1.03 ls, c_min = 0.5 at its tail, 2.06 s). Branch and bound closes it: the
// piece (a sub-triangle) with the largest bound is split into four at its edge midpoints (r
// halves; the midpoints' crossings computed), until the largest bound is within `tolerance` of the
// latest crossing computed, or `max_splits` splits are spent. Whenever it stops, the largest bound
// of the pieces holds for every point (the pieces cover the triangles). Cost: the vertices'
// crossings, then 3 crossings a split.
// Rounding: the crossings within about 1e-14 |s| (worldline.h), r within a few ulps (it is
// enlarged by 1e-12 relative); callers widen the result by their own rounding margin.
#pragma once

#include <cstddef>

#include "mesh4d/extrude.h"
#include "mesh4d/lightcone.h"
#include "mesh4d/motion/worldline.h"

namespace mesh4d {

struct LatestCrossing {
    double bound = -INFINITY;  // no point of the triangles crosses the view later (sound; above)
    double found = -INFINITY;  // the latest crossing of a point computed (a vertex or a split's corner)
    size_t splits = 0;         // pieces split
    bool ok = true;            // false when a crossing search failed (NaN or infinite input)
};

// The bound above for the triangles of `mesh` moving with `motion` and the view `view`; -infinity
// for a mesh without triangles. Preconditions: motion Lorentz, without spin or keyframed path, every
// vertex in front of the horizon (horizonDistance > 0, as the stage checks); tolerance >= 0 (in s).
LatestCrossing latestCrossing(const RestMesh& mesh, const Motion& motion, const ViewSurface& view, double tolerance,
                              size_t max_splits);

// The largest distance of a point of triangle (a, b, c) to its nearest vertex (above).
double nearestVertexReach(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace mesh4d
