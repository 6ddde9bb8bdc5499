// The geometric distance of mesh4d/refine/measure.h (geometricError, ExactSurface): nearest points, not
// images of the same rest point. Checked where the two measures must differ (a face containing
// the velocity: the slide is within the face, geometric ~0), against a closed form of the exact
// surface that shares no code with it (a plate moving along its normal appears as a hyperboloid
// of revolution with its focus at the camera), against a brute-force lattice of exact points, and
// never above the parametric distance on random scenes.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "mesh4d/refine/measure.h"
#include "mesh4d/refine/subdivide.h"
#include "test_meshes.h"

using namespace mesh4d;

namespace {

using testmesh::unitBox;

// A square plate of half-width W in the plane z = 0, split in 2 triangles, subdivided `levels` times.
RestMesh plate(double W, int levels) {
    RestMesh p;
    p.positions = {{-W, -W, 0}, {W, -W, 0}, {W, W, 0}, {-W, W, 0}};
    p.triangles = {{0, 1, 2}, {0, 2, 3}};
    return subdivideUniform(p, levels);
}

// The distance from P to the surface of revolution r(phi) = D / (cos phi - b) about the z axis
// (phi from the -z axis; focus at the origin), by a dense scan of the meridian and golden-section
// refinement: the apparent surface of the plane z = -D + b t seen from the origin at t = 0
// (emission: -t = r, z = -D + b t = -D - b r, so r cos phi = D + b r).
double hyperboloidDistance(const Vec3& P, double D, double b) {
    const double rho = std::hypot(P.x, P.y), z = P.z;
    auto dist = [&](double phi) {
        const double r = D / (std::cos(phi) - b);
        return std::hypot(r * std::sin(phi) - rho, -r * std::cos(phi) - z);
    };
    const double top = std::acos(b) * 0.999;
    const int n = 20000;
    int best = 0;
    double bd = INFINITY;
    for (int i = 0; i <= n; ++i) {
        const double d = dist(-top + 2 * top * i / n);
        if (d < bd) { bd = d; best = i; }
    }
    double lo = -top + 2 * top * std::max(0, best - 1) / n, hi = -top + 2 * top * std::min(n, best + 1) / n;
    const double g = (std::sqrt(5.0) - 1) / 2;
    for (int it = 0; it < 200; ++it) {
        const double a = hi - g * (hi - lo), c = lo + g * (hi - lo);
        if (dist(a) < dist(c)) hi = c;
        else lo = a;
    }
    return std::min(bd, dist(0.5 * (lo + hi)));
}

}  // namespace

// (i) A box moving along x: its faces y = +-1/2 and z = +-1/2 contain v. Vertex mode slides their points within
// the face (the parametric error is along v), so inside those faces the geometric distance is
// rounding while the parametric one is not.
TEST(GeometricMeasure, FaceContainingTheVelocityIsExactInside) {
    for (Kinematics k : {Kinematics::Lorentz, Kinematics::Galilean}) {
        const World4D w = extrude(unitBox(), makeMotion(k, 0.0, {0, 0, -6}, {0.9, 0, 0}), -100, 100, false, false);
        const ViewSurface view{ViewKind::PastCone, 6.0, {0, 0, 0}};
        const ApparentMesh out = sliceWorld(w, view, {});
        const measure::ExactSurface exact(w, view, out.origin);
        double worst_geometric = 0, least_parametric = INFINITY;
        int samples = 0;
        for (size_t t = 0; t < out.triangles.size(); ++t) {
            const auto& ot = out.triangles[t];
            // Faces y = const and z = const contain v (along x): their corners share y or z.
            const Vec3 r0 = out.rest_points[ot[0]], r1 = out.rest_points[ot[1]], r2 = out.rest_points[ot[2]];
            const bool contains_v = (r0.y == r1.y && r1.y == r2.y) || (r0.z == r1.z && r1.z == r2.z);
            if (!contains_v) continue;
            // Points inside the triangle, away from the face's outline.
            const std::array<double, 3> points[3] = {{1. / 3, 1. / 3, 1. / 3}, {0.4, 0.3, 0.3}, {0.3, 0.4, 0.3}};
            for (const auto& l : points) {
                Vec3 rest{0, 0, 0}, p{0, 0, 0};
                for (int c = 0; c < 3; ++c) {
                    rest += out.rest_points[ot[c]] * l[c];
                    p += out.positions[ot[c]] * l[c];
                }
                const double parametric = norm(exact.exact(rest) - p);
                least_parametric = std::min(least_parametric, parametric);
                const double gd = exact.distance(p, parametric, out.source_triangles[t], &rest);
                worst_geometric = std::max(worst_geometric, gd);
                ++samples;
            }
        }
        EXPECT_EQ(samples, 24) << "8 triangles on the four faces containing v, 3 points each";
        EXPECT_GT(least_parametric, 1e-3) << "the test must be able to fail: vertex mode slides these points";
        EXPECT_LT(worst_geometric, 1e-12) << "inside a face containing v the slide stays in the face (least parametric "
                                          << least_parametric << ")";
        // The whole mesh: the geometric two-sided distance below the parametric one (the other faces).
        const measure::GeometricError g = measure::geometricError(w, view, out);
        EXPECT_LT(g.twoSided(), measure::twoSided(w, view, out));
        EXPECT_GT(g.twoSided(), 0.0);
    }
}

