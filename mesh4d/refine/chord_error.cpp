#include "chord_error.h"

#include <algorithm>
#include <cmath>

#if !defined(APPARENT_NO_LANES)
#include "mesh4d/lanes.h"
#endif

namespace mesh4d {

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
    return displacedChordError(m, m.beta, t_corner, t_mid, s, xm, tolerance);
}

ChordError displacedChordError(const Motion& m, double speed, const double t_corner[3], const double t_mid[3],
                               const Vec3 s[3], const double xm[3], double tolerance) {
    if (speed == 0) return {};  // no displacement: the map is affine
    // Delays (delta = -t) and the midpoint bubbles, |beta| (delta is convex: beta <= 0 up to rounding).
    double c[3];
    for (int e = 0; e < 3; ++e) {
        const double d0 = -t_corner[e], d1 = -t_corner[(e + 1) % 3], dm = -t_mid[e];
        c[e] = 4 * std::fabs(dm - 0.5 * (d0 + d1));
    }
    return chordErrorOfBubbles(m, speed, c, s, xm, tolerance);
}

double chordErrorFromCorners(const ViewAnchor& anchor, const Motion& m, const Event corner[3]) {
    if (m.beta == 0) return 0;
    Vec3 s[3];
    double xm[3];
    for (int i = 0; i < 3; ++i) {
        s[i] = shapeOfEvent(m, corner[i]);
        xm[i] = normMOfEvent(anchor, m, corner[i]);
    }
    return chordErrorFromSpread(cornerSpread(s, m), xm, m);
}

namespace {

// The terms all of a piece's candidate forms are made from.
struct PieceFormTerms {
    double k;                  // 1 - b^2
    double xm2, xm;            // |x_c|_M^2, |x_c|_M
    double q;                  // r_M^2, the largest squared M-distance from the centroid to a corner
    double m1;                 // the direct form's m (bounded when > 0; sin2, inv, a[3], b set then)
    double a[4], b[4];         // the balances' across and along parts: the sides' (a[e] = |e_perp|^2), then their sums
    double along2[3];          // alpha^2 of each side
    double centre[3];          // H(x_c)'s coefficients (PieceForm::centre)
    double sin2, inv;          // the sin^2 theta bound and 1 / (2 (1 - b^2) m)
};

// Step: the direct form's m, sin^2 theta bound, factor and balances, from the corners' reach and p^2.
void finishTerms(PieceFormTerms& t, double reach, double perp2) {
    const double m1 = t.m1 = t.xm - reach;
    if (m1 > 0) {
        const double sin2 = t.sin2 = std::min(1.0, std::max(0.0, perp2) / (m1 * m1));
        t.inv = 0.5 / (t.k * m1);
        for (int e = 0; e < 3; ++e) t.b[e] = sin2 * t.along2[e];
        t.a[3] = t.a[0] + t.a[1] + t.a[2];
        t.b[3] = t.b[0] + t.b[1] + t.b[2];
    }
}

// Fills t in place (the direct form's fields only when m1 > 0).
void pieceFormTerms(const Motion& m, const Vec3& E, const Vec3 s[3], PieceFormTerms& t) {
    const double k = t.k = m.one_minus_beta2;
    const Vec3 centre = (s[0] + s[1] + s[2]) / 3.0;
    const Vec3 x = E + centre;
    const double xv = dot(x, m.velocity);
    const double xm2 = t.xm2 = xv * xv + k * norm2(x);
    const double xm = t.xm = std::sqrt(xm2);
    // Step: the corners d_i = s_i - centre: r_M^2, the reach towards the camera, p^2.
    double q = 0, reach = 0, perp2 = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3 u = s[i] - centre;
        const double uv = dot(u, m.velocity);
        const double d2 = uv * uv + k * norm2(u);
        const double along = (uv * xv + k * dot(u, x)) / xm;
        q = std::max(q, d2);
        reach = std::max(reach, -along);
        perp2 = std::max(perp2, d2 - along * along);
    }
    t.q = q;
    // Step: the sides s[e] -> s[e + 1]: alpha^2, |e_perp|^2 and H(x_c)'s coefficient.
    for (int e = 0; e < 3; ++e) {
        const Vec3 u = s[(e + 1) % 3] - s[e];
        const double uv = dot(u, m.velocity);
        const double l2 = uv * uv + k * norm2(u);
        const double uMx = uv * xv + k * dot(u, x);
        const double uMx2 = uMx * uMx;
        t.along2[e] = uMx2 / xm2;
        t.a[e] = std::max(0.0, l2 - t.along2[e]);
        t.centre[e] = 0.5 * std::max(0.0, l2 * xm2 - uMx2) / (k * xm2 * xm);
    }
    finishTerms(t, reach, perp2);
}

