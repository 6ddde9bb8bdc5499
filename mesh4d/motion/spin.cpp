#include "mesh4d/motion/worldline.h"

#include <cmath>

#include "mesh4d/motion/local.h"

namespace mesh4d {

namespace {

// Rodrigues' turn of q about unit axis k by angle a, with 1 - cos a = 2 sin^2(a/2) (no cancellation
// for small angles).
Vec3 turn(const Vec3& k, double a, const Vec3& q) {
    const double c = std::cos(a), sn = std::sin(a), h = std::sin(0.5 * a);
    return q * c + cross(k, q) * sn + k * (dot(k, q) * 2 * h * h);
}

}  // namespace

namespace motion_detail {

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

}  // namespace motion_detail

using namespace motion_detail;

Vec3 spunPoint(const Motion& m, double s, const Vec3& q) { return spinLocal(m, s, q).Y; }

double spinSpeed(const Motion& m, const Vec3& q) { return norm(cross(m.angular_velocity, q)); }

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

double spinVertexSpeed(const Motion& m, const Vec3& q) {
    return m.kinematics == Kinematics::Lorentz ? spinSpeed(m, q) : maxGalileanSpeed(m, q);
}

}  // namespace mesh4d
