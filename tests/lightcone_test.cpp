// Tests of the retarded point (DESIGN.md section 5) against an independent solve and the inverse map.
#include <gtest/gtest.h>

#include <random>

extern "C" {
#include <quadmath.h>
}

#include "mesh4d/boost.h"
#include "mesh4d/lightcone.h"
#include "mesh4d/robust.h"

using namespace mesh4d;

namespace {

// Independent reference: the delay d solves |e - v d| = d; f(d) = |e - v d| - d is strictly
// decreasing for |v| < 1, so bisection on [0, 2 |e| / (1 - b)] finds it. Done in binary128
// (113-bit significand): f cancels about log2(1 / (1 - b)) bits near b = 1, which leaves over 80.
typedef __float128 Quad;
double referenceDelay(const Vec3& e, const Vec3& v) {
    auto f = [&](Quad d) {
        const Quad x = Quad(e.x) - Quad(v.x) * d, y = Quad(e.y) - Quad(v.y) * d, z = Quad(e.z) - Quad(v.z) * d;
        return sqrtq(x * x + y * y + z * z) - d;
    };
    const Quad b = sqrtq(Quad(v.x) * Quad(v.x) + Quad(v.y) * Quad(v.y) + Quad(v.z) * Quad(v.z));
    Quad lo = 0, hi = 2 * sqrtq(Quad(e.x) * Quad(e.x) + Quad(e.y) * Quad(e.y) + Quad(e.z) * Quad(e.z)) / (1 - b);
    for (int i = 0; i < 300; ++i) {
        const Quad mid = (lo + hi) / 2;
        if (f(mid) > 0) lo = mid; else hi = mid;
    }
    return double((lo + hi) / 2);
}

}  // namespace

// Over 15 decades of distance and speeds up to 1 - 1e-12. Speeds very near 1 are put along an
// axis, where |v| is exact: for a general direction the rounding of |v| itself (1e-16) changes
// 1 - b^2 by 1e-16 / (1 - b) relative, a limit of stating v as three doubles, not of the root.
TEST(Lightcone, DelayMatchesIndependentSolve) {
    for (int seed = 0; seed < 2000; ++seed) {
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> u(-1, 1);
        const double scale = std::pow(10.0, std::uniform_real_distribution<double>(-6, 9)(rng));
        Vec3 e{u(rng) * scale, u(rng) * scale, u(rng) * scale};
        Vec3 v;
        if (seed % 4 == 0) {
            const double beta = 1 - std::pow(10.0, -std::uniform_real_distribution<double>(1, 12)(rng));
            v = Vec3{0, 0, 0};
            const int axis = seed / 4 % 3;
            (axis == 0 ? v.x : axis == 1 ? v.y : v.z) = u(rng) < 0 ? -beta : beta;
        } else {
            const Vec3 dir{u(rng), u(rng), u(rng)};
            v = dir * (std::uniform_real_distribution<double>(0, 0.999)(rng) / norm(dir));
        }
        const double d = retardedDelay(e, v, oneMinusSquare(norm(v)));
        const double ref = referenceDelay(e, v);
        // Bound: a few ulps from the root, plus the conditioning of 1 - b^2 on the rounded |v|
        // (zero for the axis-aligned speeds, whose |v| is exact).
        const double bound = 1e-14 + (seed % 4 == 0 ? 0.0 : 2.2e-16 / (1 - norm(v)));
        EXPECT_LE(std::fabs(d - ref) / ref, bound) << "seed " << seed << " beta " << norm(v);
    }
}

// The retarded event lies on the past cone and on the worldline; un-retarding it (DESIGN.md
// section 5's inverse: z = y - v (t_c - |y - C| - t0)) lands where the worldline is at t0.
TEST(Lightcone, CutIsOnConeAndWorldlineBothDirections) {
    for (int seed = 0; seed < 500; ++seed) {
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> u(-1, 1);
        const Vec3 C{u(rng), u(rng), u(rng)};
        const Event anchor{u(rng) * 5, Vec3{u(rng), u(rng), u(rng)} * 30.0};
        const Vec3 v = Vec3{u(rng), u(rng), u(rng)} * 0.55;  // |v| < 0.96
        const ViewSurface view{ViewKind::PastCone, 12.5, C};
        const Event y = cutWorldline(view, anchor, v, oneMinusSquare(norm(v))).event;
        const double dist = norm(y.x - C);
        EXPECT_NEAR(dist, view.t_c - y.t, 1e-12 * (1 + dist)) << "seed " << seed;
        EXPECT_LE(y.t, view.t_c);
        const Vec3 z = y.x - v * (view.t_c - dist - anchor.t);
        EXPECT_NEAR(norm(z - anchor.x), 0, 1e-12 * (1 + norm(anchor.x) + dist)) << "seed " << seed;
    }
}

// At rest the delay is the distance. A point now at distance r on the line of sight emitted the
// light from r + b d when approaching (d = r + b d, so d = r / (1 - b)) and from r - b d when
// receding (d = r / (1 + b)).
TEST(Lightcone, ClosedFormsOnTheLineOfSight) {
    const Vec3 e{0, 0, -10};
    EXPECT_DOUBLE_EQ(retardedDelay(e, {0, 0, 0}, 1.0), 10.0);
    const double b = 0.6;
    EXPECT_NEAR(retardedDelay(e, {0, 0, b}, oneMinusSquare(b)), 10.0 / (1 - b), 1e-12);   // approaching
    EXPECT_NEAR(retardedDelay(e, {0, 0, -b}, oneMinusSquare(b)), 10.0 / (1 + b), 1e-12);  // receding
    EXPECT_EQ(retardedDelay({0, 0, 0}, {0, 0, b}, oneMinusSquare(b)), 0.0);  // at the camera
}

// A point now at closest approach r is seen at distance gamma r (DESIGN.md section 10), arcsin(b)
// behind the perpendicular.
TEST(Lightcone, ClosestApproachAppearsAtGammaR) {
    for (double b : {0.1, 0.5, 0.866, 0.99, 0.999999}) {
        const double r = 7.0, g = 1 / std::sqrt(oneMinusSquare(b));
        const Vec3 e{0, 0, -r}, v{b, 0, 0};
        const double d = retardedDelay(e, v, oneMinusSquare(b));
        const Vec3 y = e - v * d;
        EXPECT_NEAR(norm(y), g * r, 1e-12 * g * r) << b;
        EXPECT_NEAR(std::asin(-y.x / norm(y)), std::asin(b), 1e-9) << b;
    }
}

TEST(Lightcone, SegmentCrossingIsOnTheCone) {
    const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
    // A spacelike segment at one time straddling the cone: from inside (far past) to outside.
    const Event p0{-10, {0, 0, -5}}, p1{-10, {0, 0, -15}};
    ASSERT_GT(viewSide(view, p0), 0);
    ASSERT_LT(viewSide(view, p1), 0);
    const double s = cutSegment(view, p0, p1);
    EXPECT_NEAR(s, 0.5, 1e-15);  // |x| = 10 at s = 0.5
    // A tilted segment (relativity of simultaneity): check the identity at the root.
    const Event q0{-9, {1, 2, -3}}, q1{-11.5, {4, -1, -14}};
    const double s2 = cutSegment(view, q0, q1);
    const Event e = lerp(q0, q1, s2);
    EXPECT_NEAR(viewSide(view, e), 0, 1e-13);
    const ViewSurface plane{ViewKind::Hyperplane, -10.0, {}};
    EXPECT_NEAR(lerp(q0, q1, cutSegment(plane, q0, q1)).t, -10.0, 1e-14);
}
