// How far a straight output triangle lies from the exact apparent surface: the bound the adaptive
// refinement (slice.h) accepts a triangle by.
//
// The map. For uniform motion the apparent point of rest point q is, in the frame's local
// coordinates (lightcone.h, ViewAnchor),
//     F(q) = s(q) - v delta(q),
// where s(q) = shapeOffset(q) is affine in q and delta(q) = d(E + s(q)) - D is the light delay
// relative to the object's origin, with d(x) = (x.v + |x|_M) / (1 - b^2) the delay of a point now
// at x (relative to the camera) and |x|_M = sqrt((x.v)^2 + (1 - b^2)|x|^2), a norm. So d, and
// delta along any line of rest points, are convex, and the whole non-linearity of F is one scalar
// function times the fixed vector v. On a triangle with exact corners the linear interpolant L of
// F therefore differs from it by
//     F(p) - L(p) = -v (delta(p) - L delta(p)),     |F - L| = b |delta - L delta|,
// and |F - L| bounds both one-sided distances between the output triangle and the exact surface
// patch (each output point L(p) has the exact point F(p), and back).
//
// The bound, term by term. Let I2 be the quadratic interpolant of delta through the corners and
// the three edge midpoints, and beta_ij = delta(m_ij) - (delta_i + delta_j) / 2 <= 0 the midpoint
// bubbles (measured by cuts in chordError; bounded from above without a cut by edgeBubble below,
// which is what the refinement uses). Then
//     delta - L delta = (I2 delta - L I2 delta) + (delta - I2 delta),
//     I2 delta - L I2 delta = sum_{i<j} 4 beta_ij l_i l_j      (l the barycentrics),
// whose largest magnitude over the triangle, Q, has a closed form (bubbleMax). The remainder is
// bounded with the Taylor quadratic T of delta at the centroid c: I2 reproduces quadratics and
// its Lebesgue constant on a triangle is 5/3, so |delta - I2 delta| <= (1 + 5/3) sup |delta - T|,
// and sup |delta - T| <= sup |D^3 delta| r_M^3 / 6 along the segments from c. For the norm,
// |D^3 |x|_M [u]^3| <= (2 / sqrt 3) |u|_M^3 / |x|_M^2 (the Euclidean case in the coordinates
// where |.|_M is Euclidean: max over the angle of 3 sin^2 cos / r^2), so with r_M the largest
// M-distance from c to a corner and m a lower bound of |x|_M on the triangle,
//     R = (8/3) (1/6) (2/sqrt 3) r_M^3 / ((1 - b^2) m^2) = 8 r_M^3 / (9 sqrt 3 (1 - b^2) m^2),
//     |F - L| <= b (Q + R)  everywhere on the triangle.
// m: |x|_M >= |x_i|_M - |x - x_i|_M and |x - x_i|_M <= 2 r_M inside the triangle, so
// m = min_i |x_i|_M - 2 r_M (a triangle reaching the camera, m <= 0, gets an infinite bound).
// |x_i|_M needs no extra work: it is B + (1 - b^2) delta = S + s.v + (1 - b^2) delta, and with
// the local position y = s - v delta that is S + y.v + delta.
// R falls as the cube of the triangle's size and Q as the square: R / Q is about h / |x|, small
// once a triangle is small against its distance from the camera, so the bound is tight (the
// refinement's measured error is 0.5 to 1 times the tolerance; docs/ACCURACY.md).
// Rounding: the inputs carry relative errors of a few ulps of the local coordinates; the bubbles
// are differences of local delays (no term of the size of the distance), so their rounding is a
// few ulps of the object's size, far below any tolerance the program accepts.
//
// Hyperplane views (the instant and contracted models) and objects at rest map affinely: there
// is nothing to bound and the refinement does not call this.
#pragma once

#include <algorithm>
#include <cmath>

#include "mesh4d/event.h"
#include "mesh4d/lightcone.h"
#include "mesh4d/motion/motion.h"

