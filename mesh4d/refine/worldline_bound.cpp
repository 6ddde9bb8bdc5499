#include "worldline_bound.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/kinds.h"

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

// A keyframed path's segments whose s-range meets [s_lo, s_hi]: first and last index.
struct SegmentSpan {
    size_t first, last;
};
SegmentSpan segmentsIn(const KeyedMotion& k, double s_lo, double s_hi) {
    return {keyedSegment(k, s_lo), keyedSegment(k, s_hi)};
}

// A keyframed path's corners turned by each key's pose, p = rotate(turns[key], q) (keyed.h
// keyedSegmentTurned): every segment's rates, Lambda and kink start from them, so each is turned
// once per piece instead of once per use. Lazily per key; a per-thread store stamped per piece.
class TurnedCorners {
public:
    TurnedCorners(const KeyedMotion& k, const CornerCrossing c[3]) : k_(k), c_(c) {
        thread_local Store store;
        st_ = &store;
        if (st_->p.size() < k.s.size()) st_->p.resize(k.s.size()), st_->stamp.resize(k.s.size(), 0);
        if (++st_->piece == 0) std::fill(st_->stamp.begin(), st_->stamp.end(), 0), st_->piece = 1;
    }
    // The corners turned by segment j's first key (key 0 for j = 0).
    const Vec3* segment(size_t j) {
        const size_t key = j == 0 ? 0 : j - 1;
        if (st_->stamp[key] != st_->piece) {
            for (int i = 0; i < 3; ++i) st_->p[key][i] = rotate(k_.turns[key], c_[i].q);
            st_->stamp[key] = st_->piece;
        }
        return st_->p[key].data();
    }

private:
    struct Store {
        std::vector<std::array<Vec3, 3>> p;
        std::vector<uint64_t> stamp;
        uint64_t piece = 0;
    };
    const KeyedMotion& k_;
    const CornerCrossing* c_;
    Store* st_;
};

// Segment j of a keyframed path, as a carry in its own frame (the header): Y = P + u s + R(s) Q q.
// rho: the corners' largest distance from the turn axis after the key's turn (a distance to a line
// is convex, so no point of the triangle is farther).
double turnRho(const KeyedMotion& k, size_t j, const Vec3 p[3]) {
    double rho = 0;
    if (k.rate[j] > 0)
        for (int i = 0; i < 3; ++i) rho = std::max(rho, norm(p[i] - k.axis[j] * dot(k.axis[j], p[i])));
    return rho;
}
FrameRates segmentRates(const KeyedMotion& k, size_t j, double rho) {
    const double w = k.rate[j];
    return {1, norm(k.velocity[j]) + w * rho, 0, w * w * rho, 0, 1, 0, w};
}

// Not for a keyframed path (keyedRates below).
FrameRates frameRates(const Motion& m, const CornerCrossing c[3], double s_lo, double s_hi) {
    FrameRates r;
    if (const KindAnswers* k = answersOf(m)) {  // a kind answered in its own file (kinds.h)
        const Vec3 q[3] = {c[0].q, c[1].q, c[2].q};
        double o[8];
        k->rates(m, q, o);
        return {o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7]};
    }
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

