// For the bounds' property tests (geometric_bound_test.cpp, slide_bound_test.cpp): one random
// object moving uniformly past a camera at rest at the origin, seen on its past cone, drawn from
// a seeded generator so that every run meets the same cases.
#pragma once

#include <cmath>
#include <random>

#include "mesh4d/lightcone.h"
#include "mesh4d/motion/motion.h"

namespace testcase {

struct MovingCase {
    double beta, size, distance;
    mesh4d::Vec3 where;  // the object's origin at t = 0
    mesh4d::Motion m;
    mesh4d::ViewSurface view;
    mesh4d::ViewAnchor anchor;
};

// Case `trial`, drawn from rng through u (uniform on [-1, 1]), in this order: b uniform in
// [0.05, 0.999] (every 7th trial 0.999), a direction, the kinematics by turns (odd trials
// Lorentz), size 10^[-2.5, -0.5], distance size 10^e with e uniform in [log_lo, log_hi] (every 5th
// trial 3 sizes), the object's origin at t = 0 at that distance in front of the camera (-z), the
// camera time uniform in [0, 2] distance. The caller draws its points on from the same rng.
inline MovingCase randomMovingCase(int trial, double log_lo, double log_hi, std::mt19937& rng,
                                   std::uniform_real_distribution<double>& u) {
    using namespace mesh4d;
    const double beta = trial % 7 == 0 ? 0.999 : 0.05 + 0.949 * (u(rng) + 1) / 2;
    Vec3 dir{u(rng), u(rng), u(rng)};
    dir = dir / norm(dir);
    const Kinematics k = trial % 2 ? Kinematics::Lorentz : Kinematics::Galilean;
    const double size = std::pow(10.0, 2 * u(rng) - 1.5);
    const double distance = size * (trial % 5 == 0 ? 3.0 : std::pow(10.0, log_lo + (log_hi - log_lo) / 2 * (u(rng) + 1)));
    const Vec3 where = Vec3{u(rng), u(rng), -1} * distance;
    const Motion m = makeMotion(k, 0.0, where, dir * beta);
    const ViewSurface view{ViewKind::PastCone, distance * (1 + u(rng)), {0, 0, 0}};
    return {beta, size, distance, where, m, view, viewAnchor(view, m)};
}

}  // namespace testcase