namespace mesh4d {

// Per point, from its exact local event e (t = -delta, x = y): the shape offset s = y + v delta,
// and |x|_M = S + y.v + delta (see above).
inline Vec3 shapeOfEvent(const Motion& m, const Event& e) { return e.x - m.velocity * e.t; }
inline double normMOfEvent(const ViewAnchor& anchor, const Motion& m, const Event& e) {
    return anchor.S + dot(e.x, m.velocity) - e.t;
}

// The largest value over the triangle (l0, l1, l2 >= 0, sum 1) of
//     c01 l0 l1 + c12 l1 l2 + c20 l2 l0,   every c >= 0:
// on an edge c/4 at its middle; inside, where the gradient is parallel to (1, 1, 1), at
// l_k proportional to a_k (a_i + a_j - a_k) ... (a_k the coefficient of the edge opposite corner
// k), with value a0 a1 a2 / (2 (a0 a1 + a1 a2 + a2 a0) - a0^2 - a1^2 - a2^2) when the three a
// satisfy the triangle inequality (the point is inside then).

// bubbleFirst is bubbleMax's first term, its value at the edge middles (c/4 of the largest c, NaNs
// alike): bubbleMax returns it or more, and is NaN when it is (when c12 is). The whole-piece forms
// (chord_error.cpp) pass a candidate whose bubbleFirst already loses without its bubbleMax, which
// is sound only while both are this one expression.
inline double bubbleFirst(double c01, double c12, double c20) { return 0.25 * std::max(std::max(c12, c20), c01); }
inline double bubbleMax(double c01, double c12, double c20) {
    // a_k: coefficient of the edge opposite corner k.
    const double a0 = c12, a1 = c20, a2 = c01;
    double best = bubbleFirst(c01, c12, c20);  // edge middles (std::max({a0, a1, a2}), NaNs alike)
    const double w0 = a0 * (a1 + a2 - a0), w1 = a1 * (a0 + a2 - a1), w2 = a2 * (a0 + a1 - a2);
    const double den = w0 + w1 + w2;  // = 2 (a0 a1 + a1 a2 + a2 a0) - a0^2 - a1^2 - a2^2
    if (w0 >= 0 && w1 >= 0 && w2 >= 0 && den > 0) best = std::max(best, a0 * a1 * a2 / den);
    return best;
}

struct ChordError {
    double bound = 0;      // b (Q + R): bound of |F - L| on the triangle, light-seconds (INFINITY if unbounded)
    double quadratic = 0;  // b Q, the part of the bubbles alone
};

// The bound above for the triangle with exact corner events `corner` (local coordinates: t = -delta,
// x = y) and exact edge-midpoint events `mid` (mid[c] on corners c, c + 1), for an object moving
// with `m` seen through the past cone anchored at `anchor` (anchor.cone must be true). When the
// bubbles alone exceed `tolerance`, the bound returned is b Q (already over it; R is not computed).
ChordError chordError(const ViewAnchor& anchor, const Motion& m, const Event corner[3], const Event mid[3],
                      double tolerance = INFINITY);

// The same bound from per-point terms, as the refinement keeps them once per point: the local
// event times t (= -delta) of the corners and of the edge midpoints (t_mid[c] on corners c, c + 1),
// and the corners' shape offsets s = shapeOfEvent and |x|_M = normMOfEvent. Bit-identical to
// chordError (which computes these terms and calls it).
ChordError chordErrorOfTerms(const Motion& m, const double t_corner[3], const double t_mid[3], const Vec3 s[3],
                             const double xm[3], double tolerance = INFINITY);

// A moving camera in the finite model (lightcone.h ViewSurface::shear = v): the cut is made in the
// lab with the object's lab velocity u, and each output event (t, x) becomes (t, x - v t). A local
// event (t = -delta, y = s - u delta) thus becomes y' = y + v delta = s - w delta, w = u - v:
//     F'(q) = s(q) - w delta(q),     |F' - L F'| = |w| |delta - L delta| <= |w| (Q + R),
// with delta, Q and R exactly as above (the same light delay, the quadratic with u: only the
// displacement is along w). So the bound is chordErrorOfTerms' with the factor b = |u| replaced by
// `speed` = |w|. An object at rest in the lab (u = 0: delta is the Euclidean distance, convex too,
// |.|_M Euclidean and 1 - b^2 = 1) is not affine in the camera's frame then (w = -v), and this
// bound applies to it as well. chordErrorOfTerms is this with speed = b (0 when b = 0).
ChordError displacedChordError(const Motion& m, double speed, const double t_corner[3], const double t_mid[3],
                               const Vec3 s[3], const double xm[3], double tolerance = INFINITY);

// A bound from the corners alone, for triangles that need no refinement: no midpoint is cut.
// The Hessian of delta satisfies u^T H u <= |u|_M^2 / ((1 - b^2) |x|_M) (that of a norm is at
// most M / |x|_M), and the linear interpolant of a function with such a Hessian errs by at most
// half its bound times sum_i l_i |p - x_i|_M^2 <= d_M^2 / 3 (the spread of three weighted points
// no farther apart than the longest side d_M). With m = min_i |x_i|_M - d_M <= |x|_M on the
// triangle:
//     |F - L| <= b d_M^2 / (6 (1 - b^2) m).
// Looser than chordError (it ignores the direction of the motion), so it only ever saves work:
// a triangle passing it passes chordError's bound too, up to the slack between the two.
double chordErrorFromCorners(const ViewAnchor& anchor, const Motion& m, const Event corner[3]);

// The same test without a square root or a division, for the per-frame pass over every triangle:
// true only when chordErrorFromCorners <= tolerance holds with m >= |x|_M,min / 2 in place of
// m (sufficient: d_M^2 <= xm^2 / 4 gives d_M <= xm / 2). s: shape offsets y + v delta of the
// corners; xm: their |x|_M = S + y.v + delta (chordErrorFromCorners shows both).
// d_M^2, the square of the longest side in the metric M, of the corners with shape offsets s.
inline double cornerSpread(const Vec3 s[3], const Motion& m) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3 u = s[(i + 1) % 3] - s[i];
        const double uv = dot(u, m.velocity);
        d2 = std::max(d2, uv * uv + m.one_minus_beta2 * norm2(u));
    }
    return d2;
}
// passesFromCorners with the corners' spread d2 = cornerSpread(s, m) given. Monotone as rounded:
// true at (d2, xm) stays true at any smaller d2 and larger xm (fl(4 d2), fl(xmin xmin) and
// fl(beta d2) grow with their operand; fl(3 (1 - beta^2) T) >= 0 multiplies xmin), so true at the
// largest spread of a mesh with the least xm of all its corners is true for each of its triangles
// (slice.cpp refineFrame skips its pass over the triangles then).
inline bool passesFromSpread(double d2, const double xm[3], const Motion& m, double tolerance) {
    const double xmin = std::min(xm[0], std::min(xm[1], xm[2]));
    return xmin > 0 && 4 * d2 <= xmin * xmin && m.beta * d2 <= 3 * m.one_minus_beta2 * tolerance * xmin;
}
inline bool passesFromCorners(const Vec3 s[3], const double xm[3], const Motion& m, double tolerance) {
    return passesFromSpread(cornerSpread(s, m), xm, m, tolerance);
}
// chordErrorFromCorners from the corners' terms, for a caller that keeps them per point (the
// refinement's first pass): d2 = cornerSpread(s, m), xm the corners' |x|_M = normMOfEvent.
// Bit for bit chordErrorFromCorners of the events the terms were made from (it makes the same
// terms, the same spread, and calls this).
inline double chordErrorFromSpread(double d2, const double xm[3], const Motion& m) {
    if (m.beta == 0) return 0;
    double xm_min = INFINITY;
    for (int i = 0; i < 3; ++i) xm_min = std::min(xm_min, xm[i]);
    const double mlow = xm_min - std::sqrt(d2);
    if (!(mlow > 0)) return INFINITY;
    const double bound = m.beta * d2 / (6 * m.one_minus_beta2 * mlow);
    return bound == bound ? bound : INFINITY;
}

