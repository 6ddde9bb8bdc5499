#include "boost.h"

#include "robust.h"

namespace mesh4d {

Motion makeMotion(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& velocity) {
    Motion m;
    m.kinematics = kinematics;
    m.t0 = t0;
    m.origin = origin;
    m.velocity = velocity;
    m.beta = norm(velocity);
    if (kinematics == Kinematics::Lorentz) {
        m.inv_gamma2 = oneMinusSquare(m.beta);
        m.gamma = 1.0 / std::sqrt(m.inv_gamma2);
    }
    return m;
}

// (q.u) u computed as (q.v) v / b^2, and (g - 1) / b^2 = g^2 / (g + 1) without cancellation:
// (g - 1) = (g^2 - 1)/(g + 1) = g^2 b^2 / (g + 1).
static Vec3 alongVelocityScaled(const Motion& m, const Vec3& q, double coefficient_over_b2) {
    return m.velocity * (dot(q, m.velocity) * coefficient_over_b2);
}

Event labFromRest(const Motion& m, double tau, const Vec3& q) {
    if (m.kinematics == Kinematics::Galilean) return {m.t0 + tau, m.origin + q + m.velocity * tau};
    const double g = m.gamma;
    const double g_minus_1_over_b2 = g * g / (g + 1.0);
    Event e;
    e.t = m.t0 + g * (tau + dot(m.velocity, q));
    e.x = m.origin + q + alongVelocityScaled(m, q, g_minus_1_over_b2) + m.velocity * (g * tau);
    return e;
}

double properTimeAt(const Motion& m, const Vec3& q, double t) {
    if (m.kinematics == Kinematics::Galilean) return t - m.t0;
    return (t - m.t0) / m.gamma - dot(m.velocity, q);
}

Vec3 labPositionAt(const Motion& m, const Vec3& q, double t) {
    const Vec3 moved = m.origin + m.velocity * (t - m.t0) + q;
    if (m.kinematics == Kinematics::Galilean) return moved;
    // (1 - 1/g)(q.u)u = (q.v)v * (1 - 1/g)/b^2, and (1 - 1/g)/b^2 = (g - 1)/(g b^2) = g/(g + 1).
    const double g = m.gamma;
    return moved - alongVelocityScaled(m, q, g / (g + 1.0));
}

Vec3 restFromLab(const Motion& m, const Vec3& x, double t) {
    const Vec3 p = x - m.origin - m.velocity * (t - m.t0);
    if (m.kinematics == Kinematics::Galilean) return p;
    // p = q - (1 - 1/g)(q.u)u stretches back by g along u: q = p + (g - 1)(p.u)u.
    const double g = m.gamma;
    return p + alongVelocityScaled(m, p, g * g / (g + 1.0));
}

}  // namespace mesh4d
