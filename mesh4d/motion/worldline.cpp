#include "mesh4d/motion/worldline.h"

#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/kinds.h"
#include "mesh4d/motion/local.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mesh4d {

using namespace motion_detail;

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

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

// q's event in the object's own frame, by kind (a uniform motion's is the spin's without a turn).
Local localEvent(const Motion& m, double s, const Vec3& q) {
    switch (kindOf(m)) {
        case MotionKind::Keyed:
            return keyedLocalEvent(m, s, q);
        case MotionKind::Hyperbolic:
            return rigidLocal(m, s, q);
        case MotionKind::Uniform:
        case MotionKind::Spin:
            break;
        default:  // a kind answered in its own file (kinds.h)
            return answersOf(m)->local(m, s, q);
    }
    return spinLocal(m, s, q);
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
        switch (kindOf(m)) {
            case MotionKind::Keyed: {  // carried in the lab along the path (keyed.h)
                const KeyedLocal l = keyedLocal(*m.keyed, s, q);
                r.e.x = (m.origin - apex) + l.y;
                r.rate.dx = l.dy;
                return r;
            }
            case MotionKind::Hyperbolic: {
                Vec3 disp, vel;
                originPath(m, s, &disp, &vel);
                r.e.x = (m.origin - apex) + (q + disp);
                r.rate.dx = vel;
                return r;
            }
            case MotionKind::Uniform:
            case MotionKind::Spin:
                break;
            default: {  // a kind answered in its own file (kinds.h): its lab carry
                const Local l = answersOf(m)->local(m, s, q);
                r.e.x = (m.origin - apex) + l.Y;
                r.rate.dx = l.dY;
                return r;
            }
        }
        const Local l = spinLocal(m, s, q);
        r.e.x = (m.origin - apex) + (l.Y + m.velocity * s);
        r.rate.dx = l.dY + m.velocity;
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

}  // namespace

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

double worldlineProperTime(const Motion& m, double s, const Vec3& q) {
    if (m.kinematics == Kinematics::Galilean) return s;
    switch (kindOf(m)) {
        case MotionKind::Uniform:
            return s;
        case MotionKind::Keyed:
            return keyedProperTime(*m.keyed, s, q);
        case MotionKind::Hyperbolic: {
            if (!(s > 0)) return s;
            const double a = norm(m.acceleration);
            return (1 + a * dot(q, m.acceleration / a)) * s;
        }
        case MotionKind::Spin:
            break;
        default:  // a kind answered in its own file (kinds.h)
            return answersOf(m)->proper_time(m, s, q);
    }
    const double u = spinSpeed(m, q);
    return s * std::sqrt((1 - u) * (1 + u));
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
    plain.kinds = KindParams{};
    const Event plain_cut = cutRestWorldline(view, plain, nowBase(view, plain), q);
    double s = properTimeAt(plain, q, plain_cut.t);
    if (kindOf(m) == MotionKind::Hyperbolic) {
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
