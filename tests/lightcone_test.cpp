// Tests of the retarded point (docs/DESIGN.md section 5) against an independent solve and the inverse map.
#include <gtest/gtest.h>

#include <random>

extern "C" {
#include <quadmath.h>
}

#include "mesh4d/motion/motion.h"
#include "mesh4d/exact_side.h"
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

// The retarded event lies on the past cone and on the worldline; un-retarding it (docs/DESIGN.md
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

// A point now at closest approach r is seen at distance gamma r (docs/DESIGN.md section 10), arcsin(b)
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

// The side of the cone, decided exactly. An event a hair outside the cone far away: in doubles
// |x|^2 = a^2 + b^2 rounds to a^2, so the float side function says "on the cone" (0), while the
// event is outside (h < 0). The exact sign says so, through the exact fallback.
TEST(ExactSide, DecidesWhereDoublesCannot) {
    const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
    const double a = 1e8, b = 1e-5;
    const Event e{-a, {a, b, 0}};
    EXPECT_EQ(viewSide(view, e), 0.0);  // the rounding this test is about
    const long long before = exactSideFallbacks();
    EXPECT_EQ(viewSideSign(view, e), -1);
    EXPECT_EQ(exactSideFallbacks(), before + 1);
    EXPECT_EQ(viewSideSign(view, Event{-a - 1e-7, {a, 0, 0}}), 1);  // inside by 1e-7 (ulp of a is 1.5e-8)
    // Exactly on the cone, and at the apex.
    EXPECT_EQ(viewSideSign(view, Event{-5, {3, 4, 0}}), 0);
    EXPECT_EQ(viewSideSign(view, Event{-a, {a, 0, 0}}), 0);
    EXPECT_EQ(viewSideSign(view, Event{0, {0, 0, 0}}), 0);
    EXPECT_EQ(viewSideSign(view, Event{0, {0, 1e-300, 0}}), -1);  // at the camera time, elsewhere
    EXPECT_EQ(viewSideSign(view, Event{1e-300, {0, 0, 0}}), -1);   // in the future of the apex
    // The hyperplane: the sign of one subtraction.
    const ViewSurface plane{ViewKind::Hyperplane, 1.0, {}};
    EXPECT_EQ(viewSideSign(plane, Event{1.0, {5, 5, 5}}), 0);
    EXPECT_EQ(viewSideSign(plane, Event{std::nextafter(1.0, 2.0), {}}), -1);
}

// Against an independent exact evaluation: events on integer lattices (times 2^-20, offset by a
// camera far from the origin) within one unit of the cone, where dt^2 - |dx|^2 is computed
// exactly in 64-bit integers.
TEST(ExactSide, AgreesWithIntegerArithmeticNearTheCone) {
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int64_t> coord(-(1 << 20), 1 << 20), jitter(-2, 2);
    const double unit = std::ldexp(1.0, -20);
    const Vec3 apex{12345678.0, -7654321.0, 1e6};
    const double t_c = 98765432.0;
    const ViewSurface view{ViewKind::PastCone, t_c, apex};
    int zeros = 0, negatives = 0, positives = 0;
    for (int i = 0; i < 20000; ++i) {
        const int64_t dx = coord(rng), dy = coord(rng), dz = coord(rng);
        const int64_t r2 = dx * dx + dy * dy + dz * dz;
        int64_t dt = int64_t(std::llround(std::sqrt(double(r2)))) + jitter(rng);
        if (i % 4 == 0) {  // exact cone points: a Pythagorean case along an axis
            dt = std::llabs(dx);
        }
        const int64_t ry2 = i % 4 == 0 ? dx * dx : r2;
        const Vec3 off = i % 4 == 0 ? Vec3{double(dx), 0, 0} : Vec3{double(dx), double(dy), double(dz)};
        const Event e{t_c - double(dt) * unit, apex + off * unit};
        // The event's coordinates are exact (integers times 2^-20 below 2^53 in magnitude).
        ASSERT_EQ((e.x.x - apex.x) / unit, off.x);
        ASSERT_EQ((t_c - e.t) / unit, double(dt));
        const int expected = dt < 0 ? -1 : (dt == 0 ? (ry2 == 0 ? 0 : -1) : (dt * dt > ry2) - (dt * dt < ry2));
        ASSERT_EQ(viewSideSign(view, e), expected) << i;
        zeros += expected == 0;
        negatives += expected < 0;
        positives += expected > 0;
    }
    EXPECT_GT(zeros, 1000);
    EXPECT_GT(negatives, 1000);
    EXPECT_GT(positives, 1000);
}

// The vectorized batch cut (vertex mode's fast path) gives bit for bit what the scalar cut gives,
// on random points around anchors ahead of, behind and at the camera (both root branches, K = 0).
TEST(Lightcone, BatchCutIsBitIdenticalToTheScalarCut) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    int branches_negative = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 dir = Vec3{u(rng), u(rng), u(rng)} / std::sqrt(3.0);
        const double b = trial % 5 == 0 ? 0.0 : std::fabs(u(rng)) * 0.999;
        const Kinematics k = trial % 2 ? Kinematics::Lorentz : Kinematics::Galilean;
        const Vec3 origin = trial % 7 == 0 ? Vec3{0, 0, 0} : Vec3{10 * u(rng), 10 * u(rng), 10 * u(rng)};
        const Motion m = makeMotion(k, 0.0, origin, dir * b);
        const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
        const ViewAnchor anchor = viewAnchor(view, m);
        std::vector<Vec3> q(257);
        for (size_t i = 1; i < q.size(); ++i) q[i] = Vec3{u(rng), u(rng), u(rng)} * (trial % 3 == 0 ? 30.0 : 2.0);
        std::vector<Vec3> pos(q.size());
        std::vector<double> times(q.size());
        cutRestLocalBatch(anchor, m, q.data(), q.size(), pos.data(), times.data());
        for (size_t i = 0; i < q.size(); ++i) {
            const Event e = cutRestLocal(anchor, m, q[i]);
            ASSERT_EQ(pos[i].x, e.x.x) << trial << " " << i;
            ASSERT_EQ(pos[i].y, e.x.y) << trial << " " << i;
            ASSERT_EQ(pos[i].z, e.x.z) << trial << " " << i;
            ASSERT_EQ(times[i], e.t) << trial << " " << i;
            branches_negative += anchor.S + dot(shapeOffset(m, q[i]), m.velocity) < 0;
        }
    }
    EXPECT_GT(branches_negative, 100);  // the B < 0 branch was exercised
}
