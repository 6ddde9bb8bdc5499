#include "mesh4d/motion/keyed.h"

#include <algorithm>
#include <cmath>

#include "mesh4d/elliptic.h"
#include "mesh4d/motion/motion.h"

namespace mesh4d {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// Rodrigues' turn of p about unit axis k by angle a (1 - cos a = 2 sin^2(a/2): no cancellation).
// With the angle's cosine, sine and half-angle sine given (ca, sa, h).
Vec3 turnWith(const Vec3& k, double ca, double sa, double h, const Vec3& p) {
    return p * ca + cross(k, p) * sa + k * (dot(k, p) * 2 * h * h);
}
Vec3 turnAbout(const Vec3& k, double a, const Vec3& p) { return turnWith(k, std::cos(a), std::sin(a), std::sin(0.5 * a), p); }

// (g - 1)(a.u) u = v (a.v) g^2 / (g + 1), as motion.h.
Vec3 stretch(const Vec3& v, double g, const Vec3& a) { return v * (dot(a, v) * (g * g / (g + 1.0))); }

// The segment holding s (the vectors sized n + 1 of KeyedMotion) and its base key.
struct Where {
    size_t segment;
    size_t key;
};
Where locate(const KeyedMotion& k, double s) {
    const size_t j = size_t(std::upper_bound(k.s.begin(), k.s.end(), s) - k.s.begin());
    return {j, j == 0 ? 0 : j - 1};
}

// A point's speed over a segment as phi = rate (s - s_key) runs: |dY|^2 = A + B cos(phi - phi0)
// (the header), B >= 0.
struct SpeedWave {
    double A = 0, B = 0, phi0 = 0;
};
SpeedWave speedWave(const KeyedMotion& k, size_t j, const Vec3& p) {
    SpeedWave w;
    const Vec3& u = k.velocity[j];
    w.A = norm2(u);
    const double rate = k.rate[j];
    if (!(rate > 0)) return w;
    const Vec3& a = k.axis[j];
    const Vec3 perp = p - a * dot(a, p);
    const double rho = norm(perp);
    if (!(rho > 0)) return w;
    const Vec3 e1 = cross(a, perp) / rho, e2 = cross(a, e1);
    const double c1 = dot(u, e1), c2 = dot(u, e2);
    w.A += rate * rate * rho * rho;
    w.B = 2 * rate * rho * std::hypot(c1, c2);
    w.phi0 = std::atan2(c2, c1);
    return w;
}

// The integral of sqrt(1 - A - B cos(phi - phi0)) d phi over [pa, pb]: with psi = phi - phi0 - pi,
// 1 - A + B cos psi = (alpha + B)(1 - k^2 sin^2(psi/2)), alpha = 1 - A, k^2 = 2B / (alpha + B), whose
// integral is 2 sqrt(alpha + B) E(psi/2, k) (E the incomplete elliptic integral of the 2nd kind).
double arcClock(const SpeedWave& w, double pa, double pb) {
    const double alpha = 1 - w.A;
    const double top = alpha + w.B;
    if (!(top > 0)) return 0;
    const double kk = std::min(1.0, std::sqrt(2 * w.B / top));
    const double shift = w.phi0 + 3.14159265358979323846;
    return 2 * std::sqrt(top) * (ellipticE(kk, 0.5 * (pb - shift)) - ellipticE(kk, 0.5 * (pa - shift)));
}

// q's clock over [a, b] (absolute s) within segment j.
double segmentClock(const KeyedMotion& k, size_t j, const Vec3& q, double a, double b) {
    const size_t key = j == 0 ? 0 : j - 1;
    const SpeedWave w = speedWave(k, j, rotate(k.turns[key], q));
    if (w.B == 0) {
        const double speed = std::sqrt(w.A);
        return (b - a) * std::sqrt(std::max(0.0, (1 - speed) * (1 + speed)));
    }
    const double rate = k.rate[j];
    return arcClock(w, rate * (a - k.s[key]), rate * (b - k.s[key])) / rate;
}

}  // namespace

Quat multiply(const Quat& a, const Quat& b) {
    return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + b.w * a.x + a.y * b.z - a.z * b.y,
            a.w * b.y + b.w * a.y + a.z * b.x - a.x * b.z, a.w * b.z + b.w * a.z + a.x * b.y - a.y * b.x};
}

