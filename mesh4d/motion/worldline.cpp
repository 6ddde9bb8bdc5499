#include "mesh4d/motion/worldline.h"

#include "mesh4d/motion/keyed.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mesh4d {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Rodrigues' turn of q about unit axis k by angle a, with 1 - cos a = 2 sin^2(a/2) (no cancellation
// for small angles).
Vec3 turn(const Vec3& k, double a, const Vec3& q) {
    const double c = std::cos(a), sn = std::sin(a), h = std::sin(0.5 * a);
    return q * c + cross(k, q) * sn + k * (dot(k, q) * 2 * h * h);
}

bool accelerated(const Motion& m) {
    return m.acceleration.x != 0 || m.acceleration.y != 0 || m.acceleration.z != 0;
}

// q's event at s in the object's own frame (the centre frame of a spin, the start frame of an
// acceleration: the rest frame of `velocity`, origin at the event (t0, X0)), its derivatives with
// respect to s, and the rate of q's clock.
struct Local {
    double T = 0;
    Vec3 Y;
    double dT = 1;
    Vec3 dY;
    double dtau = 1;
};

Local spinLocal(const Motion& m, double s, const Vec3& q) {
    Local l;
    l.T = s;
    const Vec3& w = m.angular_velocity;
    const double wn = norm(w);
    if (!(wn > 0)) {
        l.Y = q;
        return l;
    }
    l.Y = turn(w / wn, wn * s, q);
    l.dY = cross(w, l.Y);
    const double u = norm(cross(w, q));
    l.dtau = std::sqrt((1 - u) * (1 + u));
    return l;
}

// Born-rigid hyperbolic motion from s = 0 on, uniform before (the header).
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

// A keyframed path in its own frame (keyed.h): T = s.
Local keyedLocalEvent(const Motion& m, double s, const Vec3& q) {
    const KeyedLocal k = keyedLocal(*m.keyed, s, q);
    Local l;
    l.T = s;
    l.Y = k.y;
    l.dY = k.dy;
    l.dtau = k.dtau;
    return l;
}

Local localEvent(const Motion& m, double s, const Vec3& q) {
    if (m.keyed) return keyedLocalEvent(m, s, q);
    return accelerated(m) ? rigidLocal(m, s, q) : spinLocal(m, s, q);
}

// gamma of `velocity` whatever the kinematics (the Galilean carry of an acceleration follows the
// origin's relativistic lab path).
double lorentzGamma(const Motion& m) { return 1.0 / std::sqrt(m.one_minus_beta2); }

// (g - 1)(a.u) u = v (a.v) g^2 / (g + 1): the boost's stretch along v, no division by b.
Vec3 stretch(const Vec3& v, double g, const Vec3& a) { return v * (dot(a, v) * (g * g / (g + 1.0))); }

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

// The event of q at s relative to (t_c, C), large terms first, with its s-derivatives.
struct Rel {
    Event e;
    WorldlineRate rate;
};
Rel relativeEvent(const Motion& m, double s, const Vec3& q, double t_c, const Vec3& apex) {
    Rel r;
    if (m.kinematics == Kinematics::Galilean) {
        r.e.t = (m.t0 - t_c) + s;
        if (m.keyed) {  // carried in the lab along the path (keyed.h)
            const KeyedLocal l = keyedLocal(*m.keyed, s, q);
            r.e.x = (m.origin - apex) + l.y;
            r.rate.dx = l.dy;
        } else if (accelerated(m)) {
            Vec3 disp, vel;
            originPath(m, s, &disp, &vel);
            r.e.x = (m.origin - apex) + (q + disp);
            r.rate.dx = vel;
        } else {
            const Local l = spinLocal(m, s, q);
            r.e.x = (m.origin - apex) + (l.Y + m.velocity * s);
            r.rate.dx = l.dY + m.velocity;
        }
        return r;
    }
    const Local l = localEvent(m, s, q);
    const double g = m.gamma;
    r.e.t = (m.t0 - t_c) + g * (l.T + dot(m.velocity, l.Y));
    r.e.x = (m.origin - apex) + (l.Y + stretch(m.velocity, g, l.Y) + m.velocity * (g * l.T));
    r.rate.dt = g * (l.dT + dot(m.velocity, l.dY));
    r.rate.dx = l.dY + stretch(m.velocity, g, l.dY) + m.velocity * (g * l.dT);
    r.rate.dtau = l.dtau;
    return r;
}

double sideOf(ViewKind kind, const Event& rel) { return kind == ViewKind::Hyperplane ? -rel.t : -rel.t - norm(rel.x); }

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

}  // namespace

Vec3 spunPoint(const Motion& m, double s, const Vec3& q) { return spinLocal(m, s, q).Y; }

Event worldlineEvent(const Motion& m, double s, const Vec3& q) {
    if (isUniform(m)) return labFromRest(m, s, q);
    return relativeEvent(m, s, q, 0.0, Vec3{0, 0, 0}).e;
}

WorldlineRate worldlineRate(const Motion& m, double s, const Vec3& q) {
    return relativeEvent(m, s, q, 0.0, Vec3{0, 0, 0}).rate;
}

Vec3 worldlineVelocity(const Motion& m, double s, const Vec3& q) {
    const WorldlineRate r = worldlineRate(m, s, q);
    return r.dx / r.dt;
}

double spinSpeed(const Motion& m, const Vec3& q) { return norm(cross(m.angular_velocity, q)); }

double worldlineProperTime(const Motion& m, double s, const Vec3& q) {
    if (m.kinematics == Kinematics::Galilean || isUniform(m)) return s;
    if (m.keyed) return keyedProperTime(*m.keyed, s, q);
    if (accelerated(m)) {
        if (!(s > 0)) return s;
        const double a = norm(m.acceleration);
        return (1 + a * dot(q, m.acceleration / a)) * s;
    }
    const double u = spinSpeed(m, q);
    return s * std::sqrt((1 - u) * (1 + u));
}

