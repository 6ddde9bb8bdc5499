#include "light_factors.h"

#include <cmath>

#include "worldline.h"

namespace mesh4d {

double dopplerFactor(const Motion& m, ViewKind kind, const Vec3& apex, const Vec3& x) {
    if (kind == ViewKind::Hyperplane) return 1.0;
    const Vec3 d = apex - x;
    const double dist = norm(d);
    if (!(dist > 0) || !(m.beta > 0)) return m.kinematics == Kinematics::Lorentz ? 1.0 / m.gamma : 1.0;
    const Vec3 n = d / dist;
    const Vec3 u = m.velocity / m.beta;
    // 1 - b cos t = (1 - b) + b (1 - cos t), each term without cancellation.
    const double one_minus_b = m.one_minus_beta2 / (1.0 + m.beta);
    const double one_minus_wn = one_minus_b + m.beta * 0.5 * norm2(u - n);
    const double g = m.kinematics == Kinematics::Lorentz ? m.gamma : 1.0;
    return 1.0 / (g * one_minus_wn);
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
        m->doppler[i] = dopplerFactor(world.motion, view.kind, view.apex, m->absolutePosition(i));
        m->proper_time[i] = properTimeAt(world.motion, m->rest_points[i], m->absoluteTime(i));
    }
}

}  // namespace mesh4d