// The direct form's candidates.
int directCandidates(const PieceFormTerms& t) { return t.b[3] > 0 ? 4 : 1; }

// Candidate j's sides' coefficients c[e] and the least value bubbleMax can give them.
void directForm(const PieceFormTerms& t, int j, double c[3], double* least) {
    double mu = 1e-6, fb = 0;
    if (t.b[3] > 0) {
        mu = t.a[j] > 0 ? std::min(1e6, std::max(1e-6, std::sqrt(t.b[j] / t.a[j]))) : 1e6;
        fb = 1 + 1 / mu;
    }
    const double fa = 1 + mu, fbs = fb * t.sin2;
    for (int e = 0; e < 3; ++e) c[e] = t.inv * (fa * t.a[e] + fbs * t.along2[e]);
    *least = bubbleFirst(c[0], c[1], c[2]);
}

// The Taylor form's coefficients from H(x_c)'s (t.centre) and its least value.
bool taylorForm(const PieceFormTerms& t, const double centre_c[3], double c[3], double* least) {
    const double rM = std::sqrt(t.q);
    const double mlow = t.xm - rM;
    if (!(mlow > 0)) return false;
    const double K = 2 / 1.7320508075688772 * rM / (t.k * mlow * mlow);
    for (int e = 0; e < 3; ++e) c[e] = centre_c[e] + 0.5 * K * (t.a[e] + t.along2[e]);
    *least = bubbleFirst(c[0], c[1], c[2]);
    return true;
}

