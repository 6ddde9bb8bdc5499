#include "worldline_bound.h"

#include <algorithm>
#include <cmath>

namespace mesh4d {

namespace {

// Magnitude bounds of a worldline's rates in the object's own frame (the header's list): time part
// T and space part Y of d/ds, d2/ds2, d/dq (per |u|) and d2/ds dq (per |u|).
struct FrameRates {
    double Ts = 0, Ys = 0, Tss = 0, Yss = 0, Tq = 0, Yq = 0, Tsq = 0, Ysq = 0;
    void takeMax(const FrameRates& o) {
        Ts = std::max(Ts, o.Ts), Ys = std::max(Ys, o.Ys), Tss = std::max(Tss, o.Tss), Yss = std::max(Yss, o.Yss);
        Tq = std::max(Tq, o.Tq), Yq = std::max(Yq, o.Yq), Tsq = std::max(Tsq, o.Tsq), Ysq = std::max(Ysq, o.Ysq);
    }
};

bool accelerated(const Motion& m) { return norm(m.acceleration) > 0; }

FrameRates frameRates(const Motion& m, const CornerCrossing c[3], double s_lo, double s_hi) {
    FrameRates r;
    const bool lorentz = m.kinematics == Kinematics::Lorentz;
    if (!accelerated(m)) {  // spin
        const double wn = norm(m.angular_velocity);
        double rim = 0, carried = 0;
        for (int i = 0; i < 3; ++i) {
            rim = std::max(rim, spinSpeed(m, c[i].q));
            if (!lorentz) carried = std::max(carried, maxGalileanSpeed(m, c[i].q));
        }
        r.Ts = 1;
        r.Ys = lorentz ? rim : carried;
        r.Yss = wn * rim;
        r.Yq = 1;
        r.Ysq = wn;
        return r;
    }
    const double a = norm(m.acceleration);
    const FrameRates before{1, lorentz ? 0.0 : m.beta, 0, 0, 0, 1, 0, 0};  // uniform, s <= 0
    if (s_lo <= 0) r = before;
    if (!(s_hi > 0)) return r;
    FrameRates after;
    if (lorentz) {
        double xi_hi = 0;
        for (int i = 0; i < 3; ++i) xi_hi = std::max(xi_hi, horizonDistance(m, c[i].q));
        const double ch = std::cosh(a * s_hi), sh = std::sinh(a * s_hi);
        after = {xi_hi * a * ch, xi_hi * a * sh, xi_hi * a * a * sh, xi_hi * a * a * ch, sh, ch, a * ch, a * sh};
    } else {
        const double th = std::tanh(a * originProperTime(m, s_hi));
        const double speed = (m.beta + th) / (1 + m.beta * th);
        after = {1, speed, 0, a, 0, 1, 0, 0};
    }
    r.takeMax(after);
    return r;
}

// The lab bounds: time part, space part and the cone's combination t + n.x of one frame pair, for
// directions n with v.n <= nu (the boost's Doppler factor for them is at most g (1 + nu)).
struct LabPair {
    double t, x, c;
};
LabPair toLab(const Motion& m, double nu, double T, double Y) {
    if (m.kinematics == Kinematics::Galilean) return {T, Y, T + Y};
    const double g = m.gamma, b = m.beta;
    return {g * (T + b * Y), g * (Y + b * T), g * (1 + nu) * (T + Y)};
}

}  // namespace

CornerCrossing cornerCrossing(const ViewSurface& view, const Motion& m, const Vec3& q, bool* ok) {
    CornerCrossing c;
    c.q = q;
    const WorldlineCrossing w = crossWorldline(view, m, q);
    *ok = w.ok;
    c.event = w.event;
    c.s = w.s;
    const WorldlineRate rate = worldlineRate(m, w.s, q);
    if (view.kind == ViewKind::PastCone) {
        const Vec3 d = w.event.x - view.apex;
        c.rho = norm(d);
        c.lambda = rate.dt + (c.rho > 0 ? dot(d, rate.dx) / c.rho : -norm(rate.dx));
    } else {
        c.lambda = rate.dt;
    }
    return c;
}

double secondDerivativeBound(const Motion& m, const ViewSurface& view, double shear_speed, const CornerCrossing c[3]) {
    const bool cone = view.kind == ViewKind::PastCone;
    double d2 = 0;
    for (int i = 0; i < 3; ++i) d2 = std::max(d2, norm2(c[(i + 1) % 3].q - c[i].q));
    const double d = std::sqrt(d2);
    double lam_c = INFINITY, rho_c = INFINITY, s_lo = INFINITY, s_hi = -INFINITY;
    for (int i = 0; i < 3; ++i) {
        lam_c = std::min(lam_c, c[i].lambda);
        rho_c = std::min(rho_c, c[i].rho);
        s_lo = std::min(s_lo, c[i].s);
        s_hi = std::max(s_hi, c[i].s);
    }
    if (!(lam_c > 0) || (cone && !(rho_c > 0))) return INFINITY;
    const bool windowed = accelerated(m);
    // v.n at the corners (the Doppler factor of the boost, header): the guess nu starts a hundredth
    // of the way from their largest to b.
    const double b = m.kinematics == Kinematics::Lorentz ? m.beta : 0.0;
    double nu_c = -b;
    if (cone)
        for (int i = 0; i < 3; ++i) nu_c = std::max(nu_c, dot(m.velocity, c[i].event.x - view.apex) / c[i].rho);
    double nu = std::min(b, nu_c + 0.01 * (b - nu_c));
    double lam_min = 0.9 * lam_c;
    double spread = std::max(s_hi - s_lo, 1e-300);  // the window's margin about the corners' s
    for (int iter = 0; iter < 24; ++iter) {
        const FrameRates f = frameRates(m, c, s_lo - spread, s_hi + spread);
        const LabPair s1 = toLab(m, nu, f.Ts, f.Ys), ss = toLab(m, nu, f.Tss, f.Yss), q1 = toLab(m, nu, f.Tq, f.Yq),
                      sq = toLab(m, nu, f.Tsq, f.Ysq);
        const double cq = cone ? q1.c : q1.t;
        const double G = cq / lam_min;  // |sigma'| per |u|
        const double LF = s1.x * G + q1.x;
        double rho_min = 0, L_lambda = 0;
        bool nu_holds = true;
        if (cone) {
            const double r = rho_c - LF * d;
            if (!(r > 0)) return INFINITY;  // the triangle may reach the camera (a smaller one may not)
            rho_min = r * (1 - 1e-9);
            L_lambda = ss.c * G + sq.c + s1.x * LF / rho_min;
            // n turns by at most L_F d / rho_min over the triangle.
            nu_holds = nu >= b || nu_c + b * LF * d / rho_min < nu;
            if (!nu_holds) nu = std::min(b, nu_c + 2 * b * LF * d / rho_min);
        } else {
            L_lambda = ss.t * G + sq.t;
        }
        const bool lam_holds = lam_c - L_lambda * d > lam_min;
        const bool window_holds = !windowed || G * d < spread;
        if (lam_holds && window_holds && nu_holds) {
            const double css = cone ? ss.c : ss.t, csq = cone ? sq.c : sq.t;
            const double S2 = (css * G * G + 2 * csq * G + (cone ? LF * LF / rho_min : 0.0)) / lam_min;
            const double xdd = s1.x * S2 + ss.x * G * G + 2 * sq.x * G;
            const double tdd = s1.t * S2 + ss.t * G * G + 2 * sq.t * G;
            const double K = xdd + shear_speed * tdd;
            return K == K ? K : INFINITY;
        }
        if (!lam_holds) {  // toward the fixed point lam_min = lam_c - L_lambda(lam_min) d
            const double next = lam_c - 1.05 * L_lambda * d;
            lam_min = next > 0.5 * lam_min ? next : 0.5 * lam_min;
        }
        if (!window_holds) spread = 2 * G * d;
        if (!(lam_min > 0) || !std::isfinite(spread)) break;
    }
    return INFINITY;
}

}  // namespace mesh4d
