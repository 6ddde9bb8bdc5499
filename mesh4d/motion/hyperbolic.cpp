#include "mesh4d/motion/worldline.h"

#include <cmath>

#include "mesh4d/motion/local.h"

namespace mesh4d {

using namespace motion_detail;

namespace {

// The origin's proper time sigma at lab time t0 + dt > t0 on its hyperbolic lab path:
// dt = (g / a) (sinh(a sigma) + k (cosh(a sigma) - 1)), k = v.a/|a|, is the quadratic
// (1 + k) u^2 - 2 (k + c) u + (k - 1) = 0 in u = e^(a sigma), c = a dt / g, whose one positive
// root is taken without cancellation.
double originProperTimeAtLab(const Motion& m, double dt) {
    const double a = norm(m.acceleration);
    const double k = dot(m.velocity, m.acceleration / a);
    const double c = a * dt / lorentzGamma(m);
    const double p = k + c;
    const double root = std::sqrt(p * p + (1 - k) * (1 + k));
    const double u = p >= 0 ? (p + root) / (1 + k) : (1 - k) / (root - p);
    return std::log(u) / a;
}

}  // namespace

namespace motion_detail {

Local rigidLocal(const Motion& m, double s, const Vec3& q) {
    Local l;
    const double a = norm(m.acceleration);
    l.T = s;
    l.Y = q;
    if (!(s > 0) || !(a > 0)) return l;
    const Vec3 k = m.acceleration / a;
    const double xi = 1 / a + dot(q, k);  // distance to the horizon, start frame
    const double sh = std::sinh(a * s), ch = std::cosh(a * s), h = std::sinh(0.5 * a * s);
    l.T = xi * sh;
    l.Y = q + k * (xi * 2 * h * h);  // cosh - 1 = 2 sinh^2(x/2)
    l.dT = a * xi * ch;
    l.dY = k * (a * xi * sh);
    l.dtau = a * xi;
    return l;
}

// The origin's lab displacement and velocity (per unit lab time) at lab time t0 + dt, Galilean
// carry of an acceleration.
void originPath(const Motion& m, double dt, Vec3* disp, Vec3* vel) {
    if (!(dt > 0)) {
        *disp = m.velocity * dt;
        *vel = m.velocity;
        return;
    }
    const double g = lorentzGamma(m);
    const Local l = rigidLocal(m, originProperTimeAtLab(m, dt), Vec3{0, 0, 0});
    *disp = l.Y + stretch(m.velocity, g, l.Y) + m.velocity * (g * l.T);
    *vel = (l.dY + stretch(m.velocity, g, l.dY) + m.velocity * (g * l.dT)) / (g * (l.dT + dot(m.velocity, l.dY)));
}

// The closed form of an accelerated point's past-cone crossing on its hyperbolic part (s > 0), in
// the start frame where the camera event is (Tc, P): with xi = 1/a + q.k, xiC = 1/a + P.k and rho
// the distance of q - P from the line along k, (Tc - T)^2 = |Y - P|^2 on T = xi sinh(a s),
// Y.k - P.k = xi cosh(a s) - xiC is, with u = e^(a s),
//     (xiC - Tc) u^2 - (K / xi) u + (xiC + Tc) = 0,   K = rho^2 + xi^2 + xiC^2 - Tc^2.
// The root with u > 1 and T < Tc; false when there is none (the crossing is before t0).
bool hyperbolicCrossing(const ViewSurface& view, const Motion& m, const Vec3& q, double* s_out) {
    const double a = norm(m.acceleration);
    const Vec3 k = m.acceleration / a;
    const double g = m.gamma;
    const double dt = view.t_c - m.t0;
    const Vec3 dx = view.apex - m.origin;
    const double Tc = g * (dt - dot(m.velocity, dx));
    const Vec3 P = dx + stretch(m.velocity, g, dx) - m.velocity * (g * dt);
    const double xi = 1 / a + dot(q, k), xiC = 1 / a + dot(P, k);
    const Vec3 d = q - P;
    const double rho2 = norm2(d - k * dot(d, k));
    const double K = rho2 + xi * xi + xiC * xiC - Tc * Tc;
    const double A = xiC - Tc, B = -K / xi, C = xiC + Tc;
    double roots[2];
    int n = 0;
    if (A == 0) {
        if (B != 0) roots[n++] = -C / B;
    } else {
        const double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            const double sq = std::sqrt(disc);
            const double qq = -0.5 * (B + (B >= 0 ? sq : -sq));  // the same-sign form
            if (qq != 0) roots[n++] = qq / A, roots[n++] = C / qq;
        }
    }
    for (int i = 0; i < n; ++i) {
        const double u = roots[i];
        if (!(u > 1) || !std::isfinite(u)) continue;
        if (!(xi * 0.5 * (u - 1 / u) < Tc)) continue;  // the future sheet
        *s_out = std::log(u) / a;
        return true;
    }
    return false;
}

}  // namespace motion_detail

double originProperTime(const Motion& m, double dt) {
    if (!(dt > 0) || kindOf(m) != MotionKind::Hyperbolic) return dt;
    return originProperTimeAtLab(m, dt);
}

double horizonDistance(const Motion& m, const Vec3& q) {
    const double a = norm(m.acceleration);
    if (!(a > 0)) return INFINITY;
    return 1 / a + dot(q, m.acceleration / a);
}

double originTimeAtCrossing(const Motion& m, const WorldlineCrossing& c) {
    const double t_lab = c.event.t - m.t0;
    return m.kinematics == Kinematics::Lorentz ? c.s : originProperTime(m, t_lab);
}

}  // namespace mesh4d