Quat conjugate(const Quat& a) { return {a.w, -a.x, -a.y, -a.z}; }

Quat slerp(const Quat& a, const Quat& b, double f) {
    Quat d = multiply(b, conjugate(a));
    if (d.w < 0) d = {-d.w, -d.x, -d.y, -d.z};
    const Vec3 v{d.x, d.y, d.z};
    const double vn = norm(v);
    if (!(vn > 0)) return a;
    const double half = f * std::atan2(vn, d.w);
    const Vec3 k = v * (std::sin(half) / vn);
    return multiply({std::cos(half), k.x, k.y, k.z}, a);
}

Vec3 rotate(const Quat& r, const Vec3& v) {
    const Vec3 u{r.x, r.y, r.z};
    const Vec3 t = cross(u, v) * 2.0;
    return v + t * r.w + cross(u, t);
}

Vec3 meanVelocity(const KeyPath& path) {
    const size_t n = path.times.size();
    if (n < 2) return {0, 0, 0};
    return (path.positions[n - 1] - path.positions[0]) / (path.times[n - 1] - path.times[0]);
}

Vec3 keyedCentreAt(const KeyPath& path, double t) {
    const size_t n = path.times.size();
    if (n == 0) return {0, 0, 0};
    if (!(t > path.times[0])) return path.positions[0];
    if (!(t < path.times[n - 1])) return path.positions[n - 1];
    const size_t j = size_t(std::upper_bound(path.times.begin(), path.times.end(), t) - path.times.begin());
    const double f = (t - path.times[j - 1]) / (path.times[j] - path.times[j - 1]);
    return path.positions[j - 1] + (path.positions[j] - path.positions[j - 1]) * f;
}

std::shared_ptr<const KeyedMotion> makeKeyedMotion(const KeyPath& path, bool lorentz, double t0, const Vec3& origin,
                                                   const Vec3& frame_velocity) {
    auto k = std::make_shared<KeyedMotion>();
    k->lorentz = lorentz;
    k->t0 = t0;
    k->origin = origin;
    const size_t n = path.times.size();
    const Vec3 V = lorentz ? frame_velocity : Vec3{0, 0, 0};
    const double b = norm(V);
    const double g = lorentz ? 1 / std::sqrt((1 - b) * (1 + b)) : 1.0;
    k->frame_velocity = V;
    k->gamma = g;
    // Step: each key event in the object's own frame (boosted into F_V about (t0, origin)).
    for (size_t i = 0; i < n; ++i) {
        const double dt = path.times[i] - t0;
        const Vec3 dx = path.positions[i] - origin;
        k->s.push_back(lorentz ? g * (dt - dot(V, dx)) : dt);
        k->centre.push_back(lorentz ? dx + stretch(V, g, dx) - V * (g * dt) : dx);
        k->turns.push_back(path.turns[i]);
    }
    // Step: the segments: resting in the lab before and after (-V in F_V), straight and turning at
    // a constant rate between keys (slerp: the relative turn the shorter way round).
    k->velocity.assign(n + 1, -V);
    k->axis.assign(n + 1, Vec3{0, 0, 0});
    k->rate.assign(n + 1, 0.0);
    k->whole_turn.assign(n + 1, KeyedMotion::WholeTurn{});
    for (size_t j = 1; j < n; ++j) {
        const double ds = k->s[j] - k->s[j - 1];
        k->velocity[j] = (k->centre[j] - k->centre[j - 1]) / ds;
        Quat d = multiply(k->turns[j], conjugate(k->turns[j - 1]));
        if (d.w < 0) d = {-d.w, -d.x, -d.y, -d.z};
        const Vec3 v{d.x, d.y, d.z};
        const double vn = norm(v);
        if (vn > 0) {
            k->axis[j] = v / vn;
            k->rate[j] = 2 * std::atan2(vn, d.w) / ds;
            const double a = k->rate[j] * ds;  // as keyedSegmentTurned forms it at s = s[j]
            k->whole_turn[j] = {std::cos(a), std::sin(a), std::sin(0.5 * a)};
        }
    }
    return k;
}

size_t keyedSegment(const KeyedMotion& k, double s) { return locate(k, s).segment; }

KeyedLocal keyedLocal(const KeyedMotion& k, double s, const Vec3& q) {
    return keyedSegmentLocal(k, locate(k, s).segment, s, q);
}