namespace {

// (g - 1)(a.u) u = v (a.v) g^2 / (g + 1), as motion.h.
Vec3 stretch(const Vec3& v, double g, const Vec3& a) { return v * (dot(a, v) * (g * g / (g + 1.0))); }

// Lambda of segment j's rates at corner c's exact event (the header: its own segment's is c.lambda).
double segmentLambda(const Motion& m, const ViewSurface& view, const CornerCrossing& c, const Vec3& p, size_t j) {
    const KeyedLocal l = keyedSegmentTurned(*m.keyed, j, c.s, p);
    double dt = 1;
    Vec3 dx = l.dy;
    if (m.kinematics == Kinematics::Lorentz) {
        dt = m.gamma * (1 + dot(m.velocity, l.dy));
        dx = l.dy + stretch(m.velocity, m.gamma, l.dy) + m.velocity * m.gamma;
    }
    if (view.kind != ViewKind::PastCone) return dt;
    return dt + (c.rho > 0 ? dot(c.event.x - view.apex, dx) / c.rho : -norm(dx));
}

// The least of `least` and the Lambda of every segment of `span` at the three corners (a least
// value does not depend on the order taken, so a grown window adds only its new segments).
double keyedLambda(const Motion& m, const ViewSurface& view, const CornerCrossing c[3], TurnedCorners& turned,
                   const SegmentSpan& span, double least) {
    double out = least;
    for (size_t j = span.first; j <= span.last; ++j) {
        const Vec3* p = turned.segment(j);
        for (int i = 0; i < 3; ++i) out = std::min(out, segmentLambda(m, view, c[i], p[i], j));
    }
    return out;
}

// A keyframed path's rates over the segments of `span` (header), taken into *f and *first as
// largest values (so a grown window adds only its new segments): the frame rates and the lab rate
// (t_s, x_s): per segment the boost of (1, u) exactly plus the turn's part (0, w x R Q q) by its
// magnitude w rho, so a segment at rest in the lab has |x_s| = 0 but for its turn (its .c is not used).
void keyedRates(const Motion& m, TurnedCorners& turned, const SegmentSpan& span, FrameRates* f, LabPair* first) {
    const double nu = m.kinematics == Kinematics::Lorentz ? m.beta : 0.0;  // the c part at its worst
    const KeyedMotion& k = *m.keyed;
    const bool lorentz = m.kinematics == Kinematics::Lorentz;
    for (size_t j = span.first; j <= span.last; ++j) {
        const double rho = turnRho(k, j, turned.segment(j));
        f->takeMax(segmentRates(k, j, rho));
        const Vec3& u = k.velocity[j];
        const double tt = lorentz ? m.gamma * (1 + dot(m.velocity, u)) : 1.0;
        const double xt = norm(lorentz ? u + stretch(m.velocity, m.gamma, u) + m.velocity * m.gamma : u);
        const LabPair turn = toLab(m, nu, 0, k.rate[j] * rho);
        first->t = std::max(first->t, tt + turn.t);
        first->x = std::max(first->x, xt + turn.x);
        first->c = std::max(first->c, tt + xt + turn.c);
    }
}

// The corners' lab events at key i's time s_i, relative to (0, 0) as worldlineEvent gives them
// (worldline.cpp relativeEvent: the pose y at s_i boosted with V about (t0, X0), or carried), and
// their rates on the segment after the key (dyb), from one keyedSegmentTurned call per corner.
void keyEvents(const Motion& m, size_t i, TurnedCorners& turned, Event ev[3], Vec3 dyb[3]) {
    const KeyedMotion& k = *m.keyed;
    const double s = k.s[i];
    const Vec3* p = turned.segment(i + 1);
    for (int q = 0; q < 3; ++q) {
        const KeyedLocal l = keyedSegmentTurned(k, i + 1, s, p[q]);
        dyb[q] = l.dy;
        if (m.kinematics == Kinematics::Galilean) {
            ev[q].t = m.t0 + s;
            ev[q].x = m.origin + l.y;
        } else {
            const double g = m.gamma;
            ev[q].t = m.t0 + g * (s + dot(m.velocity, l.y));
            ev[q].x = m.origin + (l.y + stretch(m.velocity, g, l.y) + m.velocity * (g * s));
        }
    }
}

// Whether the curve sigma = s_i may meet the triangle (header): the sign of
// g(s_i, q) = t_c - t - |x - C| (t_c - t on a hyperplane) at the corners' events at s_i, e. t and x are
// affine in q at a fixed s, so g is concave (affine on a hyperplane): corners all inside the cone
// (g > 0) keep the whole triangle inside; corners all outside keep it outside when one corner's
// tangent plane, g_a - (t_b - t_a) - n_a.(x_b - x_a) at the corners b, lies below 0 (a concave
// function lies below its tangent planes; affine: the corners decide). Near 0 counts as crossing.
bool keyMayCross(const ViewSurface& view, const Event e[3]) {
    const bool cone = view.kind == ViewKind::PastCone;
    double g[3], scale = 1;
    for (int k = 0; k < 3; ++k) {
        g[k] = view.t_c - e[k].t - (cone ? norm(e[k].x - view.apex) : 0.0);
        scale = std::max(scale, std::fabs(view.t_c - e[k].t));
    }
    const double tiny = 1e-12 * scale;
    if (g[0] > tiny && g[1] > tiny && g[2] > tiny) return false;
    if (!(g[0] < -tiny && g[1] < -tiny && g[2] < -tiny)) return true;
    if (!cone) return false;
    for (int a = 0; a < 3; ++a) {
        const Vec3 d = e[a].x - view.apex;
        const double r = norm(d);
        if (!(r > 0)) continue;
        bool below = true;
        for (int b = 0; b < 3 && below; ++b)
            below = g[a] - (e[b].t - e[a].t) - dot(d, e[b].x - e[a].x) / r < -tiny;
        if (below) return false;
    }
    return true;
}

// The lab rates (dt/ds, dx/ds) of a key segment's velocity dY in the key frame F_V, for the two
// kink terms below: boosted with `velocity` (Lorentz), as they are for the Galilean carry.
struct KeyLab {
    bool lorentz;
    double g, b;
    Vec3 V;
    explicit KeyLab(const Motion& m)
        : lorentz(m.kinematics == Kinematics::Lorentz), g(lorentz ? m.gamma : 1.0), b(lorentz ? m.beta : 0.0),
          V(lorentz ? m.velocity : Vec3{0, 0, 0}) {}
    double t(const Vec3& dY) const { return lorentz ? g * (1 + dot(V, dY)) : 1.0; }
    Vec3 x(const Vec3& dY) const { return lorentz ? dY + stretch(V, g, dY) + V * g : dY; }
};

// The kink term of key i over the triangle on the cone (header), light-seconds: the lesser of
// m_i j_i d / sqrt(3) (j(q) = |c(q)| D(q) at q's event at s_i (ev), exact at the corners, carried over
// the triangle by its Lipschitz bound) and the crossing-weighted D_hi (3 a b / (a + b) + 2 eps + 2 e)
// (a, b the corners' largest g_i and -g_i, e = g^2 d^2 / (2 rho_lo), eps = e / 3). INFINITY when the
// carried bounds do not close (the triangle may reach the camera or a Lambda 0).
double keyKink(const Motion& m, const ViewSurface& view, double shear_speed, size_t i, const Event ev[3],
               const Vec3 dyb[3], TurnedCorners& turned, double d) {
    const KeyedMotion& k = *m.keyed;
    const bool cone = view.kind == ViewKind::PastCone;
    const KeyLab lab(m);
    const double g = lab.g, b = lab.b;
    const Vec3 V = lab.V;
    const double s = k.s[i], w = std::max(k.rate[i], k.rate[i + 1]);
    const Vec3* pa = turned.segment(i);
    double rho_min = INFINITY, j_min = INFINITY, D_min = INFINITY, D_max = 0, c_max = 0, x_max = 0, t_max = 0,
           lam_min = INFINITY, above = 0, below = 0;
    for (int q = 0; q < 3; ++q) {
        const Event& e = ev[q];
        Vec3 n{0, 0, 0};
        if (cone) {
            const Vec3 r = e.x - view.apex;
            const double rho = norm(r);
            if (!(rho > 0)) return INFINITY;
            rho_min = std::min(rho_min, rho);
            n = r / rho;
            const double gk = view.t_c - e.t - rho;  // g_i at the corner (exact)
            above = std::max(above, gk);
            below = std::max(below, -gk);
        }
        const Vec3 dya = keyedSegmentTurned(k, i, s, pa[q]).dy;
        const double ta = lab.t(dya), tb = lab.t(dyb[q]);
        const Vec3 xa = lab.x(dya), xb = lab.x(dyb[q]);
        const double la = ta + dot(n, xa), lb = tb + dot(n, xb);
        if (!(la > 0) || !(lb > 0)) return INFINITY;
        const double D = norm(xb / lb - xa / la) + shear_speed * std::fabs(tb / lb - ta / la);
        // c = t_q + x_q^T n, up to the key's turn Q_i (a rotation): g V + n + g^2/(g + 1) (V.n) V
        // (Lorentz; its n-part is n itself for the carry), g V on a hyperplane (0 for the carry).
        const Vec3 cv = cone ? V * g + n + V * (g * g / (g + 1) * dot(V, n)) : V * g;
        j_min = std::min(j_min, norm(cv) * D);
        D_min = std::min(D_min, D);
        D_max = std::max(D_max, D);
        c_max = std::max(c_max, norm(cv));
        x_max = std::max({x_max, norm(xa), norm(xb)});
        t_max = std::max({t_max, ta, tb});
        lam_min = std::min({lam_min, la, lb});
    }
    // Over the triangle: |x_q| <= g, so |x - C| >= rho_min - g d and n turns at most g / rho_lo per
    // unit length; c's n-part at most g times that; (t_s, x_s) move at most (g b w, g w) (the turn's
    // spread, boosted); Lambda = t_s + n.x_s then at most L_lam; D's two quotients x_s / Lambda at
    // most g w / lam_lo + X L_lam / lam_lo^2 each (t_s / Lambda likewise).
    const double rho_lo = cone ? rho_min - g * d : INFINITY;
    if (!(rho_lo > 0)) return INFINITY;
    const double dn = cone ? g / rho_lo : 0.0;
    const double X = x_max + g * w * d, Tm = t_max + g * b * w * d;
    const double L_lam = g * b * w + g * w + X * dn;
    const double lam_lo = lam_min - L_lam * d;
    if (!(lam_lo > 0)) return INFINITY;
    const double L_D = 2 * (g * w / lam_lo + X * L_lam / (lam_lo * lam_lo)) +
                       shear_speed * 2 * (g * b * w / lam_lo + Tm * L_lam / (lam_lo * lam_lo));
    const double L_c = g * dn;
    const double j = j_min + (L_c * (D_max + L_D * d) + (c_max + L_c * d) * L_D) * d;
    const double by_length = 2 * j * d / std::sqrt(3.0);
    // Weighted by where the lines from a point to the corners can cross Gamma_i (header): g_i is
    // concave with curvature at most g^2 / rho_lo, so each crossing's remainder is at most
    // D (|g_i(corner)| + e) and g_i within eps above its affine interpolant.
    const double e = cone ? g * g * d * d / (2 * rho_lo) : 0.0;
    const double straddle = above + below > 0 ? above * below / (above + below) : 0.0;
    const double by_crossing = (D_min + L_D * d) * (3 * straddle + 2 * e / 3 + 2 * e);
    const double term = std::min(by_length, by_crossing);
    return term == term ? term : INFINITY;
}

// The kink term of key i over the triangle on a hyperplane (header, "On a hyperplane"): with
// g_k = t_c - t(s_i, q_k) at the corners' events ev at s_i (g is affine in q there), a = max(g_k, 0), b = max(-g_k, 0)
// at their largest, the term is D_hi a b / (a + b), D_hi = the least corner D plus L_D d (D's
// Lipschitz bound of keyKink above, no n). 0 when the corners do not straddle the plane; INFINITY
// when the carried bounds do not close.
double keyKinkOnPlane(const Motion& m, const ViewSurface& view, size_t i, const Event ev[3],
                      const Vec3 dyb[3], TurnedCorners& turned, double d) {
    const KeyedMotion& k = *m.keyed;
    const KeyLab lab(m);
    const double g = lab.g, b = lab.b;
    const double s = k.s[i], w = std::max(k.rate[i], k.rate[i + 1]);
    const Vec3* pa = turned.segment(i);
    double above = 0, below = 0, D_min = INFINITY, x_max = 0, lam_min = INFINITY;
    for (int q = 0; q < 3; ++q) {
        const double gk = view.t_c - ev[q].t;
        above = std::max(above, gk);
        below = std::max(below, -gk);
        const Vec3 dya = keyedSegmentTurned(k, i, s, pa[q]).dy;
        const double ta = lab.t(dya), tb = lab.t(dyb[q]);
        const Vec3 xa = lab.x(dya), xb = lab.x(dyb[q]);
        if (!(ta > 0) || !(tb > 0)) return INFINITY;
        D_min = std::min(D_min, norm(xb / tb - xa / ta));  // the shear's part: |t_s / Lambda| = 1 on both sides
        x_max = std::max({x_max, norm(xa), norm(xb)});
        lam_min = std::min({lam_min, ta, tb});
    }
    if (!(above > 0) || !(below > 0)) return 0;  // no straddle: no crossing on any segment p -> q_l
    const double X = x_max + g * w * d;
    const double L_lam = g * b * w;
    const double lam_lo = lam_min - L_lam * d;
    if (!(lam_lo > 0)) return INFINITY;
    const double L_D = 2 * (g * w / lam_lo + X * L_lam / (lam_lo * lam_lo));
    const double term = (D_min + L_D * d) * above * below / (above + below);
    return term == term ? term : INFINITY;
}

// The Born-rigid acceleration seen on a past cone, relativistic (header, "A Born-rigid acceleration
// on the cone"): everything in the start frame, where the worldlines are hyperbolae about one
// event, then the second derivative boosted into the lab. No bootstrap: sigma's Lipschitz bound
// G, the distance rho and Lambda-hat follow from the corners without a guess.
PieceBound rigidBound(const Motion& m, const ViewSurface& view, double shear_speed, const CornerCrossing c[3],
                      double d) {
    const PieceBound none;
    const double a = norm(m.acceleration);
    const Vec3 k = m.acceleration / a;
    const double g = m.gamma;
    const Vec3& V = m.velocity;
    // Start-frame event of a lab event, about (t0, X0) (the inverse of worldline.cpp's boost).
    auto startFrame = [&](double t, const Vec3& x, double* T) {
        const double dt = t - m.t0;
        const Vec3 dx = x - m.origin;
        *T = g * (dt - dot(V, dx));
        return dx + stretch(V, g, dx) - V * (g * dt);
    };
    double Tc;
    const Vec3 P = startFrame(view.t_c, view.apex, &Tc);
    double xi_lo = INFINITY, rho_c = INFINITY, lhat_c = INFINITY, s_lo = INFINITY, s_hi = -INFINITY;
    for (int i = 0; i < 3; ++i) {
        double T;
        const Vec3 r = startFrame(c[i].event.t, c[i].event.x, &T) - P;
        const double rho = norm(r);
        if (!(rho > 0)) return none;
        xi_lo = std::min(xi_lo, horizonDistance(m, c[i].q));
        rho_c = std::min(rho_c, rho);
        const double s = c[i].s;
        lhat_c = std::min(lhat_c, s > 0 ? std::cosh(a * s) + dot(k, r) / rho * std::sinh(a * s) : 1.0);
        s_lo = std::min(s_lo, s);
        s_hi = std::max(s_hi, s);
    }
    if (!(xi_lo > 0) || !(lhat_c > 0)) return none;
    // sigma is Lipschitz with G = 1 / (xi a) after t0 (|c| = Lambda-hat) and 1 before: its window.
    const double G = std::max(1.0, 1 / (xi_lo * a));
    const double w_lo = s_lo - G * d, w_hi = s_hi + G * d;
    const double S = std::max(w_hi, 0.0);
    const double sh = std::sinh(a * S), ch = std::cosh(a * S), e = std::exp(a * S);
    // rho and Lambda-hat over the triangle from a bound xdot on |x.| (Gronwall along a segment from a
    // corner: Lambda-hat' >= -Lambda-hat / xi - sh |x.| / rho); false when they do not close.
    double rho_min = 0, lhat = 0;
    auto carry = [&](double xdot) {
        rho_min = (rho_c - xdot * d) * (1 - 1e-9);
        if (!(rho_min > 0)) return false;  // the triangle may reach the camera (a smaller one may not)
        const double C = sh * xdot / rho_min * xi_lo;  // C / kappa, kappa = 1 / xi_lo
        lhat = (lhat_c + C) * std::exp(-d / xi_lo) - C;
        return lhat > 0;
    };
    // |x.| <= e^(a S) everywhere, and <= 1 + (e^(a S) - 1) / Lambda-hat: first the one, then the other
    // with the Lambda-hat it gave; when the first does not close, the second with a guess
    // Lambda-hat >= lhat_c / 2, accepted when the carry returns more (the bootstrap of the header).
    double xdot = e;
    if (carry(xdot)) {
        xdot = std::min(e, 1 + (e - 1) / lhat);
        if (!carry(xdot)) return none;
    } else {
        const double guess = 0.5 * lhat_c;
        xdot = std::min(e, 1 + (e - 1) / guess);
        if (!carry(xdot) || !(lhat > guess)) return none;
    }
    const double Pr = xdot * xdot / rho_min;  // P / rho
    double X = 0, T = 0;  // |x..| and |t..| per |u|^2 in the start frame
    if (w_hi > 0) X = (1 / xi_lo + sh * Pr) / lhat, T = (1 / xi_lo + ch * Pr) / lhat;
    if (w_lo <= 0) T = std::max(T, Pr);  // at rest before t0: x.. = 0, t.. = -P / rho
    // Into the lab: x.. = X k boosted plus g V t.., t.. boosted.
    const double kx = norm(k + stretch(V, g, k));
    const double K = X * kx + g * norm(V) * T + shear_speed * g * (T + std::fabs(dot(V, k)) * X);
    PieceBound out;
    out.K = K == K ? K : INFINITY;
    return out;
}

}  // namespace