// (ii) A closed form: a plate moving along its normal towards the camera at speed b appears as the
// hyperboloid r = D / (cos phi - b) (focus at the camera), in both kinematics (a flat plate across
// the motion has no contraction, and its points share their lab times). The distance from points
// near the surface (the vertex-mode chords and points pushed off along z) to the exact surface
// equals the distance to that hyperboloid.
TEST(GeometricMeasure, PlateAlongItsNormalMatchesTheHyperboloid) {
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz})
        for (double b : {0.5, 0.9})
            for (double D : {3.0, 20.0}) {
                const World4D w = extrude(plate(1.0, 2), makeMotion(k, 0.0, {0, 0, -D}, {0, 0, b}), -1000, 1000, false, false);
                const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
                const ApparentMesh out = sliceWorld(w, view, {});
                const measure::ExactSurface exact(w, view, out.origin);
                double worst_diff = 0, largest = 0, param_excess = INFINITY;
                for (size_t t = 0; t < out.triangles.size(); ++t) {
                    const auto& ot = out.triangles[t];
                    Vec3 rest{0, 0, 0}, p{0, 0, 0};
                    for (int c = 0; c < 3; ++c) {
                        rest += out.rest_points[ot[c]] / 3.0;
                        p += out.positions[ot[c]] / 3.0;
                    }
                    if (std::max(std::fabs(rest.x), std::fabs(rest.y)) > 0.75) continue;  // away from the rim
                    for (double push : {0.0, 0.01, -0.01}) {
                        const Vec3 pp = p + Vec3{0, 0, push * D};
                        const double parametric = norm(exact.exact(rest) - pp);
                        const double measured = exact.distance(pp, parametric, out.source_triangles[t], &rest);
                        const double closed = hyperboloidDistance(out.origin + pp, D, b);
                        worst_diff = std::max(worst_diff, std::fabs(measured - closed));
                        largest = std::max(largest, closed);
                        param_excess = std::min(param_excess, parametric - closed);
                    }
                }
                EXPECT_GT(largest, 1e-3 * D) << "the points must be off the surface";
                EXPECT_LT(worst_diff, 1e-9 * largest + 1e-12 * D) << "b " << b << " D " << D;
                EXPECT_GE(param_excess, -1e-12 * D) << "the parametric distance is never below the geometric one";
            }
}

// (iii) On random scenes: geometric <= parametric in each direction, and the search finds the
// nearest exact point at least as well as a brute-force lattice of 60 x 60 exact points per input
// triangle (a measured distance above the lattice's minimum would be a missed minimiser).
TEST(GeometricMeasure, NeverAboveParametricAndFindsTheMinimum) {
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int trial = 0; trial < 12; ++trial) {
        const Kinematics k = trial % 2 ? Kinematics::Lorentz : Kinematics::Galilean;
        const double beta = 0.3 + 0.69 * (u(rng) + 1) / 2;
        Vec3 dir{u(rng), u(rng), u(rng)};
        dir = dir / norm(dir);
        const double D = 2.5 + 4 * (u(rng) + 1);
        const RestMesh mesh = trial % 3 == 0 ? unitBox() : testmesh::icosphere(trial % 3 == 1 ? 0 : 1, 1.0);
        const World4D w = extrude(mesh, makeMotion(k, 0.0, {u(rng), u(rng), -D}, dir * beta), -1000, 1000, false, false);
        const ViewSurface view{ViewKind::PastCone, D * u(rng), {0, 0, 0}};
        SliceSettings s;
        if (trial % 4 == 3) s.tolerance = 1e-2;
        const ApparentMesh out = sliceWorld(w, view, s);
        const measure::GeometricError g = measure::geometricError(w, view, out);
        const double rounding = 1e-13 * D;
        EXPECT_LE(g.output_to_exact, measure::outputToExact(w, view, out) + rounding) << "trial " << trial;
        EXPECT_LE(g.exact_to_output, measure::exactToOutput(w, view, out, 8) + rounding) << "trial " << trial;
        EXPECT_LT(g.twoSided(), measure::twoSided(w, view, out)) << "trial " << trial;
        // Brute force at the centroids of the output triangles.
        const measure::ExactSurface exact(w, view, out.origin);
        const int n = 60;
        std::vector<Vec3> lattice;
        for (const auto& t : w.mesh.triangles)
            for (int i = 0; i <= n; ++i)
                for (int j = 0; i + j <= n; ++j) {
                    const Vec3 a = w.mesh.positions[t[0]], b = w.mesh.positions[t[1]], c = w.mesh.positions[t[2]];
                    lattice.push_back(exact.exact(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n)));
                }
        for (size_t t = 0; t < out.triangles.size(); t += 1 + out.triangles.size() / 40) {
            const auto& ot = out.triangles[t];
            Vec3 rest{0, 0, 0}, p{0, 0, 0};
            for (int c = 0; c < 3; ++c) {
                rest += out.rest_points[ot[c]] / 3.0;
                p += out.positions[ot[c]] / 3.0;
            }
            const double parametric = norm(exact.exact(rest) - p);
            const double measured = exact.distance(p, parametric, out.source_triangles[t], &rest);
            double brute = parametric;
            for (const Vec3& x : lattice) brute = std::min(brute, norm(x - p));
            EXPECT_LE(measured, brute + rounding) << "trial " << trial << " triangle " << t;
            // And not below the truth: measured is the distance to an actual exact point.
            EXPECT_GE(measured, 0.0);
        }
    }
}