// ---- The a-priori bound: the bubbles from the Hessian, no midpoint cut ----
// The refinement decides its splits with this bound (slice.cpp): it needs only per-point terms
// that are affine in the rest point or one square root away from it, so no exact cut is made for
// a decision; only the output vertices are cut, in one batch after the last split.
// Along an edge x(t) = x_a + t u (x: the point now relative to the camera, x = E + s, affine in
// the rest point; u = s_b - s_a), let g(t) = delta(x(t)) and h(t) = g''(t) = u^T H u >= 0, H the
// Hessian of delta (that of d):
//     H = (M - (M x)(M x)^T / |x|_M^2) / ((1 - b^2) |x|_M),   M = v v^T + (1 - b^2) I,
//     h = (|u|_M^2 - (u.w)^2) / ((1 - b^2) |x|_M),   w = M x / |x|_M.
// The midpoint bubble is |beta| = integral over [0, 1] of G h, G the hat of height 1/4 at t = 1/2
// (integral 1/8), symmetric about 1/2. Expanding h about t = 1/2, the first-order term integrates
// to zero, and the rest is at most K4 (t - 1/2)^2 / 2 with K4 the bound of the fourth derivative:
// for a norm |D^4 |x|_M [u]^4| <= 3 |u|_M^4 / |x|_M^3 (the Euclidean case in the coordinates where
// |.|_M is Euclidean: max over the angle of 3 sin^2 |4 cos^2 - sin^2| / r^3), and the integral of
// G (t - 1/2)^2 is 1/192, so
//     c = 4 |beta| <= h(1/2) / 2 + l^4 / (32 (1 - b^2) m_e^3),
// l = |u|_M, m_e = |x_mid|_M - l / 2 <= |x(t)|_M on the edge. Exact (h / 2) for a quadratic delta;
// the correction is fourth order, smaller than h / 2 by about (l / |x|)^2 / 32. bubbleMax is
// non-decreasing in every coefficient, so chordErrorOfBubbles with these c bounds |F - L| as
// chordErrorOfTerms does with the measured bubbles, and is as tight.
// Rounding: h is a difference of two terms of size |u|_M^2 / |x|_M; its rounding is a few ulps of
// that, far below any tolerance the program accepts (as the bubbles' rounding above).

