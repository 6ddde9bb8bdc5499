#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mesh4d/elliptic.h"
#include "mesh4d/extrude.h"
#include "mesh4d/motion/kinds.h"

namespace mesh4d {

namespace {

using motion_detail::Local;

constexpr double kPi = 3.14159265358979323846;

// The circle (motion.h Orbit): unit axis k, X0's radial vector e0 from the axis (length R), f0 =
// k x e0, the speed v and angular speed w = v / R, and the carry's g and alpha = 1 - 1/g (1 and 0
// for the Galilean carry).
struct Ring {
    Vec3 k, e0, f0;
    double R = 0, v = 0, w = 0, g = 1, alpha = 0;
    bool locked = false;
};

Ring ringOf(const Motion& m) {
    const Orbit& o = *m.kinds.orbit;
    Ring r;
    r.k = o.axis;
    const Vec3 d = m.origin - o.center;
    r.e0 = d - r.k * dot(r.k, d);
    r.R = norm(r.e0);
    r.f0 = cross(r.k, r.e0);
    r.v = o.speed;
    r.w = o.speed / r.R;
    r.locked = o.locked;
    if (m.kinematics == Kinematics::Lorentz) {
        const double root = std::sqrt((1 - r.v) * (1 + r.v));  // 1/g
        r.g = 1 / root;
        r.alpha = r.v * r.v / (1 + root);  // 1 - 1/g without cancellation
    }
    return r;
}

// Rodrigues' turn of q about unit axis k by angle a (1 - cos a = 2 sin^2(a/2)).
Vec3 turnAbout(const Vec3& k, double a, const Vec3& q) {
    const double h = std::sin(0.5 * a);
    return q * std::cos(a) + cross(k, q) * std::sin(a) + k * (dot(k, q) * 2 * h * h);
}

// Q contracted by 1/g along unit u: Q - alpha (Q.u) u.
Vec3 contract(const Ring& r, const Vec3& Q, const Vec3& u) { return Q - u * (r.alpha * dot(Q, u)); }

// A locked body's point q: its distance from the axis (constant: the body turns rigidly with the
// circle), carried at lab time t0.
double lockedRadius(const Ring& r, const Vec3& q) {
    const Vec3 p = r.e0 + contract(r, q, r.f0 / r.R);
    return norm(p - r.k * dot(r.k, p));
}

// A fixed body's point q: its distance from the axis direction through the origin (the part of q in
// the orbit's plane).
double planeRadius(const Ring& r, const Vec3& q) { return norm(q - r.k * dot(r.k, q)); }

Local orbitLocal(const Motion& m, double s, const Vec3& q) {
    const Ring r = ringOf(m);
    Local l;
    l.dT = r.g;
    l.T = r.g * s;
    // Step: the origin on the circle at lab time T since t0, and its direction of motion u.
    const double a = r.w * l.T, sn = std::sin(a), cs = std::cos(a), h = std::sin(0.5 * a);
    const Vec3 u = (r.f0 * cs - r.e0 * sn) / r.R;
    const Vec3 n = cross(r.k, u);  // toward the centre
    const Vec3 path = r.f0 * sn - r.e0 * (2 * h * h);
    // Step: q turned (locked) or not (fixed), contracted along u, and its rate of change.
    const Vec3 Q = r.locked ? turnAbout(r.k, a, q) : q;
    const Vec3 C = contract(r, Q, u);
    const Vec3 dC = r.locked ? cross(r.k, C) * r.w : (u * dot(Q, n) + n * dot(Q, u)) * (-r.alpha * r.w);
    const Vec3 V = u * r.v + dC;  // q's lab velocity
    l.Y = path + C;
    l.dY = V * l.dT;
    if (m.kinematics == Kinematics::Lorentz) {
        const double speed = norm(V);
        l.dtau = l.dT * std::sqrt((1 - speed) * (1 + speed));
    }
    return l;
}

double orbitProperTime(const Motion& m, double s, const Vec3& q) {
    const Ring r = ringOf(m);
    const double T = r.g * s;
    if (r.locked) {  // a constant speed w rho
        const double speed = r.w * lockedRadius(r, q);
        return T * std::sqrt((1 - speed) * (1 + speed));
    }
    // Fixed (motion.h): |V|^2 = v^2 - 2 v A sin(theta) + A^2 with theta = psi - w T, A = alpha w rho;
    // tau = (2 sqrt(c0 + c1) / w) (E(phi1 | m) - E(phi0 | m)), c0 = 1 - v^2 - A^2, c1 = 2 v A,
    // m = 2 c1 / (c0 + c1), phi0 = (pi/2 - psi) / 2, phi1 = phi0 + w T / 2.
    const Vec3 u0 = r.f0 / r.R, n0 = r.e0 / (-r.R);
    const double a0 = dot(q, u0), b0 = dot(q, n0);
    const double A = r.alpha * r.w * std::hypot(a0, b0);
    if (!(A > 0)) return T * std::sqrt((1 - r.v) * (1 + r.v));
    const double top = (1 - r.v + A) * (1 + r.v - A);  // c0 + c1 = 1 - (v - A)^2
    const double modulus = std::sqrt(4 * r.v * A / top);
    const double phi0 = 0.5 * (0.5 * kPi - std::atan2(b0, a0));
    const double phi1 = phi0 + 0.5 * r.w * T;
    return 2 * std::sqrt(top) / r.w * (ellipticE(modulus, phi1) - ellipticE(modulus, phi0));
}

double orbitFastest(const Motion& m, const Vec3& q) {
    const Ring r = ringOf(m);
    return r.locked ? r.w * lockedRadius(r, q) : r.v + r.alpha * r.w * planeRadius(r, q);
}

// |d2Y/dT2| at q, its largest over the circle: locked w^2 rho; fixed v w + 2 alpha w^2 rho_p.
double curvature(const Ring& r, const Vec3& q) {
    return r.locked ? r.w * r.w * lockedRadius(r, q) : r.v * r.w + 2 * r.alpha * r.w * r.w * planeRadius(r, q);
}

// |d(dY/dT)/dq|: locked w (a turn), fixed alpha w (the contraction's turn).
double spread(const Ring& r) { return r.locked ? r.w : r.alpha * r.w; }

void orbitRates(const Motion& m, const Vec3 q[3], double out[8]) {
    const Ring r = ringOf(m);
    double fastest = 0, bend = 0;
    for (int i = 0; i < 3; ++i) {
        fastest = std::max(fastest, orbitFastest(m, q[i]));
        bend = std::max(bend, curvature(r, q[i]));
    }
    const double rates[8] = {r.g, r.g * fastest, 0, r.g * r.g * bend, 0, 1, 0, r.g * spread(r)};
    std::copy(rates, rates + 8, out);
}

void orbitSlabRates(const Motion& m, const RestMesh& mesh, double* K, double* M) {
    const Ring r = ringOf(m);
    double edge = 0, bend = 0;
    for (const auto& t : mesh.triangles)
        for (int c = 0; c < 3; ++c) edge = std::max(edge, norm(mesh.positions[t[c]] - mesh.positions[t[(c + 1) % 3]]));
    for (const Vec3& q : mesh.positions) bend = std::max(bend, curvature(r, q));
    *K = r.g * spread(r) * edge;
    *M = r.g * r.g * bend;
}

std::string number(double x) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
}

std::string orbitProblem(const Motion& m, const std::vector<Vec3>& rest) {
    const Ring r = ringOf(m);
    if (!(r.R > 0) || !std::isfinite(r.w))
        return "position lies on the axis through center: no circle to move on";
    for (size_t i = 0; i < rest.size(); ++i) {
        const double speed = orbitFastest(m, rest[i]);
        if (!(speed < 1))
            return "vertex " + std::to_string(i) + " would move at " + number(speed) +
                   (r.locked ? " (the rim of a body locked to its orbit)" : " (the body contracted along its turning velocity)") +
                   ", which must be < 1 (the speed of light)";
    }
    return "";
}

}  // namespace

extern const KindAnswers kOrbitAnswers = {"orbit",        "an orbiting object", &orbitLocal,    &orbitProperTime,
                                          &orbitFastest, &orbitRates,          &orbitSlabRates, &orbitProblem};

}  // namespace mesh4d