PieceBound pieceBound(const Motion& m, const ViewSurface& view, double shear_speed, const CornerCrossing c[3]) {
    const PieceBound none;
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
    if (!(lam_c > 0) || (cone && !(rho_c > 0))) return none;
    if (cone && accelerated(m) && m.kinematics == Kinematics::Lorentz) return rigidBound(m, view, shear_speed, c, d);
    if (m.keyed && !(std::isfinite(s_lo) && std::isfinite(s_hi))) return none;  // no window of segments
    const bool windowed = accelerated(m) || m.keyed;
    // v.n at the corners (the Doppler factor of the boost, header): the guess nu starts a hundredth
    // of the way from their largest to b.
    const double b = m.kinematics == Kinematics::Lorentz ? m.beta : 0.0;
    double nu_c = -b;
    if (cone)
        for (int i = 0; i < 3; ++i) nu_c = std::max(nu_c, dot(m.velocity, c[i].event.x - view.apex) / c[i].rho);
    double nu = std::min(b, nu_c + 0.01 * (b - nu_c));
    double spread = std::max(s_hi - s_lo, 1e-300);  // the window's margin about the corners' s
    // A keyframed path's rates depend on the window only through the segments it meets: taken
    // here and again when those change.
    SegmentSpan held{1, 0};
    FrameRates keyed_f;
    LabPair keyed_s1{0, 0, 0};
    std::optional<TurnedCorners> turned;
    if (m.keyed) {
        turned.emplace(*m.keyed, c);
        held = segmentsIn(*m.keyed, s_lo - spread, s_hi + spread);
        lam_c = keyedLambda(m, view, c, *turned, held, INFINITY);
        if (!(lam_c > 0)) return none;
        keyedRates(m, *turned, held, &keyed_f, &keyed_s1);
    }
    if (!(lam_c > 0)) return none;
    double lam_min = 0.9 * lam_c;
    for (int iter = 0; iter < 24; ++iter) {
        FrameRates f;
        LabPair s1;
        if (m.keyed) {  // every segment the window meets, at every corner (header)
            const SegmentSpan span = segmentsIn(*m.keyed, s_lo - spread, s_hi + spread);
            if (span.first != held.first || span.last != held.last) {
                // The window only grows (spread doubles past G d): its new segments at each end.
                const SegmentSpan ends[2] = {{span.first, held.first - 1}, {held.last + 1, span.last}};
                if (span.first <= held.first && span.last >= held.last) {
                    for (const SegmentSpan& e : ends)
                        if (e.first <= e.last && e.last != size_t(-1)) {
                            lam_c = keyedLambda(m, view, c, *turned, e, lam_c);
                            keyedRates(m, *turned, e, &keyed_f, &keyed_s1);
                        }
                } else {
                    keyed_f = FrameRates{};
                    keyed_s1 = LabPair{0, 0, 0};
                    lam_c = keyedLambda(m, view, c, *turned, span, INFINITY);
                    keyedRates(m, *turned, span, &keyed_f, &keyed_s1);
                }
                held = span;
            }
            if (!(lam_c > 0)) return none;
            f = keyed_f;
            s1 = keyed_s1;
        } else {
            f = frameRates(m, c, s_lo - spread, s_hi + spread);
            s1 = toLab(m, nu, f.Ts, f.Ys);
        }
        const LabPair ss = toLab(m, nu, f.Tss, f.Yss), q1 = toLab(m, nu, f.Tq, f.Yq), sq = toLab(m, nu, f.Tsq, f.Ysq);
        const double cq = cone ? q1.c : q1.t;
        const double G = cq / lam_min;  // |sigma'| per |u|
        const double LF = s1.x * G + q1.x;
        double rho_min = 0, L_lambda = 0;
        bool nu_holds = true;
        if (cone) {
            const double r = rho_c - LF * d;
            if (!(r > 0)) return none;  // the triangle may reach the camera (a smaller one may not)
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
            PieceBound out;
            out.K = K == K ? K : INFINITY;
            if (m.keyed) {
                // The kinks (header): on the cone m_i j_i d / sqrt(3) for each key in the window
                // whose curve may meet the triangle; on a hyperplane the straddle term of each key.
                const SegmentSpan span = segmentsIn(*m.keyed, s_lo - spread, s_hi + spread);
                double kinks = 0, plane = 0;
                for (size_t i = span.first; i < span.last; ++i) {
                    Event ev[3];  // the corners' events at the key's time, shared by the tests below
                    Vec3 dyb[3];  // and their rates on the segment after it
                    keyEvents(m, i, *turned, ev, dyb);
                    if (!cone) plane += keyKinkOnPlane(m, view, i, ev, dyb, *turned, d);
                    else if (keyMayCross(view, ev)) kinks += keyKink(m, view, shear_speed, i, ev, dyb, *turned, d);
                }
                const double kink = kinks + plane;
                out.kink = kink == kink ? kink : INFINITY;
            }
            return out;
        }
        if (!lam_holds) {  // toward the fixed point lam_min = lam_c - L_lambda(lam_min) d
            const double next = lam_c - 1.05 * L_lambda * d;
            lam_min = next > 0.5 * lam_min ? next : 0.5 * lam_min;
        }
        if (!window_holds) spread = 2 * G * d;
        if (!(lam_min > 0) || !std::isfinite(spread)) break;
    }
    return none;
}

}  // namespace mesh4d