// The terms of one point for the a-priori bound: its shape offset s and |x|_M, x = E + s (E =
// nowBase, the object's origin now, relative to the camera).
struct PointTerms {
    Vec3 s;
    double xm = 0;
};
inline double normMOfShape(const Motion& m, const Vec3& E, const Vec3& s) {
    const Vec3 x = E + s;
    const double xv = dot(x, m.velocity);
    return std::sqrt(xv * xv + m.one_minus_beta2 * norm2(x));
}
// |u|_M^2 = (u.v)^2 + (1 - b^2) |u|^2 (the same bits for u and -u).
inline double normM2(const Motion& m, const Vec3& u) {
    const double uv = dot(u, m.velocity);
    return uv * uv + m.one_minus_beta2 * norm2(u);
}

// The third-order term R of the bound (top of this file) from the squared M-lengths side2[e] of
// the triangle's three sides and the least |x_i|_M of its corners, without the centroid: by the
// median formula (an identity of any inner product, so of M's) the M-distance from the centroid
// to corner i, opposite side j k, is
//     |s_i - centre|_M^2 = (2 l_ij^2 + 2 l_ik^2 - l_jk^2) / 9 = (2 S - 3 l_jk^2) / 9,   S = sum l^2,
// so 9 r_M^2 = 2 S - 3 min_e l_e^2 exactly, and with r3 = 3 r_M,
//     m = min_i |x_i|_M - (2/3) r3,     R = 8 r_M^3 / (9 sqrt 3 (1 - b^2) m^2) = 8 r3 (r3^2) / (243 sqrt 3 (1 - b^2) m^2).
// Rounding: 2 S - 3 min lies in [S, 2 S] (min <= S / 3), no cancellation: a few ulps relative, as
// the products after it; the sides' own rounding is that of the shape offsets' differences, as
// before (a few ulps of the object's size).
inline double thirdOrderTerm(const Motion& m, const double side2[3], double xm_min) {
    constexpr double kR = 8 / (243 * 1.7320508075688772);  // 8 / (243 sqrt 3)
    const double S = side2[0] + side2[1] + side2[2];
    const double q9 = 2 * S - 3 * std::min(std::min(side2[0], side2[1]), side2[2]);  // 9 r_M^2
    const double r3 = std::sqrt(q9);                                                 // 3 r_M
    const double mlow = xm_min - (2.0 / 3.0) * r3;
    return mlow > 0 ? kR * r3 * q9 / (m.one_minus_beta2 * mlow * mlow) : INFINITY;
}

