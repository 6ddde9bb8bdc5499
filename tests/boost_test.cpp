// Tests of the rest-to-lab maps against closed forms of special relativity (docs/DESIGN.md section 3).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "mesh4d/motion/motion.h"
#include "mesh4d/robust.h"

using namespace mesh4d;

namespace {
Vec3 randomVec(std::mt19937_64& rng, double scale) {
    std::uniform_real_distribution<double> u(-scale, scale);
    return {u(rng), u(rng), u(rng)};
}
Vec3 randomVelocity(std::mt19937_64& rng, double beta) {
    Vec3 d = randomVec(rng, 1.0);
    return d * (beta / norm(d));
}
}  // namespace

// The Minkowski interval between two events is the same in the rest frame and in the lab.
TEST(Boost, PreservesTheInterval) {
    for (int seed = 0; seed < 200; ++seed) {
        std::mt19937_64 rng(seed);
        const double beta = std::uniform_real_distribution<double>(0, 0.99)(rng);
        const Motion m = makeMotion(Kinematics::Lorentz, 3.0, randomVec(rng, 10), randomVelocity(rng, beta));
        const Vec3 q1 = randomVec(rng, 2), q2 = randomVec(rng, 2);
        const double tau1 = std::uniform_real_distribution<double>(-5, 5)(rng), tau2 = tau1 + 1.7;
        const double rest = norm2(q2 - q1) - (tau2 - tau1) * (tau2 - tau1);
        const double lab = interval2(labFromRest(m, tau1, q1), labFromRest(m, tau2, q2));
        EXPECT_NEAR(lab, rest, 1e-12 * (1 + std::fabs(rest)) * m.gamma * m.gamma) << "seed " << seed;
    }
}

// A rod of rest length L along the motion measures L/gamma at one lab time; a clock runs slow by gamma.
TEST(Boost, LengthContractionAndTimeDilation) {
    for (double beta : {0.1, 0.5, 0.866, 0.99, 0.999999}) {
        const Vec3 u = Vec3{1, 2, -2} / 3.0;
        const Motion m = makeMotion(Kinematics::Lorentz, 0, {}, u * beta);
        const double L = 4.0, gamma = 1 / std::sqrt((1 - beta) * (1 + beta));
        const double t = 7.25;
        const double measured = norm(labPositionAt(m, u * L, t) - labPositionAt(m, Vec3{}, t));
        EXPECT_NEAR(measured, L / gamma, 1e-12 * L) << "beta " << beta;
        const Vec3 q{0.3, -1, 2};
        const double dt = labFromRest(m, 2.0, q).t - labFromRest(m, 1.0, q).t;
        EXPECT_NEAR(dt, gamma, 1e-12 * gamma) << "beta " << beta;
        // Perpendicular extents are unchanged.
        const Vec3 perp = cross(u, Vec3{0, 0, 1});
        EXPECT_NEAR(norm(labPositionAt(m, perp, t) - labPositionAt(m, Vec3{}, t)), norm(perp), 1e-12);
    }
}

// labFromRest, labPositionAt, properTimeAt and restFromLab describe the same worldlines.
TEST(Boost, MapsAreMutuallyConsistent) {
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        for (int seed = 0; seed < 100; ++seed) {
            std::mt19937_64 rng(seed);
            const Motion m = makeMotion(k, -2.0, randomVec(rng, 20), randomVelocity(rng, 0.95));
            const Vec3 q = randomVec(rng, 3);
            const double tau = std::uniform_real_distribution<double>(-10, 10)(rng);
            const Event e = labFromRest(m, tau, q);
            EXPECT_NEAR(norm(labPositionAt(m, q, e.t) - e.x), 0, 1e-12 * 50) << "seed " << seed;
            EXPECT_NEAR(properTimeAt(m, q, e.t), tau, 1e-12 * 50) << "seed " << seed;
            EXPECT_NEAR(norm(restFromLab(m, e.x, e.t) - q), 0, 1e-12 * 50) << "seed " << seed;
        }
    }
}

// The origin event is (t0, X0), and Galilean motion is a plain shear.
TEST(Boost, OriginEventAndGalileanShear) {
    const Motion l = makeMotion(Kinematics::Lorentz, 1.5, {1, 2, 3}, {0.6, 0, 0});
    const Event o = labFromRest(l, 0, {});
    EXPECT_EQ(o.t, 1.5);
    EXPECT_EQ(o.x, (Vec3{1, 2, 3}));
    EXPECT_DOUBLE_EQ(l.gamma, 1.25);
    const Motion g = makeMotion(Kinematics::Galilean, 1.5, {1, 2, 3}, {0.6, 0, 0});
    const Event e = labFromRest(g, 2.0, {0, 1, 0});
    EXPECT_DOUBLE_EQ(e.t, 3.5);
    EXPECT_DOUBLE_EQ(e.x.x, 2.2);
    EXPECT_DOUBLE_EQ(e.x.y, 3.0);
}

