// The raytracer's time slabs checked against the true history, for the motion tests: rays cast
// through the slabs, each hit taken back to its rest point by the test's own inverse of the motion.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include "mesh4d/event.h"
#include "mesh4d/extrude.h"
#include "mesh4d/ray4d.h"

namespace testslab {

struct OffPlanes {
    double worst = 0;  // largest distance of a hit's rest point from its rest triangle's plane
    int hits = 0;
};

// The 61 x 61 rays from `camera` at lab time t_c (directions (0.02 ix, 0.02 iy, -1), |ix|, |iy| <=
// 30) through the slabs of `mesh` under `motion` cut at `samples`, the nearest hit of each taken to
// its rest point by `rest_point` (the test's inverse of the motion) and measured against the plane
// of the rest triangle it hit: within the slabs' chord when the slabs follow the history.
inline OffPlanes slabHitsOffTheirPlanes(const mesh4d::RestMesh& mesh, const mesh4d::Motion& motion,
                                        const std::vector<double>& samples, double t_c, const mesh4d::Vec3& camera,
                                        const std::function<mesh4d::Vec3(const mesh4d::Event&)>& rest_point) {
    const std::vector<mesh4d::World4D> slabs = mesh4d::extrudeSlabs(mesh, motion, samples, false, false);
    std::vector<mesh4d::TraceWorld> traces;
    for (const auto& w : slabs) traces.push_back(mesh4d::prepareTrace(w));
    OffPlanes r;
    for (int iy = -30; iy <= 30; ++iy)
        for (int ix = -30; ix <= 30; ++ix) {
            mesh4d::Vec3 d = mesh4d::Vec3{0.02 * ix, 0.02 * iy, -1};
            d = d / mesh4d::norm(d);
            mesh4d::Ray4D ray;
            ray.origin = {t_c, camera};
            ray.direction = d;
            std::optional<mesh4d::WorldHit> best;
            for (const auto& tr : traces)
                if (auto h = mesh4d::intersectWorld(tr, ray, best ? best->s : INFINITY)) best = h;
            if (!best) continue;
            ++r.hits;
            const mesh4d::Vec3 q = rest_point(best->event);
            const auto& t = mesh.triangles[best->triangle];
            const mesh4d::Vec3 a = mesh.positions[t[0]];
            const mesh4d::Vec3 n_f = mesh4d::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a);
            r.worst = std::max(r.worst, std::fabs(mesh4d::dot(q - a, n_f / mesh4d::norm(n_f))));
        }
    return r;
}

}  // namespace testslab