// The edge a -> b's coefficient bound c (above; INFINITY when the edge may reach the camera,
// m_e <= 0) and its length in the map's metric for longest-edge bisection: h(1/2) / 2 plus the
// edge's share of the third-order term, 8 l^3 / (9 sqrt 3 (1 - b^2) m^2) with m = m_e floored at
// l (finite near the camera, and shrinking as the edge is halved). Callers pass the ends in a
// fixed order (lower vertex id first) so both triangles of an edge get the same bits.
struct EdgeBubble {
    double c = 0;
    double length = 0;
    double xm_mid = 0;  // |x|_M of the edge's middle (normMOfShape of the mean of the ends' s)
};
// Valid at b = 0 too (M = I: the delay is the Euclidean distance), which a displaced bound needs
// (displacedChordError: an object at rest under a shear).
inline EdgeBubble edgeBubble(const Motion& m, const Vec3& E, const PointTerms& a, const PointTerms& b) {
    EdgeBubble r;
    const double k = m.one_minus_beta2;
    const Vec3 x = E + (a.s + b.s) * 0.5;  // the midpoint now, relative to the camera
    const double xv = dot(x, m.velocity);
    const double xm2 = xv * xv + k * norm2(x);
    const double xm = std::sqrt(xm2);
    r.xm_mid = xm;
    const Vec3 u = b.s - a.s;
    const double uv = dot(u, m.velocity);
    const double l2 = uv * uv + k * norm2(u);
    const double uMx = uv * xv + k * dot(u, x);  // u^T M x = |x|_M (u.w)
    // h(1/2) / 2 = (|u|_M^2 |x|_M^2 - (u^T M x)^2) / (2 (1 - b^2) |x|_M^3), >= 0 but for rounding.
    const double half_h = 0.5 * std::max(0.0, l2 * xm2 - uMx * uMx) / (k * xm2 * xm);
    const double l = std::sqrt(l2);
    const double me = xm - 0.5 * l;
    constexpr double kThird = 8 / (9 * 1.7320508075688772);  // 8 / (9 sqrt 3)
    if (me > 0) {
        const double inv = 1 / (k * me * me * me);  // 1 / ((1 - b^2) m_e^3)
        r.c = half_h + l2 * l2 * inv / 32;
        r.length = half_h + kThird * l * l2 * (me >= l ? me * inv : 1 / (k * l2));
    } else {
        r.c = INFINITY;
        r.length = half_h + kThird * l / k;  // m floored at l
    }
    // A NaN c becomes INFINITY, a NaN length 0 (min and max return their first operand for a NaN;
    // the length is a sum of terms >= 0, so max(0, length) changes nothing else).
    r.c = std::min(double(INFINITY), r.c);
    r.length = std::max(0.0, r.length);
    return r;
}
// edgeBubbleLanes: edgeBubble of two edges at once (a0 -> b0 into out[0], a1 -> b1 into out[1]),
// bit for bit, on the lanes of lanes.h (see "Scalar and lanes" below). For a caller that needs two
// edges' bounds at the same point (the refinement's split: the edge's halves, the new interior edges).
#if !defined(APPARENT_NO_LANES)
void edgeBubbleLanes(const Motion& m, const Vec3& E, const PointTerms& a0, const PointTerms& b0, const PointTerms& a1,
                     const PointTerms& b1, EdgeBubble out[2]);
#endif