// 1 - b^2 keeps full relative precision near b = 1, where 1 - b*b loses it. Reference: long
// double, where 1 - b and 1 + b of a double b are exact and their product is off by 2^-64.
TEST(Robust, OneMinusSquareNearOne) {
    for (int k = 3; k <= 15; ++k) {
        const double b = 1.0 - std::pow(10.0, -k);
        const long double exact = (1.0L - (long double)b) * (1.0L + (long double)b);
        const double got = oneMinusSquare(b);
        EXPECT_LE(std::fabs((long double)got - exact) / exact, 2.3e-16) << "k " << k;
    }
    // The naive form loses about log10(1 / (1 - b)) digits: at b = 1 - 1e-9, over 1e-10 relative
    // (a million times the bound above).
    const double b = 1.0 - 1e-9;
    const long double exact = (1.0L - (long double)b) * (1.0L + (long double)b);
    EXPECT_GT(std::fabs((long double)(1.0 - b * b) - exact) / exact, 1e-10);
}

// 1 - |v|^2 for oblique velocities, against exact arithmetic in __float128 (113-bit
// significand): each square of a double is exact in 106 bits, and with every component at least
// 1/8 in magnitude (squares >= 2^-6, lowest bit >= 2^-111) the sum and 1 - sum span at most 112
// bits, so the reference is exact until its one final rounding to double. The result must be
// within 1 ulp of it. Before the compensated sum, 1 - b^2 was (1 - b)(1 + b) of the rounded
// b = |v|: 2.2e-11 relative at b = 0.999999 with three equal components (checked below).
TEST(Robust, OneMinusNorm2OfObliqueVelocitiesIsExactToRounding) {
    auto exact = [](const Vec3& v) {
        const __float128 x = v.x, y = v.y, z = v.z;
        return double(__float128(1) - (x * x + y * y + z * z));
    };
    auto withinUlp = [](double got, double ref) {
        return got >= std::nextafter(ref, -INFINITY) && got <= std::nextafter(ref, INFINITY);
    };
    // Step: the case from the issue: three equal components, b = 0.999999.
    const double c = 0.999999 / std::sqrt(3.0);
    const Vec3 v{c, c, c};
    const double ref = exact(v);
    EXPECT_TRUE(withinUlp(oneMinusNorm2(v.x, v.y, v.z), ref)) << oneMinusNorm2(v.x, v.y, v.z) << " vs " << ref;
    const double old_way = oneMinusSquare(norm(v));
    EXPECT_GT(std::fabs(old_way - ref) / ref, 1e-12) << "the test no longer tells the two forms apart";
    const Motion m = makeMotion(Kinematics::Lorentz, 0, {0, 0, 0}, v);
    EXPECT_TRUE(withinUlp(m.one_minus_beta2, ref));
    EXPECT_TRUE(withinUlp(m.inv_gamma2, ref));
    // Step: random directions and speeds up to 1 - 1e-12, seed fixed per case.
    for (const double b : {0.5, 0.9, 0.999999, 1 - 1e-9, 1 - 1e-12}) {
        std::mt19937_64 rng(std::hash<double>{}(b));
        for (int i = 0; i < 2000; ++i) {
            Vec3 w;
            do w = randomVelocity(rng, b);
            while (std::fabs(w.x) < 0.125 || std::fabs(w.y) < 0.125 || std::fabs(w.z) < 0.125);
            const double r = exact(w);
            ASSERT_TRUE(withinUlp(oneMinusNorm2(w.x, w.y, w.z), r))
                << "b " << b << " i " << i << " v " << w.x << " " << w.y << " " << w.z << ": got "
                << oneMinusNorm2(w.x, w.y, w.z) << ", exact " << r;
        }
    }
    // Step: along an axis the result is correctly rounded as well (1 - b*b exactly split).
    EXPECT_TRUE(withinUlp(oneMinusNorm2(0.999999, 0, 0), exact({0.999999, 0, 0})));
    EXPECT_EQ(oneMinusNorm2(0, 0, 0), 1.0);
}

TEST(Robust, QuadraticRootsAgainstClosedForm) {
    // (s - 1e-9)(s - 1e9) = s^2 - (1e9 + 1e-9) s + 1: the naive formula loses the small root.
    const QuadraticRoots r = solveQuadratic(1.0, -0.5 * (1e9 + 1e-9), 1.0);
    ASSERT_EQ(r.count, 2);
    EXPECT_NEAR(r.r0, 1e-9, 1e-24);
    EXPECT_NEAR(r.r1, 1e9, 1e-6);
    EXPECT_EQ(solveQuadratic(1.0, 0.0, 1.0).count, 0);  // s^2 + 1
    const QuadraticRoots lin = solveQuadratic(0.0, 1.0, -4.0);  // 2 s - 4
    ASSERT_EQ(lin.count, 1);
    EXPECT_EQ(lin.r0, 2.0);
}
