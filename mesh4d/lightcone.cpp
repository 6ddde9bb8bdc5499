#include "lightcone.h"

#include <algorithm>
#include <cmath>

#include "exact_side.h"
#include "robust.h"
#include "motion/worldline.h"

namespace mesh4d {

double viewSide(const ViewSurface& view, const Event& e) {
    const double dt = view.t_c - e.t;
    if (view.kind == ViewKind::Hyperplane) return view.tilted() ? dt - dot(e.x - view.apex, view.tilt) : dt;
    return dt - norm(e.x - view.apex);
}

double retardedDelay(const Vec3& e, const Vec3& v, double one_minus_b2) {
    const double ee = norm2(e);
    if (ee == 0) return 0;
    const double ev = dot(e, v);
    const double s = std::sqrt(ev * ev + one_minus_b2 * ee);
    // Choose the branch that adds quantities of the same sign (docs/DESIGN.md section 5).
    if (ev >= 0) return ee / (ev + s);
    return (s - ev) / one_minus_b2;
}

WorldlineCut cutWorldline(const ViewSurface& view, const Event& anchor, const Vec3& v, double one_minus_b2) {
    // Move to the camera first: e is where the point is at t_c, relative to C.
    const double dt_now = view.t_c - anchor.t;
    WorldlineCut cut;
    if (view.kind == ViewKind::Hyperplane && !view.tilted()) {
        cut.event = {view.t_c, anchor.x + v * dt_now};
        return cut;
    }
    const Vec3 e = (anchor.x - view.apex) + v * dt_now;
    if (view.kind == ViewKind::Hyperplane) {
        const double d = dot(e, view.tilt) / (1 + dot(v, view.tilt));
        cut.event = {view.t_c - d, view.apex + (e - v * d)};
        return cut;
    }
    const double d = retardedDelay(e, v, one_minus_b2);
    cut.event = {view.t_c - d, view.apex + (e - v * d)};
    return cut;
}

Vec3 nowBase(const ViewSurface& view, const Motion& m) {
    return (m.origin - view.apex) + m.velocity * (view.t_c - m.t0);
}

Event cutRestWorldline(const ViewSurface& view, const Motion& m, const Vec3& now_base, const Vec3& q) {
    if (!isUniform(m)) return crossWorldline(view, m, q).event;
    const Vec3 e = now_base + shapeOffset(m, q);
    if (view.kind == ViewKind::Hyperplane && view.tilted()) {
        const double d = dot(e, view.tilt) / (1 + dot(m.velocity, view.tilt));
        return {view.t_c - d, view.apex + (e - m.velocity * d)};
    }
    if (view.kind == ViewKind::Hyperplane) return {view.t_c, view.apex + e};
    const double d = retardedDelay(e, m.velocity, m.one_minus_beta2);
    return {view.t_c - d, view.apex + (e - m.velocity * d)};
}

ViewAnchor viewAnchor(const ViewSurface& view, const Motion& m) {
    ViewAnchor a;
    a.view = view;
    if (!isUniform(m)) {
        const Event origin = crossWorldline(view, m, Vec3{0, 0, 0}).event;
        a.cone = view.kind == ViewKind::PastCone;
        a.origin = origin.x;
        a.time_origin = origin.t;
        a.y0 = origin.x - view.apex;
        return a;
    }
    const Vec3 E = nowBase(view, m);
    if (view.kind == ViewKind::Hyperplane && view.tilted()) {
        // The null hyperplane: the origin's delay D = E.k / (1 + v.k), each point's delta = s.lean.
        a.cone = false;
        a.tilted = true;
        a.lean = view.tilt / (1 + dot(m.velocity, view.tilt));
        const double D = dot(E, a.lean);
        a.y0 = E - m.velocity * D;
        a.origin = view.apex + a.y0;
        a.time_origin = view.t_c - D;
        return a;
    }
    if (view.kind == ViewKind::Hyperplane) {
        a.cone = false;
        a.y0 = E;
        a.origin = view.apex + E;
        a.time_origin = view.t_c;
        return a;
    }
    const double ev = dot(E, m.velocity);
    a.S = std::sqrt(ev * ev + m.one_minus_beta2 * norm2(E));
    const double D = retardedDelay(E, m.velocity, m.one_minus_beta2);
    a.y0 = E - m.velocity * D;
    a.origin = view.apex + a.y0;
    a.time_origin = view.t_c - D;
    return a;
}

namespace {
inline Event cutLocal(const ViewAnchor& anchor, const Motion& m, const Vec3& s) {
    if (anchor.tilted) {
        const double delta = dot(s, anchor.lean);
        return {-delta, s - m.velocity * delta};
    }
    if (!anchor.cone) return {0, s};
    const double K = 2 * dot(s, anchor.y0) + norm2(s);
    const double B = anchor.S + dot(s, m.velocity);
    const double disc = std::sqrt(std::max(0.0, B * B + m.one_minus_beta2 * K));
    // The same-sign branch: no cancellation in the denominator (B >= 0) or the numerator. Written
    // as selects and one division so that the batch loop below vectorizes; K = 0 with B >= 0
    // (the anchor point itself) gives 0 / 1.
    const bool plus = B >= 0;
    const double num = plus ? (K == 0 ? 0.0 : K) : disc - B;
    const double den = plus ? (K == 0 ? 1.0 : B + disc) : m.one_minus_beta2;
    const double delta = num / den;
    return {-delta, s - m.velocity * delta};
}
}  // namespace

Event cutRestLocal(const ViewAnchor& anchor, const Motion& m, const Vec3& q) {
    if (!isUniform(m)) {
        const Event e = crossWorldline(anchor.view, m, q).event;
        return {e.t - anchor.time_origin, e.x - anchor.origin};
    }
    return cutLocal(anchor, m, shapeOffset(m, q));
}

namespace {
// The batch loop on the cone with the contraction chosen at compile time, written without
// branches (selects only) so that the compiler can vectorize it; the same operations in the same
// order as cutLocal, so the results are bit-identical (a test compares them).
template <bool kContract>
void cutBatch(const ViewAnchor& anchor, const Motion& m, const Vec3* __restrict q, size_t n, Vec3* __restrict positions,
              double* __restrict times) {
    const Vec3 u = kContract ? m.velocity / m.beta : Vec3{0, 0, 0};
    const double gamma = m.gamma, a = m.one_minus_beta2, S = anchor.S;
    const double vx = m.velocity.x, vy = m.velocity.y, vz = m.velocity.z;
    const double yx = anchor.y0.x, yy = anchor.y0.y, yz = anchor.y0.z;
    for (size_t i = 0; i < n; ++i) {
        Vec3 s = q[i];
        if (kContract) {
            const double along = dot(s, u);
            s = (s - u * along) + u * (along / gamma);
        }
        const double K = 2 * (s.x * yx + s.y * yy + s.z * yz) + (s.x * s.x + s.y * s.y + s.z * s.z);
        const double B = S + (s.x * vx + s.y * vy + s.z * vz);
        const double r = B * B + a * K;
        const double disc = std::sqrt(r > 0.0 ? r : 0.0);
        const bool plus = B >= 0;
        const bool zero = K == 0;
        const double num = plus ? (zero ? 0.0 : K) : disc - B;
        const double den = plus ? (zero ? 1.0 : B + disc) : a;
        const double delta = num / den;
        positions[i] = {s.x - vx * delta, s.y - vy * delta, s.z - vz * delta};
        times[i] = -delta;
    }
}
}  // namespace

void cutRestLocalBatch(const ViewAnchor& anchor, const Motion& m, const Vec3* q, size_t n, Vec3* positions,
                       double* times) {
    // shapeOffset inlined: q itself (Galilean, or at rest), or contracted along u by 1/gamma.
    if (!isUniform(m)) {
        for (size_t i = 0; i < n; ++i) {
            const Event e = cutRestLocal(anchor, m, q[i]);
            positions[i] = e.x;
            times[i] = e.t;
        }
    } else if (anchor.tilted) {
        for (size_t i = 0; i < n; ++i) {
            const Event e = cutLocal(anchor, m, shapeOffset(m, q[i]));
            positions[i] = e.x;
            times[i] = e.t;
        }
    } else if (!anchor.cone) {
        for (size_t i = 0; i < n; ++i) {
            positions[i] = shapeOffset(m, q[i]);
            times[i] = 0;
        }
    } else if (m.kinematics == Kinematics::Lorentz && m.beta > 0) {
        cutBatch<true>(anchor, m, q, n, positions, times);
    } else {
        cutBatch<false>(anchor, m, q, n, positions, times);
    }
}

// Bisection on the side function; h changes sign on [0, 1] by precondition. 64 halvings reach
// the spacing of doubles in [0, 1] near any root away from 0.
static double bisectSide(const ViewSurface& view, const Event& p0, const Event& p1) {
    double lo = 0, hi = 1;
    const bool lo_positive = viewSideSign(view, p0) > 0;
    for (int it = 0; it < 64; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        const bool mid_positive = viewSideSign(view, lerp(p0, p1, mid)) > 0;
        if (mid_positive == lo_positive) lo = mid; else hi = mid;
    }
    return 0.5 * (lo + hi);
}

double cutSegment(const ViewSurface& view, const Event& p0, const Event& p1) {
    // Step 1: the two end values decide the trivial cases.
    const double h0 = viewSide(view, p0), h1 = viewSide(view, p1);
    if (viewSideSign(view, p0) == 0) return 0;
    if (viewSideSign(view, p1) == 0) return 1;
    if (view.kind == ViewKind::Hyperplane) return std::clamp(h0 / (h0 - h1), 0.0, 1.0);

    // Step 2: the cone. Relative to the camera, dt(s) = A + s B and dx(s) = P + s Q; the cone
    // condition dt^2 - |dx|^2 = 0 reads a s^2 + 2 hh s + k = 0.
    const double A = view.t_c - p0.t, B = p0.t - p1.t;
    const Vec3 P = p0.x - view.apex, Q = p1.x - p0.x;
    const double a = B * B - norm2(Q);
    const double hh = A * B - dot(P, Q);
    const double k = A * A - norm2(P);
    const QuadraticRoots roots = solveQuadratic(a, hh, k);

    // Step 3: keep the root inside the segment and on the past sheet (dt >= 0). By concavity of h
    // there is exactly one; allow rounding slack of a few ulps at the ends.
    constexpr double kSlack = 1e-12;  // in units of the segment parameter, far above 1 ulp of 1
    double best = -1;
    int found = 0;
    for (int r = 0; r < roots.count; ++r) {
        const double s = r == 0 ? roots.r0 : roots.r1;
        if (!(s >= -kSlack && s <= 1 + kSlack)) continue;
        if (A + s * B < 0) continue;
        best = s;
        ++found;
        if (roots.r0 == roots.r1) break;
    }
    if (found == 1) return std::clamp(best, 0.0, 1.0);
    return bisectSide(view, p0, p1);
}

}  // namespace mesh4d