#if !defined(APPARENT_NO_LANES)
// pieceFormTerms on the lanes of lanes.h.
void pieceFormTermsLanes(const Motion& m, const Vec3& E, const Vec3 s[3], PieceFormTerms& t) {
    const double k = t.k = m.one_minus_beta2;
    const Vec3 centre = (s[0] + s[1] + s[2]) / 3.0;
    const Vec3 x = E + centre;
    const double xv = dot(x, m.velocity);
    const double xm2 = t.xm2 = xv * xv + k * norm2(x);
    const double xm = t.xm = std::sqrt(xm2);
    // Step: |u|_M^2 and u^T M x of the six steps, as dot and norm2 make them (x, then y, then z).
    const Lanes2 vx = splatLanes(m.velocity.x), vy = splatLanes(m.velocity.y), vz = splatLanes(m.velocity.z);
    const Lanes2 kk = splatLanes(k), xvv = splatLanes(xv), xx = splatLanes(x.x), xy = splatLanes(x.y), xz = splatLanes(x.z);
    Lanes2 l2[3], uMx[3];
    auto step = [&](int p, Lanes2 ux, Lanes2 uy, Lanes2 uz) {
        const Lanes2 uv = ux * vx + uy * vy + uz * vz;
        l2[p] = uv * uv + kk * (ux * ux + uy * uy + uz * uz);
        uMx[p] = uv * xvv + kk * (ux * xx + uy * xy + uz * xz);
    };
    step(0, Lanes2{s[0].x, s[1].x} - splatLanes(centre.x), Lanes2{s[0].y, s[1].y} - splatLanes(centre.y),
         Lanes2{s[0].z, s[1].z} - splatLanes(centre.z));
    step(1, Lanes2{s[2].x, s[1].x} - Lanes2{centre.x, s[0].x}, Lanes2{s[2].y, s[1].y} - Lanes2{centre.y, s[0].y},
         Lanes2{s[2].z, s[1].z} - Lanes2{centre.z, s[0].z});
    step(2, Lanes2{s[2].x, s[0].x} - Lanes2{s[1].x, s[2].x}, Lanes2{s[2].y, s[0].y} - Lanes2{s[1].y, s[2].y},
         Lanes2{s[2].z, s[0].z} - Lanes2{s[1].z, s[2].z});
    // Step: the corners (lanes of the first pair, lane 0 of the second).
    const Lanes2 along01 = uMx[0] / xm, along2x = uMx[1] / xm;
    const Lanes2 perp01 = l2[0] - along01 * along01, perp2x = l2[1] - along2x * along2x;
    t.q = std::max(std::max(std::max(0.0, l2[0][0]), l2[0][1]), l2[1][0]);
    const double reach = std::max(std::max(std::max(0.0, -along01[0]), -along01[1]), -along2x[0]);
    const double perp2 = std::max(std::max(std::max(0.0, perp01[0]), perp01[1]), perp2x[0]);
    // Step: the sides (lane 1 of the second pair, both of the third).
    const Lanes2 zero = {0, 0}, den = splatLanes(k * xm2 * xm);
    Lanes2 al[2], ac[2], cc[2];
    for (int p = 0; p < 2; ++p) {
        const Lanes2 uMx2 = uMx[p + 1] * uMx[p + 1];
        al[p] = uMx2 / xm2;
        ac[p] = maxLanes(zero, l2[p + 1] - al[p]);
        cc[p] = 0.5 * maxLanes(zero, l2[p + 1] * xm2 - uMx2) / den;
    }
    const int pair[3] = {0, 1, 1}, lane[3] = {1, 0, 1};  // side e's pair and lane
    for (int e = 0; e < 3; ++e) {
        t.along2[e] = al[pair[e]][lane[e]];
        t.a[e] = ac[pair[e]][lane[e]];
        t.centre[e] = cc[pair[e]][lane[e]];
    }
    finishTerms(t, reach, perp2);
}

// bubbleFirst lane by lane.
Lanes2 bubbleFirstLanes(Lanes2 c01, Lanes2 c12, Lanes2 c20) {
    return Lanes2{0.25, 0.25} * maxLanes(maxLanes(c12, c20), c01);
}
// bubbleMax lane by lane (the interior value made in both lanes, selected per lane).
Lanes2 bubbleMaxLanes(Lanes2 c01, Lanes2 c12, Lanes2 c20, Lanes2 first) {
    const Lanes2 a0 = c12, a1 = c20, a2 = c01;
    const Lanes2 zero = {0, 0};
    const Lanes2 w0 = a0 * (a1 + a2 - a0), w1 = a1 * (a0 + a2 - a1), w2 = a2 * (a0 + a1 - a2);
    const Lanes2 den = w0 + w1 + w2;
    const Lanes2Mask inside = (w0 >= zero) & (w1 >= zero) & (w2 >= zero) & (den > zero);
    return inside ? maxLanes(first, a0 * a1 * a2 / den) : first;
}
// directForm of candidates j and j + 1 (j = 0 or 2; with one candidate, both lanes are it).
void directFormLanes(const PieceFormTerms& t, int j, Lanes2 c[3], Lanes2* least) {
    const Lanes2 one = {1, 1}, low = {1e-6, 1e-6}, high = {1e6, 1e6}, zero = {0, 0};
    Lanes2 mu = low, fb = zero;
    if (t.b[3] > 0) {
        const Lanes2 a = {t.a[j], t.a[j + 1]}, b = {t.b[j], t.b[j + 1]};
        mu = a > zero ? minLanes(high, maxLanes(low, sqrtLanes(b / a))) : high;
        fb = one + one / mu;
    }
    const Lanes2 fa = one + mu, fbs = fb * t.sin2;
    for (int e = 0; e < 3; ++e) c[e] = t.inv * (fa * t.a[e] + fbs * t.along2[e]);
    *least = bubbleFirstLanes(c[0], c[1], c[2]);
}
#endif

}  // namespace

