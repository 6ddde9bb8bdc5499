#include "chord_error.h"

#include <algorithm>
#include <cmath>

namespace mesh4d {

double bubbleMax(double c01, double c12, double c20) {
    // a_k: coefficient of the edge opposite corner k.
    const double a0 = c12, a1 = c20, a2 = c01;
    double best = 0.25 * std::max({a0, a1, a2});  // edge middles
    const double w0 = a0 * (a1 + a2 - a0), w1 = a1 * (a0 + a2 - a1), w2 = a2 * (a0 + a1 - a2);
    const double den = w0 + w1 + w2;  // = 2 (a0 a1 + a1 a2 + a2 a0) - a0^2 - a1^2 - a2^2
    if (w0 >= 0 && w1 >= 0 && w2 >= 0 && den > 0) best = std::max(best, a0 * a1 * a2 / den);
    return best;
}

namespace {
// The corners' shape offsets (into s) and the least |x_i|_M.
double cornerTerms(const ViewAnchor& anchor, const Motion& m, const Event corner[3], Vec3 s[3]) {
    double xm_min = INFINITY;
    for (int i = 0; i < 3; ++i) {
        s[i] = shapeOfEvent(m, corner[i]);
        xm_min = std::min(xm_min, normMOfEvent(anchor, m, corner[i]));
    }
    return xm_min;
}
}  // namespace

ChordError chordError(const ViewAnchor& anchor, const Motion& m, const Event corner[3], const Event mid[3],
                      double tolerance) {
    if (m.beta == 0) return {};
    const double t_corner[3] = {corner[0].t, corner[1].t, corner[2].t};
    const double t_mid[3] = {mid[0].t, mid[1].t, mid[2].t};
    Vec3 s[3];
    double xm[3];
    for (int i = 0; i < 3; ++i) {
        s[i] = shapeOfEvent(m, corner[i]);
        xm[i] = normMOfEvent(anchor, m, corner[i]);
    }
    return chordErrorOfTerms(m, t_corner, t_mid, s, xm, tolerance);
}

ChordError chordErrorOfTerms(const Motion& m, const double t_corner[3], const double t_mid[3], const Vec3 s[3],
                             const double xm[3], double tolerance) {
    if (m.beta == 0) return {};
    // Delays (delta = -t) and the midpoint bubbles, |beta| (delta is convex: beta <= 0 up to rounding).
    double c[3];
    for (int e = 0; e < 3; ++e) {
        const double d0 = -t_corner[e], d1 = -t_corner[(e + 1) % 3], dm = -t_mid[e];
        c[e] = 4 * std::fabs(dm - 0.5 * (d0 + d1));
    }
    return chordErrorOfBubbles(m, c, s, xm, tolerance);
}

ChordError chordErrorOfBubbles(const Motion& m, const double c[3], const Vec3 s[3], const double xm[3],
                               double tolerance) {
    ChordError r;
    if (m.beta == 0) return r;
    const double Q = bubbleMax(c[0], c[1], c[2]);
    r.quadratic = m.beta * Q;
    // Over the tolerance on the bubbles alone: R only adds (callers compare the bound only).
    if (!(r.quadratic <= tolerance)) {
        r.bound = r.quadratic == r.quadratic ? r.quadratic : INFINITY;
        return r;
    }
    // The shape offsets' centroid, the M-radius r_M and the least |x_i|_M.
    double xm_min = INFINITY;
    for (int i = 0; i < 3; ++i) xm_min = std::min(xm_min, xm[i]);
    const Vec3 centre = (s[0] + s[1] + s[2]) / 3.0;
    // The largest |s_i - centre|_M: one square root of the largest square (sqrt is monotonic and
    // correctly rounded, so this is the largest of the three roots, bit for bit).
    double q = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3 u = s[i] - centre;
        const double uv = dot(u, m.velocity);
        q = std::max(q, uv * uv + m.one_minus_beta2 * norm2(u));
    }
    const double rM = std::sqrt(q);
    const double mlow = xm_min - 2 * rM;
    const double R = mlow > 0 ? 8 * rM * rM * rM / (9 * std::sqrt(3.0) * m.one_minus_beta2 * mlow * mlow) : INFINITY;
    r.bound = m.beta * (Q + R);
    if (!(r.bound == r.bound)) r.bound = INFINITY;  // NaN from a degenerate input: never accepted
    return r;
}

EdgeBubble edgeBubble(const Motion& m, const Vec3& E, const PointTerms& a, const PointTerms& b) {
    EdgeBubble r;
    if (m.beta == 0) return r;
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
    if (!(r.c == r.c)) r.c = INFINITY;
    if (!(r.length == r.length)) r.length = 0;
    return r;
}

double chordErrorFromCorners(const ViewAnchor& anchor, const Motion& m, const Event corner[3]) {
    if (m.beta == 0) return 0;
    Vec3 s[3];
    const double xm_min = cornerTerms(anchor, m, corner, s);
    double d2 = 0;  // d_M^2
    for (int i = 0; i < 3; ++i) {
        const Vec3 u = s[(i + 1) % 3] - s[i];
        const double uv = dot(u, m.velocity);
        d2 = std::max(d2, uv * uv + m.one_minus_beta2 * norm2(u));
    }
    const double mlow = xm_min - std::sqrt(d2);
    if (!(mlow > 0)) return INFINITY;
    const double bound = m.beta * d2 / (6 * m.one_minus_beta2 * mlow);
    return bound == bound ? bound : INFINITY;
}

}  // namespace mesh4d