// The bound of chordErrorOfTerms from the three edges' coefficients c (c[e] on corners e, e + 1)
// instead of the measured bubbles, and the corners' shape offsets and |x|_M.
// `speed` is the factor on the delay's error: the object's speed b for its own image, |w| for a
// displaced one (displacedChordError).
// chordErrorOfPoints takes the corners' terms in place (the refinement keeps them per point: no
// copy per piece); chordErrorOfBubbles is it, bit for bit, from arrays.
// chordErrorOfSides is the bound itself, from the sides' squared M-lengths and the corners' least
// |x_i|_M, which terms(side2) makes only when the bubbles pass (R is needed); chordErrorOfPoints
// makes them from its corners' terms. A caller that has the lengths already (the refinement's first
// pass keeps |u|_M^2 per mesh edge, slice.cpp refineFrame) passes them: side2[e] of side e
// (corners e, e + 1) is normM2 of either direction, the same bits. (Always inlined: the refinement
// calls it per piece; docs/PERFORMANCE.md, "The refinement's costs".)
template <class Terms>
[[gnu::always_inline]] inline ChordError chordErrorOfSides(const Motion& m, double speed, const double c[3],
                                                           Terms terms, double tolerance = INFINITY) {
    ChordError r;
    if (speed == 0) return r;
    const double Q = bubbleMax(c[0], c[1], c[2]);
    r.quadratic = speed * Q;
    // Over the tolerance on the bubbles alone: R only adds (callers compare the bound only).
    if (!(r.quadratic <= tolerance)) {
        r.bound = r.quadratic == r.quadratic ? r.quadratic : INFINITY;
        return r;
    }
    double side2[3];
    const double xm_min = terms(side2);
    const double R = thirdOrderTerm(m, side2, xm_min);
    r.bound = std::min(double(INFINITY), speed * (Q + R));  // NaN from a degenerate input: INFINITY, never accepted
    return r;
}
// (chordErrorOfPoints always inline too: the refinement's drain and first pass call it per piece,
// and GCC's size budget for the large drain otherwise flips with unrelated edits to it.)
[[gnu::always_inline]] inline ChordError chordErrorOfPoints(const Motion& m, double speed, const double c[3],
                                                            const PointTerms& p0, const PointTerms& p1,
                                                            const PointTerms& p2, double tolerance = INFINITY) {
    // The sides' squared M-lengths (c[e]'s side: corners e, e + 1) give r_M (thirdOrderTerm).
    auto terms = [&](double side2[3]) {
        side2[0] = normM2(m, p1.s - p0.s);
        side2[1] = normM2(m, p2.s - p1.s);
        side2[2] = normM2(m, p0.s - p2.s);
        return std::min(std::min(p0.xm, p1.xm), p2.xm);
    };
    return chordErrorOfSides(m, speed, c, terms, tolerance);
}
inline ChordError chordErrorOfBubbles(const Motion& m, double speed, const double c[3], const Vec3 s[3],
                                      const double xm[3], double tolerance = INFINITY) {
    return chordErrorOfPoints(m, speed, c, PointTerms{s[0], xm[0]}, PointTerms{s[1], xm[1]}, PointTerms{s[2], xm[2]},
                              tolerance);
}
inline ChordError chordErrorOfBubbles(const Motion& m, const double c[3], const Vec3 s[3], const double xm[3],
                                      double tolerance = INFINITY) {
    return chordErrorOfBubbles(m, m.beta, c, s, xm, tolerance);
}