// Step: the candidates in order, the first with the least bubbleMax kept.
PieceForm pieceForm(const Motion& m, const Vec3& E, const Vec3 s[3]) {
    PieceForm r;
    PieceFormTerms t;
    pieceFormTerms(m, E, s, t);
    for (int e = 0; e < 3; ++e) r.centre[e] = t.centre[e];
    double best = INFINITY;
    if (t.m1 > 0)
        for (int j = 0, n = directCandidates(t); j < n; ++j) {
            double c[3], least;
            directForm(t, j, c, &least);
            if (!(least < best)) continue;
            const double v = bubbleMax(c[0], c[1], c[2]);
            if (v < best) {
                best = v;
                for (int e = 0; e < 3; ++e) r.c[e] = c[e];
            }
        }
    double c[3], least;
    if (taylorForm(t, r.centre, c, &least) && least < best) {
        const double v = bubbleMax(c[0], c[1], c[2]);
        if (v < best) {
            for (int e = 0; e < 3; ++e) r.c[e] = c[e];
        }
    }
    r.finite = r.c[0] < INFINITY && r.c[1] < INFINITY && r.c[2] < INFINITY;  // false for a NaN too
    return r;
}

bool pieceFormWithin(const Motion& m, const Vec3& E, const Vec3 s[3], double speed, double tolerance) {
    PieceFormTerms t;
    pieceFormTerms(m, E, s, t);
    const bool prune = speed >= 0;
    auto fails = [&](double least) { return prune && speed * least > tolerance; };
    auto passes = [&](const double c[3], double v) {
        return c[0] < INFINITY && c[1] < INFINITY && c[2] < INFINITY && speed * v <= tolerance;
    };
    if (t.m1 > 0)
        for (int j = 0, n = directCandidates(t); j < n; ++j) {
            double c[3], least;
            directForm(t, j, c, &least);
            if (!fails(least) && passes(c, bubbleMax(c[0], c[1], c[2]))) return true;
        }
    double c[3], least;
    return taylorForm(t, t.centre, c, &least) && !fails(least) && passes(c, bubbleMax(c[0], c[1], c[2]));
}

#if !defined(APPARENT_NO_LANES)
PieceForm pieceFormLanes(const Motion& m, const Vec3& E, const Vec3 s[3]) {
    PieceForm r;
    PieceFormTerms t;
    pieceFormTermsLanes(m, E, s, t);
    for (int e = 0; e < 3; ++e) r.centre[e] = t.centre[e];
    double best = INFINITY;
    if (t.m1 > 0)
        for (int j = 0, n = directCandidates(t); j < n; j += 2) {
            Lanes2 c[3], least;
            directFormLanes(t, j, c, &least);
            if (!(least[0] < best) && !(least[1] < best)) continue;
            const Lanes2 v = bubbleMaxLanes(c[0], c[1], c[2], least);
            for (int l = 0; l < 2 && j + l < n; ++l)
                if (v[l] < best) {
                    best = v[l];
                    for (int e = 0; e < 3; ++e) r.c[e] = c[e][l];
                }
        }
    double c[3], least;
    if (taylorForm(t, r.centre, c, &least) && least < best) {
        const double v = bubbleMax(c[0], c[1], c[2]);
        if (v < best) {
            for (int e = 0; e < 3; ++e) r.c[e] = c[e];
        }
    }
    r.finite = r.c[0] < INFINITY && r.c[1] < INFINITY && r.c[2] < INFINITY;
    return r;
}

