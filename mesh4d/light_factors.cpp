#include "light_factors.h"

#include <cmath>

#include "robust.h"
#include "motion/worldline.h"

namespace mesh4d {

double dopplerFactor(const Motion& m, ViewKind kind, const Vec3& apex, const Vec3& x, const Vec3& receiver) {
    if (kind == ViewKind::Hyperplane) return 1.0;
    const Vec3 d = apex - x;
    const double dist = norm(d);
    // The receiver's factor 1 - v.n (1 when it is at rest), formed as the source's below.
    double received = 1.0;
    const double r = norm(receiver);
    if (r > 0 && dist > 0) {
        const double one_minus_r2 = oneMinusNorm2(receiver.x, receiver.y, receiver.z);
        received = one_minus_r2 / (1.0 + r) + r * 0.5 * norm2(receiver / r - d / dist);
        if (m.kinematics == Kinematics::Lorentz) received /= std::sqrt(one_minus_r2);  // g_r (1 - v.n)
    }
    if (!(dist > 0) || !(m.beta > 0)) return received * (m.kinematics == Kinematics::Lorentz ? 1.0 / m.gamma : 1.0);
    const Vec3 n = d / dist;
    const Vec3 u = m.velocity / m.beta;
    // 1 - b cos t = (1 - b) + b (1 - cos t), each term without cancellation.
    const double one_minus_b = m.one_minus_beta2 / (1.0 + m.beta);
    const double one_minus_wn = one_minus_b + m.beta * 0.5 * norm2(u - n);
    const double g = m.kinematics == Kinematics::Lorentz ? m.gamma : 1.0;
    return received / (g * one_minus_wn);
}

void addLightFactors(const World4D& world, const ViewSurface& view, ApparentMesh* m) {
    const size_t n = m->positions.size();
    m->doppler.resize(n);
    m->proper_time.resize(n);
    if (!isUniform(world.motion)) {  // worldline.h: the crossing again, for its time s
        for (size_t i = 0; i < n; ++i) {
            const Vec3& q = m->rest_points[i];
            const double s = crossWorldline(view, world.motion, q).s;
            m->doppler[i] = worldlineDoppler(world.motion, view.kind, view.apex, s, q, m->absolutePosition(i));
            m->proper_time[i] = worldlineProperTime(world.motion, s, q);
        }
        return;
    }
    for (size_t i = 0; i < n; ++i) {
        // Under a shear the outputs are in the camera's frame: back to the view's own (the lab).
        const Vec3 x = view.sheared() ? m->absolutePosition(i) + view.shear * m->absoluteTime(i) : m->absolutePosition(i);
        // A tilted hyperplane: the light goes along -k, to the foot of x on the image plane.
        if (view.kind == ViewKind::Hyperplane && view.tilted())
            m->doppler[i] = dopplerFactor(world.motion, ViewKind::PastCone, x - view.tilt * dot(x - view.apex, view.tilt), x);
        else
            m->doppler[i] = dopplerFactor(world.motion, view.kind, view.apex, x, view.shear);
        m->proper_time[i] = properTimeAt(world.motion, m->rest_points[i], m->absoluteTime(i));
    }
}

}  // namespace mesh4d
