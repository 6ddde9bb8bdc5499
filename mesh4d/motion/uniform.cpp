#include "mesh4d/motion/motion.h"

#include "mesh4d/robust.h"

namespace mesh4d {

Motion makeMotion(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& velocity) {
    Motion m;
    m.kinematics = kinematics;
    m.t0 = t0;
    m.origin = origin;
    m.velocity = velocity;
    m.beta = norm(velocity);
    m.one_minus_beta2 = oneMinusNorm2(velocity.x, velocity.y, velocity.z);  // exact to rounding, any direction
    if (kinematics == Kinematics::Lorentz) {
        m.inv_gamma2 = m.one_minus_beta2;
        m.gamma = 1.0 / std::sqrt(m.inv_gamma2);
    }
    return m;
}

Motion makeMotionFromGamma(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& direction, double gamma) {
    // b = sqrt((g - 1)(g + 1)) / g: no cancellation for g near 1 either.
    const double beta = std::sqrt((gamma - 1.0) * (gamma + 1.0)) / gamma;
    Motion m = makeMotion(kinematics, t0, origin, direction * beta);
    m.beta = beta;
    m.one_minus_beta2 = 1.0 / (gamma * gamma);
    if (kinematics == Kinematics::Lorentz) {
        m.gamma = gamma;
        m.inv_gamma2 = m.one_minus_beta2;
    }
    return m;
}

Motion makeMotionFromRapidity(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& direction,
                              double rapidity) {
    const double gamma = std::cosh(rapidity);
    Motion m = makeMotionFromGamma(kinematics, t0, origin, direction, gamma);
    m.beta = std::tanh(rapidity);  // more accurate than from gamma for small rapidities
    m.velocity = direction * m.beta;
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

Vec3 shapeOffset(const Motion& m, const Vec3& q) {
    if (m.kinematics == Kinematics::Galilean) return q;
    // The component along u shrinks to (q.u)/g; the rest stays. Written as q - (1 - 1/g)(q.u)u,
    // the along part would be a difference of nearly equal terms at large g (2e-9 relative error
    // at g = 1e7); split into the perpendicular part and the scaled along part, each is accurate
    // relative to |q|, and the along part relative to itself.
    if (!(m.beta > 0)) return q;
    const Vec3 u = m.velocity / m.beta;
    const double along = dot(q, u);
    return (q - u * along) + u * (along / m.gamma);
}

Vec3 labPositionAt(const Motion& m, const Vec3& q, double t) {
    return m.origin + m.velocity * (t - m.t0) + shapeOffset(m, q);
}

Vec3 restFromLab(const Motion& m, const Vec3& x, double t) {
    const Vec3 p = x - m.origin - m.velocity * (t - m.t0);
    if (m.kinematics == Kinematics::Galilean) return p;
    // p = q - (1 - 1/g)(q.u)u stretches back by g along u: q = p + (g - 1)(p.u)u.
    const double g = m.gamma;
    return p + alongVelocityScaled(m, p, g * g / (g + 1.0));
}

}  // namespace mesh4d