// ---- The whole-piece bound: one quadratic form for every triangle inside a piece ----
// The refinement fills each piece it stops bisecting with a template (tessellate.h) of many
// triangles; this bounds them all at once, from the piece's own terms.
// What a form must do. If A >= H(x) (the delay's Hessian, as quadratic forms) at every point x of
// the piece, then for a triangle S with corners x_i inside the piece and p in S,
//     L delta(p) - delta(p) = sum_i l_i integral_0^1 (1 - t) (x_i - p)^T H (x_i - p) dt
//                          <= (1/2) sum_i l_i |x_i - p|_A^2 = sum_{i<j} l_i l_j c_ij,
// c_ij = |x_i - x_j|_A^2 / 2 (the first-order terms cancel: sum_i l_i (x_i - p) = 0), and delta is
// convex, so 0 <= L delta - delta <= bubbleMax(c01, c12, c20) on S:
//     |F - L| <= speed bubbleMax(c(S's edges)),   c(e) = e^T A e / 2.
// A is one form for the whole piece: a triangle of the piece scaled by 1/n has the bound of the
// piece over n^2. Two forms A qualify; pieceForm takes, per piece, the one whose bubbleMax on the
// piece's sides is the smaller (both bound H, so either is sound).
// In the coordinates where |.|_M is Euclidean (y = M^(1/2) x, rho = |y_c| = |x_c|_M at the
// centroid, y^ = y / |y|), H(y) = P_y / ((1 - b^2) |y|), P_y the projection across y^ (above).
// (1) The direct form. Split a step u = alpha y_c^ + u_perp (along and across the centroid's
// direction). P_y u = alpha P_y y_c^ + P_y u_perp, |P_y y_c^| = sin theta (theta: the angle between
// y^ and y_c^) and |P_y u_perp| <= |u_perp|, so for any mu > 0 (Young)
//     |P_y u|^2 <= (|alpha| sin theta + |u_perp|)^2 <= (1 + mu) |u_perp|^2 + (1 + 1/mu) sin^2 theta alpha^2.
// On the piece y = y_c + d with d in the triangle of the corners' offsets d_i: |y| >= y_c^.y =
// rho + y_c^.d >= m = rho - max_i (-y_c^.d_i) (linear in d: least at a corner), and
// sin theta = |d_perp| / |y| <= min(1, p / m), p = max_i |d_i,perp| (|d_perp| is convex in d). So
//     A1 = ((1 + mu) P_c + (1 + 1/mu) sin^2 y_c^ y_c^T) / ((1 - b^2) m),   P_c the projection across y_c^,
// with no derivative of the delay at all: its slack over H(y_c) = P_c / ((1 - b^2) rho) is the
// piece's reach towards the camera, rho / m - 1, and mu across the direction of sight (the Hessian
// really is larger by rho / |y| at the piece's near corner: a uniform grid pays the worst spot), and
// along it only the second-order term sin^2 (the Hessian has no part along y_c^ at the centroid).
// mu is chosen per piece among the four values that balance the two terms on each side and on
// their sums (mu = sqrt(b / a), a the across-part of the side, b its along-part times sin^2,
// clamped to [1e-6, 1e6]), the one with the least bubbleMax. With a segment of the piece on the
// line of sight through the camera's side (m <= 0) A1 is unbounded.
// (2) The Taylor form (the earlier one, kept for pieces where it is tighter): for any u,
//     u^T H(x) u <= u^T H(x_c) u + K |u|_M^2,   K = (2 / sqrt 3) r_M / ((1 - b^2) m_r^2):
// u^T (H(x) - H(x_c)) u is the integral of D^3 delta [u, u, x - x_c] along the segment, and a
// symmetric trilinear form's norm is its largest value on one unit vector (Banach), here
// (2 / sqrt 3) / ((1 - b^2) |x|_M^2) in the metric M (the norm's third derivative, as above);
// |x - x_c|_M <= r_M (the largest M-distance from the centroid to a corner) and
// |x|_M >= m_r = |x_c|_M - r_M on the piece. So A2 = H(x_c) + K M.
// The price of either over H(x_c) is about the piece's size over its distance (A2: r_M / |x| on
// every side, the sides along the line of sight included, where H(x_c) is nearly zero; A1: the
// reach towards the camera across it, second order along it): `centre` holds the coefficients of
// H(x_c) alone, so the caller can tell how much the piece's size costs (pieces small against
// their distance from the camera get the template; larger ones are bisected first).
// Rounding: as the edge bounds', a few ulps of terms of the size of the bound.
struct PieceForm {
    double c[3] = {INFINITY, INFINITY, INFINITY};  // c(e) of side e (s[e] -> s[e + 1]) with A
    double centre[3] = {0, 0, 0};                  // the same with H(x_c) alone
    bool finite = false;                           // false when the piece may reach the camera (m <= 0)
};
// The form of the piece with corners' shape offsets s (E = nowBase): the candidates of (1) and
// (2) in order (the direct form's mu for each side, then for their sums; the Taylor form), the first
// with the least bubbleMax on the piece's sides kept; `centre` always made. Not finite when no
// candidate is bounded (a piece reaching the camera) or a kept coefficient is NaN or +infinity.
// pieceFormLanes is the same, bit for bit, with the direct candidates two at a time on the lanes
// of lanes.h. Either passes a candidate without its bubbleMax where its first term (bubbleFirst,
// which bubbleMax never falls below) already loses.
PieceForm pieceForm(const Motion& m, const Vec3& E, const Vec3 s[3]);
#if !defined(APPARENT_NO_LANES)
PieceForm pieceFormLanes(const Motion& m, const Vec3& E, const Vec3 s[3]);
#endif