KeyedLocal keyedSegmentLocal(const KeyedMotion& k, size_t j, double s, const Vec3& q) {
    KeyedLocal l = keyedSegmentTurned(k, j, s, rotate(k.turns[j == 0 ? 0 : j - 1], q));
    if (k.lorentz) {
        const double speed = norm(l.dy);
        l.dtau = std::sqrt(std::max(0.0, (1 - speed) * (1 + speed)));
    }
    return l;
}

KeyedLocal keyedSegmentTurned(const KeyedMotion& k, size_t j, double s, const Vec3& p) {
    KeyedLocal l;
    const Where at{j, j == 0 ? 0 : j - 1};
    const double ds = s - k.s[at.key];
    const double rate = k.rate[at.segment];
    const Vec3& axis = k.axis[at.segment];
    // The turn by rate ds; none at the segment's first key, the stored whole turn at its last.
    Vec3 turned = p;
    if (rate > 0 && ds != 0) {
        if (j < k.s.size() && s == k.s[j] && j < k.whole_turn.size()) {
            const KeyedMotion::WholeTurn& w = k.whole_turn[j];
            turned = turnWith(axis, w.cos, w.sin, w.half_sin, p);
        } else {
            turned = turnAbout(axis, rate * ds, p);
        }
    }
    l.y = k.centre[at.key] + k.velocity[at.segment] * ds + turned;
    l.dy = k.velocity[at.segment] + (rate > 0 ? cross(axis, turned) * rate : Vec3{0, 0, 0});
    return l;
}

double keyedProperTime(const KeyedMotion& k, double s, const Vec3& q) {
    if (!k.lorentz) return s;
    const double lo = std::min(0.0, s), hi = std::max(0.0, s);
    double total = 0;
    const size_t n = k.s.size();
    for (size_t j = 0; j <= n; ++j) {
        const double a = std::max(lo, j == 0 ? -INFINITY : k.s[j - 1]);
        const double b = std::min(hi, j == n ? INFINITY : k.s[j]);
        if (b > a) total += segmentClock(k, j, q, a, b);
    }
    return s >= 0 ? total : -total;
}

KeyedSpeed fastestCentreSegment(const KeyPath& path) {
    KeyedSpeed out;
    for (size_t j = 1; j < path.times.size(); ++j) {
        const double v = norm(path.positions[j] - path.positions[j - 1]) / (path.times[j] - path.times[j - 1]);
        if (!(v <= out.speed) || out.index < 0) {
            out.speed = v;
            out.lab_time = path.times[j - 1];
            out.index = long(j - 1);
        }
        if (!std::isfinite(v)) break;
    }
    return out;
}

KeyedSpeed maxKeyedSpeed(const KeyedMotion& k, const Vec3& q) {
    KeyedSpeed out;
    const size_t n = k.s.size();
    for (size_t j = 0; j <= n; ++j) {
        const size_t key = j == 0 ? 0 : j - 1;
        const SpeedWave w = speedWave(k, j, rotate(k.turns[key], q));
        // Step: where the cosine peaks on the segment's arc [0, rate ds] (its ends otherwise).
        double s_at = k.s[key], v2 = w.A;
        if (w.B > 0) {
            const double arc = k.rate[j] * (k.s[j] - k.s[key]);  // 0 < j < n here (rate > 0)
            double peak = std::fmod(w.phi0, kTwoPi);
            if (peak < 0) peak += kTwoPi;
            double phi = 0;
            if (arc >= kTwoPi || peak <= arc) {
                phi = peak;
            } else {
                phi = std::cos(arc - w.phi0) > std::cos(-w.phi0) ? arc : 0.0;
            }
            v2 = w.A + w.B * std::cos(phi - w.phi0);
            s_at = k.s[key] + phi / k.rate[j];
        }
        const double v = std::sqrt(std::max(0.0, v2));
        if (out.index < 0 || v > out.speed || !std::isfinite(v)) {
            out.speed = v;
            out.index = long(j);
            // The lab time of q's event there.
            const KeyedLocal l = keyedLocal(k, s_at, q);
            out.lab_time = k.lorentz ? k.t0 + k.gamma * (s_at + dot(k.frame_velocity, l.y)) : k.t0 + s_at;
        }
    }
    return out;
}

}  // namespace mesh4d
