// Exact sign of the view side function h(E) (lightcone.h) on the stored doubles.
//
// Which side of a real cap a vertex falls on, and whether a cap edge crosses the view surface,
// are topology decisions: a wrong sign near the cone would clip a triangle that its neighbour
// keeps. Each decision is made once per vertex (or per edge) and shared, so neighbours agree by
// construction; this makes the decision itself correct as well. A floating-point evaluation of
// h with a forward error bound settles all but events within a few ulps of the cone; those are
// decided by exact arithmetic (CGAL's MP_Float, a multiprecision float exact for +, -, x) on
//     sign(h) = sign(dt)                       if dt <= 0 (and 0 only if also dx = 0),
//             = sign(dt^2 - |dx|^2)            otherwise,     dt = t_c - t, dx = x - C.
#pragma once

#include "lightcone.h"

namespace mesh4d {

// -1, 0 or +1: the exact sign of viewSide(view, e) for the double values given.
int viewSideSign(const ViewSurface& view, const Event& e);

// How many calls of viewSideSign in this thread fell through the filter to exact arithmetic
// (for tests and benchmarks).
long long exactSideFallbacks();

}  // namespace mesh4d
