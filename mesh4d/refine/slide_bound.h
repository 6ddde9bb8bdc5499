// Faces that contain the velocity: the geometric distance is on their rim alone. The refinement's
// rule for them (first_pass.cpp, bisect.cpp), uniform motion through the past cone, no real cap,
// outputs not displaced (mesh4d/refine/refine.h).
//
// The face. Let R be a planar region of the rest mesh whose plane contains the velocity v (every
// triangle of R has its rest normal across v) and whose triangles are coplanar across their
// shared edges. The shape offsets s (chord_error.h) are affine in the rest point and contract
// along v only, so the shape of R is planar and contains v too; the exact image
//     F(s) = s - v delta(s)
// stays in that plane (v lies in it), and so does every straight output triangle, whose corners
// are exact images. F is one to one on the plane (geometric_bound.h Term 1: J is regular), so the
// exact face is the planar region F(R), bounded by the images of R's rim (its edges that are not
// shared with a coplanar triangle of R: boundary edges, edges onto another plane). The output over
// R is a polygon bounded by the chords of those images between output vertices, which lie on them.
// The two-sided distance between a polygon and a planar region in one plane is no more than the
// largest distance between a chord and its arc: a point of one and not of the other lies in a lune
// between a chord and its arc (each arc is a graph over its chord: the slope of eps along a short
// edge is far below 1), and the segment across the lune through the point, from chord to arc, is
// no longer than the lune's widest. Whatever the interior triangles' parametric error, it is a
// slide within the plane: the faces of the exact surface that are not R are only nearer.
//
// The rim, an edge from a to b. Along it, F(a + t (b - a)) = L(t) + b eps(t) u (u = v / b, eps =
// L delta - delta >= 0, convex delta), and the arc's distance from the chord's line is the part of
// b eps u across the chord's direction c^:
//     dist = b eps(t) |u x c^|,     |u x c^| = |u x ds| / |dy|,
// with ds = s_b - s_a and dy = ds - v (delta_b - delta_a) the chord (u x v = 0), and
// delta_b - delta_a = (|x_b|_M - |x_a|_M - ds.v) / (1 - b^2) (chord_error.h: |x|_M = S + s.v +
// (1 - b^2) delta). An edge along v has |u x ds| = 0: its image is straight.
// eps along the edge, term by term, as chord_error.h bounds it on a triangle, in one dimension:
// with g(t) = delta(a + t (b - a)), I2 its quadratic interpolant at t = 0, 1/2, 1, and beta the
// midpoint bubble,
//     eps = (L I2 g - I2 g) + (I2 g - g),   max |L I2 g - I2 g| = |beta| <= c / 4 (c = EdgeBubble::c),
//     |g - I2 g| <= (1 + 5/4) sup |g - T| <= (9/4) sup |g'''| / 48,
// 5/4 the Lebesgue constant of the three equispaced nodes, T the Taylor quadratic at t = 1/2 and
// |t - 1/2| <= 1/2; g''' = D^3 delta [ds]^3 <= (2 / sqrt 3) l^3 / ((1 - b^2) m_e^2) (chord_error.h),
// l = |ds|_M, m_e = |x_mid|_M - l / 2 <= |x|_M on the edge. So
//     rim distance <= speed (c / 4 + 3 l^3 / (32 sqrt 3 (1 - b^2) m_e^2)) |u x c^|,
// speed the bound's factor b. Tight: c / 4 is the bubble up to a fourth-order term, the remainder
// third order; |u x c^| exact.
#pragma once

#include <cmath>

#include "chord_error.h"

namespace mesh4d {

// The rest triangle (p0, p1, p2)'s plane contains the direction `velocity` (to rounding: the
// normal's cosine with it at most 1e-12).
inline bool planeContains(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& velocity) {
    const Vec3 n = cross(p1 - p0, p2 - p0);
    const double nn = norm(n), vv = norm(velocity);
    return nn > 0 && std::fabs(dot(n, velocity)) <= 1e-12 * nn * vv;
}

// The distance bound above for the rim edge between the points with terms `a` and `b` whose edge
// bound is `eb` (edgeBubble of the same ends), `speed` the bound's factor (b): infinite when the
// edge reaches the camera (m_e <= 0) or its bubble is unbounded.
inline double rimChordError(const Motion& m, double speed, const PointTerms& a, const PointTerms& b, double c,
                            double length, double xm_mid) {
    const Vec3 ds = b.s - a.s;
    const double across = norm(cross(m.velocity, ds));  // b |u x ds|
    if (across == 0) return 0;
    const double k = m.one_minus_beta2;
    const Vec3 dy = ds - m.velocity * ((b.xm - a.xm - dot(ds, m.velocity)) / k);
    const double chord = norm(dy);
    const double me = xm_mid - 0.5 * length;
    if (!(me > 0) || !(chord > 0) || !(c < INFINITY)) return INFINITY;
    constexpr double kRemainder = 3 / (32 * 1.7320508075688772);  // (9/4) (1/48) (2 / sqrt 3)
    const double eps = 0.25 * c + kRemainder * length * length * length / (k * me * me);
    const double sine = std::min(1.0, across / (m.beta * chord));  // |u x c^|
    return speed * eps * sine;
}

}  // namespace mesh4d
