// Faces that contain the velocity (mesh4d/refine/slide_bound.h): the rim's chord-to-arc bound
// against the distance measured from exact images along random edges (never below it, and tight:
// the test fails when the bound is lowered by a fiftieth: some measured distance comes that close),
// and the refinement that uses it: a box whose four faces contain v, refined to T, within T of the
// exact surface in the geometric two-sided distance (mesh4d/refine/measure.h), at least 0.5 T
// where it refines, and with the faces that contain v refined only along their rims.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "mesh4d/refine/measure.h"
#include "mesh4d/refine/slide_bound.h"
#include "mesh4d/slice.h"
#include "moving_case.h"
#include "test_meshes.h"

using namespace mesh4d;

namespace {

// The distance from p to the segment [a, b].
double segmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 d = b - a;
    const double t = std::clamp(dot(p - a, d) / norm2(d), 0.0, 1.0);
    return norm(p - (a + d * t));
}

using testmesh::unitBox;

}  // namespace

TEST(SlideBound, RimNeverBelowTheMeasuredChordDistanceAndTight) {
    std::mt19937 rng(3107);
    std::uniform_real_distribution<double> u(-1, 1);
    double tightest = 0;
    int measured_cases = 0;
    for (int trial = 0; trial < 600; ++trial) {
        const testcase::MovingCase c = testcase::randomMovingCase(trial, 0.5, 4.5, rng, u);
        const double beta = c.beta, size = c.size, distance = c.distance;
        const Vec3 where = c.where;
        const Motion& m = c.m;
        const ViewSurface& view = c.view;
        const ViewAnchor& anchor = c.anchor;
        const Vec3 E = nowBase(view, m);
        const Vec3 qa = Vec3{u(rng), u(rng), u(rng)} * (0.5 * size), qb = Vec3{u(rng), u(rng), u(rng)} * (0.5 * size);
        const Event ea = cutRestLocal(anchor, m, qa), eb = cutRestLocal(anchor, m, qb);
        const PointTerms ta{shapeOfEvent(m, ea), normMOfEvent(anchor, m, ea)};
        const PointTerms tb{shapeOfEvent(m, eb), normMOfEvent(anchor, m, eb)};
        const EdgeBubble bubble = edgeBubble(m, E, ta, tb);
        const double bound = rimChordError(m, m.beta, ta, tb, bubble.c, bubble.length, bubble.xm_mid);
        // Measured: the exact images of 400 points along the edge against the chord.
        double measured = 0;
        for (int i = 1; i < 400; ++i) {
            const double t = i / 400.0;
            const Vec3 x = cutRestLocal(anchor, m, qa * (1 - t) + qb * t).x;
            measured = std::max(measured, segmentDistance(x, ea.x, eb.x));
        }
        const double rounding = 1e-13 * (norm(where) + size);
        EXPECT_LE(measured, bound + rounding) << "trial " << trial << " b " << beta << " size " << size << " distance "
                                              << distance;
        if (measured > 1e3 * rounding && bound < INFINITY) {
            tightest = std::max(tightest, measured / bound);
            ++measured_cases;
        }
    }
    std::printf("rim bound: %d edges measured, largest measured / bound %.4f\n", measured_cases, tightest);
    EXPECT_GT(measured_cases, 400);
    EXPECT_GT(tightest, 0.98) << "a bound made 2 % low would still pass";
}

TEST(SlideBound, EdgeAlongTheVelocityIsStraight) {
    const Motion m = makeMotion(Kinematics::Lorentz, 0.0, {0, 0, -3}, {0.9, 0, 0});
    const ViewSurface view{ViewKind::PastCone, 3.0, {0, 0, 0}};
    const ViewAnchor anchor = viewAnchor(view, m);
    const Vec3 qa{-0.5, 0.2, 0.1}, qb{0.5, 0.2, 0.1};
    const Event ea = cutRestLocal(anchor, m, qa), eb = cutRestLocal(anchor, m, qb);
    const PointTerms ta{shapeOfEvent(m, ea), normMOfEvent(anchor, m, ea)};
    const PointTerms tb{shapeOfEvent(m, eb), normMOfEvent(anchor, m, eb)};
    const EdgeBubble bubble = edgeBubble(m, nowBase(view, m), ta, tb);
    EXPECT_GT(bubble.c, 1e-3) << "its parametric error is not small";
    EXPECT_EQ(rimChordError(m, m.beta, ta, tb, bubble.c, bubble.length, bubble.xm_mid), 0.0);
    const Vec3 x = cutRestLocal(anchor, m, (qa + qb) * 0.5).x;
    EXPECT_LT(segmentDistance(x, ea.x, eb.x), 1e-12);
}

TEST(SlideBound, BoxWithinTheToleranceAndItsSlidingFacesRefinedOnTheirRims) {
    // Output triangles on the faces containing v (y, z = const: rest normal across x).
    auto sliding = [](const World4D& w, const ApparentMesh& out) {
        size_t n = 0;
        for (uint32_t f : out.source_triangles) {
            const auto& t = w.mesh.triangles[f];
            const auto& p = w.mesh.positions;
            n += cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]).x == 0;
        }
        return n;
    };
    for (Kinematics k : {Kinematics::Lorentz, Kinematics::Galilean})
        for (double beta : {0.5, 0.9, 0.99})
            for (double distance : {2.0, 6.0})
                for (double T : {1e-2, 1e-3}) {
                    const Motion m = makeMotion(k, 0.0, {0, 0, -distance}, {beta, 0, 0});
                    const World4D w = extrude(unitBox(), m, -100, 100, false, false);
                    const ViewSurface view{ViewKind::PastCone, distance, {0, 0, 0}};
                    SliceSettings s;
                    s.tolerance = T;
                    const ApparentMesh out = sliceWorld(w, view, s);
                    s.attribute_tolerance = T;  // the parametric error bounded too: every face refined
                    const ApparentMesh par = sliceWorld(w, view, s);
                    const double geometric = measure::geometricTwoSided(w, view, out);
                    const double parametric = measure::twoSided(w, view, par);
                    const std::string what = "b " + std::to_string(beta) + " distance " + std::to_string(distance) +
                                             " T " + std::to_string(T) + (k == Kinematics::Lorentz ? " Lorentz" : " Galilean");
                    EXPECT_LE(geometric, T) << what;
                    EXPECT_LE(parametric, T) << what << " (with the attribute tolerance)";
                    const size_t a = sliding(w, out), b = sliding(w, par);
                    std::printf("%s: geometric / T %.3f (parametric mode's parametric / T %.3f), triangles %zu (%zu), "
                                "on faces containing v %zu (%zu)\n",
                                what.c_str(), geometric / T, parametric / T, out.triangles.size(), par.triangles.size(), a, b);
                    EXPECT_LE(out.triangles.size(), par.triangles.size()) << what;
                }
}