// Whether pieceForm(m, E, s) is finite and speed bubbleMax(its c) <= tolerance, without the
// candidates after the first that passes: the least candidate passes when any does (the product
// by speed is monotonic), so the answer is pieceForm's whenever its coefficients are numbers.
// A candidate with speed times its least value over the tolerance fails without its bubbleMax
// (speed >= 0: rounding is monotonic, and bubbleMax is not below its least).
bool pieceFormWithin(const Motion& m, const Vec3& E, const Vec3 s[3], double speed, double tolerance);
#if !defined(APPARENT_NO_LANES)
bool pieceFormWithinLanes(const Motion& m, const Vec3& E, const Vec3 s[3], double speed, double tolerance);
#endif

// ---- Scalar and lanes ----
// Each bound above with a two-lane form has its scalar form beside it, named X and XLanes
// (edgeBubble / edgeBubbleLanes, pieceForm / pieceFormLanes, pieceFormWithin / pieceFormWithinLanes;
// in chord_error.cpp also bubbleMax / bubbleMaxLanes, bubbleFirst / bubbleFirstLanes, directForm /
// directFormLanes, pieceFormTerms / pieceFormTermsLanes). A lane makes the scalar form's IEEE
// operations in the same order (both sides of a branch made and the lane's own selected), so the
// two give the same bits: +, -, *, / and sqrt are correctly rounded, and nothing is contracted
// (the mesh4d library is compiled with -ffp-contract=off, CMakeLists.txt: a fused multiply-add
// rounds once where the scalar code rounds twice, and a compiler may fuse in one form and not the
// other). The refinement calls the lanes forms; the CMake option APPARENT_NO_LANES (a compile
// definition) removes them and it calls the scalar forms: CI builds both and compares their bytes
// (scripts/compare_builds.sh), Refine.PieceFormsMatchTheReferenceBitForBit and
// RefinePairs.EdgeBubbleLanesIsEdgeBubbleBitForBit compare them directly.

// ---- Why the steps hold: the reasoning behind the step headings of the .cpp files ----
// refine/chord_error.cpp:
//   - The terms all of a piece's candidate forms are made from (the quantities of chord_error.h's
//     "The whole-piece bound"): the centroid's |x_c|_M, r_M^2, per side (s[e] -> s[e + 1]) its parts
//     across and along y_c^ (|e_perp|^2 and alpha^2) and H(x_c)'s coefficient; the direct form's m,
//     sin^2 theta bound and factor.
//   - The direct form's candidates: the four balances mu when the along-parts' sum is positive, else
//     one (mu = 1e-6 and no along term).
//   - Candidate j's sides' coefficients c[e] and the least value bubbleMax can give them
//     (bubbleFirst, which bubbleMax returns or exceeds, NaNs alike): a candidate whose least value
//     already loses is never chosen, so its bubbleMax need not be made.
//   - The Taylor form's coefficients from H(x_c)'s (t.centre) and its least value (as directForm's);
//     false when it is unbounded (m_r <= 0).
//   - pieceFormTerms on the lanes of lanes.h: the six steps u two at a time, lanes (d0, d1), (d2,
//     e0), (e1, e2) (d_i = s_i - centre, e = s[e + 1] - s[e]), each lane pieceFormTerms' operations
//     in its order.
//   - bubbleMax lane by lane (the interior value made in both lanes and selected where the point is
//     inside), from its first term `first` = bubbleFirstLanes(c01, c12, c20), made by the caller.
//   - Step: the candidates in order, the first with the least bubbleMax kept; a candidate whose
//     least value is not below the best so far is passed without its bubbleMax (the same choice).
//   - edgeBubble per lane: both branches made and each lane's own selected (me > 0, then me >= l; a
//     NaN compares false in both, as there), the closing min and max as std::min and std::max.

}  // namespace mesh4d