bool pieceFormWithinLanes(const Motion& m, const Vec3& E, const Vec3 s[3], double speed, double tolerance) {
    PieceFormTerms t;
    pieceFormTermsLanes(m, E, s, t);
    const bool prune = speed >= 0;
    auto fails = [&](double least) { return prune && speed * least > tolerance; };
    auto passes = [&](double c0, double c1, double c2, double v) {
        return c0 < INFINITY && c1 < INFINITY && c2 < INFINITY && speed * v <= tolerance;
    };
    if (t.m1 > 0)
        for (int j = 0, n = directCandidates(t); j < n; j += 2) {
            Lanes2 c[3], least;
            directFormLanes(t, j, c, &least);
            const bool skip0 = fails(least[0]), skip1 = j + 1 >= n || fails(least[1]);
            if (skip0 && skip1) continue;
            const Lanes2 v = bubbleMaxLanes(c[0], c[1], c[2], least);
            if (!skip0 && passes(c[0][0], c[1][0], c[2][0], v[0])) return true;
            if (!skip1 && passes(c[0][1], c[1][1], c[2][1], v[1])) return true;
        }
    double c[3], least;
    return taylorForm(t, t.centre, c, &least) && !fails(least) &&
           passes(c[0], c[1], c[2], bubbleMax(c[0], c[1], c[2]));
}

// edgeBubble per lane.
void edgeBubbleLanes(const Motion& m, const Vec3& E, const PointTerms& a0, const PointTerms& b0, const PointTerms& a1,
                     const PointTerms& b1, EdgeBubble out[2]) {
    const double k = m.one_minus_beta2;
    const Lanes2 kk = splatLanes(k), half = splatLanes(0.5), zero = splatLanes(0);
    const Lanes2 vx = splatLanes(m.velocity.x), vy = splatLanes(m.velocity.y), vz = splatLanes(m.velocity.z);
    // Step: x = E + (a.s + b.s) * 0.5, u = b.s - a.s, component by component.
    const Lanes2 xx = splatLanes(E.x) + (Lanes2{a0.s.x, a1.s.x} + Lanes2{b0.s.x, b1.s.x}) * half;
    const Lanes2 xy = splatLanes(E.y) + (Lanes2{a0.s.y, a1.s.y} + Lanes2{b0.s.y, b1.s.y}) * half;
    const Lanes2 xz = splatLanes(E.z) + (Lanes2{a0.s.z, a1.s.z} + Lanes2{b0.s.z, b1.s.z}) * half;
    const Lanes2 ux = Lanes2{b0.s.x, b1.s.x} - Lanes2{a0.s.x, a1.s.x};
    const Lanes2 uy = Lanes2{b0.s.y, b1.s.y} - Lanes2{a0.s.y, a1.s.y};
    const Lanes2 uz = Lanes2{b0.s.z, b1.s.z} - Lanes2{a0.s.z, a1.s.z};
    const Lanes2 xv = xx * vx + xy * vy + xz * vz;
    const Lanes2 xm2 = xv * xv + kk * (xx * xx + xy * xy + xz * xz);
    const Lanes2 xm = sqrtLanes(xm2);
    const Lanes2 uv = ux * vx + uy * vy + uz * vz;
    const Lanes2 l2 = uv * uv + kk * (ux * ux + uy * uy + uz * uz);
    const Lanes2 uMx = uv * xv + kk * (ux * xx + uy * xy + uz * xz);
    const Lanes2 half_h = half * maxLanes(zero, l2 * xm2 - uMx * uMx) / (kk * xm2 * xm);
    const Lanes2 l = sqrtLanes(l2);
    const Lanes2 me = xm - half * l;
    constexpr double kThird = 8 / (9 * 1.7320508075688772);  // as edgeBubble's
    const Lanes2 third = splatLanes(kThird), inf = splatLanes(INFINITY);
    // Step: me > 0.
    const Lanes2 inv = splatLanes(1) / (kk * me * me * me);
    const Lanes2 c_near = half_h + l2 * l2 * inv / splatLanes(32);
    const Lanes2 tail = me >= l ? me * inv : splatLanes(1) / (kk * l2);
    const Lanes2 len_near = half_h + third * l * l2 * tail;
    // Step: me <= 0 (or NaN).
    const Lanes2 len_far = half_h + third * l / kk;
    const Lanes2Mask near = me > zero;
    const Lanes2 c = minLanes(inf, near ? c_near : inf);
    const Lanes2 length = maxLanes(zero, near ? len_near : len_far);
    for (int p = 0; p < 2; ++p) out[p] = EdgeBubble{c[p], length[p], xm[p]};
}
#endif

}  // namespace mesh4d