double maxGalileanSpeed(const Motion& m, const Vec3& q) {
    const Vec3& w = m.angular_velocity;
    const double wn = norm(w);
    if (!(wn > 0)) return norm(m.velocity);
    const Vec3 k = w / wn;
    const double v_par = dot(m.velocity, k);
    const double v_perp = norm(m.velocity - k * v_par);
    const double rim = spinSpeed(m, q);
    return std::hypot(v_par, v_perp + rim);
}

double originProperTime(const Motion& m, double dt) {
    if (!(dt > 0) || !accelerated(m)) return dt;
    return originProperTimeAtLab(m, dt);
}

double horizonDistance(const Motion& m, const Vec3& q) {
    const double a = norm(m.acceleration);
    if (!(a > 0)) return INFINITY;
    return 1 / a + dot(q, m.acceleration / a);
}

WorldlineCrossing crossWorldline(const ViewSurface& view, const Motion& m, const Vec3& q) {
    WorldlineCrossing out;
    if (isUniform(m)) {
        out.event = cutRestWorldline(view, m, nowBase(view, m), q);
        out.s = properTimeAt(m, q, out.event.t);
        return out;
    }
    const double t_c = view.t_c;
    const Vec3& C = view.apex;
    auto finish = [&](double x) {
        const Event rel = relativeEvent(m, x, q, t_c, C).e;
        out.event = {t_c + rel.t, C + rel.x};
        out.s = x;
        return out;
    };
    // Step: the start, the closed-form crossing of q's worldline without the spin or the
    // acceleration. An accelerated point moves so until t0 (s = 0): a crossing there is exact.
    Motion plain = m;
    plain.angular_velocity = {0, 0, 0};
    plain.acceleration = {0, 0, 0};
    plain.keyed = nullptr;
    const Event plain_cut = cutRestWorldline(view, plain, nowBase(view, plain), q);
    double s = properTimeAt(plain, q, plain_cut.t);
    if (accelerated(m)) {
        if (!(s > 0)) {
            out.event = plain_cut;
            out.s = s;
            return out;
        }
        // After t0: the closed form (relativistic, past cone), polished below to the stated precision.
        double s_closed = 0;
        if (m.kinematics == Kinematics::Lorentz && view.kind == ViewKind::PastCone && hyperbolicCrossing(view, m, q, &s_closed))
            s = s_closed;
    }
    auto h = [&](double x, double* slope) {
        const Rel r = relativeEvent(m, x, q, t_c, C);
        const double value = sideOf(view.kind, r.e);
        if (slope) {
            const double dist = norm(r.e.x);
            *slope = -r.rate.dt - (view.kind == ViewKind::PastCone && dist > 0 ? dot(r.e.x, r.rate.dx) / dist : 0.0);
        }
        return value;
    };
    const double scale = std::max({std::fabs(s), std::fabs(t_c - m.t0), norm(m.origin - C), 1e-300});
    // Step: bracket the root, lo with h > 0 (inside the past cone), hi with h < 0. The first step is
    // the Newton step from the start (at least 4 ulps of the scale); each further one doubles.
    double slope = 0;
    const double h0 = h(s, &slope);
    if (h0 == 0) return finish(s);
    if (!std::isfinite(h0) || !(slope < 0)) {
        out.ok = false;
        return finish(s);
    }
    double lo = s, hi = s;
    double step = std::max(std::fabs(h0 / slope), 4 * kEps * scale);
    const double dir = h0 > 0 ? 1.0 : -1.0;
    bool bracketed = false;
    for (int i = 0; i < 64 && !bracketed; ++i) {
        const double next = s + dir * step;
        const double hn = h(next, nullptr);
        if (hn == 0) return finish(next);
        if ((hn > 0) == (h0 > 0)) {
            s = next;
            step *= 2;
            continue;
        }
        lo = dir > 0 ? s : next;
        hi = dir > 0 ? next : s;
        bracketed = true;
    }
    if (!bracketed) {
        out.ok = false;
        return finish(s);
    }
    // Step: Newton kept inside [lo, hi], bisection when it leaves the bracket or fails to halve it.
    double x = std::fabs(h0) < std::fabs(h(dir > 0 ? hi : lo, nullptr)) ? (dir > 0 ? lo : hi) : (dir > 0 ? hi : lo);
    double width = 2 * (hi - lo);  // the first step may be Newton's
    for (int i = 0; i < 200; ++i) {
        double dh = 0;
        const double hx = h(x, &dh);
        if (hx == 0) return finish(x);
        if (hx > 0) lo = x; else hi = x;
        const double newton = dh < 0 ? x - hx / dh : x;
        const double tol = 1e-15 * std::max(scale, std::fabs(x));
        if (std::fabs(newton - x) <= tol || hi - lo <= tol) return finish(newton > lo && newton < hi ? newton : x);
        double next = newton;
        if (!(next > lo && next < hi) || hi - lo > 0.5 * width) next = 0.5 * (lo + hi);
        width = hi - lo;
        x = next;
    }
    out.ok = false;
    return finish(x);
}

double worldlineDoppler(const Motion& m, ViewKind kind, const Vec3& apex, double s, const Vec3& q, const Vec3& x) {
    if (kind == ViewKind::Hyperplane) return 1.0;
    const WorldlineRate r = worldlineRate(m, s, q);
    const Vec3 d = apex - x;
    const double dist = norm(d);
    const double along = dist > 0 ? dot(d, r.dx) / dist : 0.0;
    return r.dtau / (r.dt - along);
}

}  // namespace mesh4d
