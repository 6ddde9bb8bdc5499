// Numerical stress: speeds up to gamma = 1e7 (stated exactly as direction + gamma), sizes from
// 1e-6 to 1e6 light-seconds and distances up to 1e9. Assertions: nothing non-finite anywhere,
// every vertex on the past cone to a relative bound, closed input stays closed, and Lampa's rod
// lengths where they can be computed in closed form.
#include <gtest/gtest.h>

#include "mesh4d/robust.h"
#include "mesh4d/slice.h"
#include "pipeline/input/mesh_check.h"
#include "test_meshes.h"

using namespace mesh4d;

namespace {
// The history over the span the view can see, padded by the object's size, as the pipeline
// builds it (render.cpp): anchors stay near the emission events, whatever the delay.
World4D extrudeSeen(const RestMesh& mesh, const Motion& m, const ViewSurface& view, double size) {
    const ProperTimeSpan span = spanSeen(mesh, m, view, view);
    const double pad = size + 1e-9 * std::max(std::fabs(span.lo), std::fabs(span.hi));
    return extrude(mesh, m, span.lo - pad, span.hi + pad, false, false);
}
}  // namespace

// Lampa's rod at extreme gamma, speed given exactly: 1 - b = 1 / (gamma^2 (1 + b)).
// finite: L/(1-b) = L gamma^2 (1+b) approaching, L/(1+b) receding;
// relativistic: L sqrt((1+b)/(1-b)) = L gamma (1+b) approaching, L / (gamma (1+b)) receding.
TEST(Stress, RodLengthsAtExtremeGamma) {
    const double L = 2.0;
    const RestMesh rod = testmesh::rod(L, 1e-3);
    for (double gamma : {10.0, 1e3, 1e5, 1e7}) {
        const double b = std::sqrt((gamma - 1) * (gamma + 1)) / gamma;
        for (int approach : {1, -1}) {
            for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
                const Motion m = makeMotionFromGamma(k, 0.0, {0, 0, -100}, {0, 0, double(approach)}, gamma);
                const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
                // The history reaches back to the emission: d ~ 100 gamma^2 (1 + b) when approaching.
                const World4D w = extrudeSeen(rod, m, view, L);
                const ApparentMesh out = sliceWorld(w, view);
                ASSERT_EQ(out.positions.size(), 3u);
                for (const auto& p : out.positions) ASSERT_TRUE(isFinite(p));
                const double apparent = norm(out.positions[1] - out.positions[0]);
                double expected;
                if (k == Kinematics::Galilean) expected = approach > 0 ? L * gamma * gamma * (1 + b) : L / (1 + b);
                else expected = approach > 0 ? L * gamma * (1 + b) : L / (gamma * (1 + b));
                // The shape is computed relative to the rod's own apparent origin (lightcone.h,
                // ViewAnchor), so no rounding of the 100 gamma^2 distance enters it.
                const double bound = 1e-12;
                EXPECT_NEAR(apparent / expected, 1.0, bound)
                    << "gamma " << gamma << (approach > 0 ? " approaching " : " receding ")
                    << (k == Kinematics::Galilean ? "finite" : "relativistic");
            }
        }
    }
}

// The sweep: speed x size x distance x direction of motion, vertex mode and refined.
TEST(Stress, SweepStaysFiniteOnTheConeAndClosed) {
    const RestMesh unit = testmesh::icosphere(1, 0.5);
    struct Speed { const char* name; double gamma; };  // gamma 1 = at rest
    const Speed speeds[] = {{"rest", 1.0}, {"0.5c", 1 / std::sqrt(0.75)}, {"gamma 1e3", 1e3}, {"gamma 1e7", 1e7}};
    const Vec3 dirs[] = {{1, 0, 0}, {0, 0, 1}, {0, 0, -1}, Vec3{1, 1, 1} / std::sqrt(3.0)};
    int cases = 0;
    for (double size : {1e-6, 1.0, 1e6}) {
        RestMesh mesh = unit;
        for (auto& p : mesh.positions) p = p * size;
        for (double distance_factor : {10.0, 1e3}) {
            const double distance = std::min(size * distance_factor, 1e9);
            for (const Speed& sp : speeds) {
                for (const Vec3& dir : dirs) {
                    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
                        const Motion m = makeMotionFromGamma(k, 0.0, {0, 0, -distance}, dir, sp.gamma);
                        const ViewSurface view{ViewKind::PastCone, distance, {0, 0, 0}};
                        const World4D w = extrudeSeen(mesh, m, view, size);
                        for (double tol : {0.0, 1e-3 * size}) {
                            if (tol > 0 && sp.gamma > 1e3) continue;  // refined output grows with gamma^2
                            SliceSettings s;
                            s.tolerance = tol;
                            const ApparentMesh out = sliceWorld(w, view, s);
                            ++cases;
                            const std::string what = std::string(sp.name) + " size " + std::to_string(size) +
                                                     " distance " + std::to_string(distance) + " tol " + std::to_string(tol);
                            ASSERT_FALSE(out.triangles.empty()) << what;
                            for (size_t i = 0; i < out.positions.size(); ++i) {
                                ASSERT_TRUE(isFinite(out.positions[i]) && std::isfinite(out.emission_times[i])) << what;
                                // The local coordinates are relative to the object's apparent origin.
                                const double dist = norm((out.origin - view.apex) + out.positions[i]);
                                const double delay = (view.t_c - out.time_origin) - out.emission_times[i];
                                // Relative to the delay, plus the rounding of the inputs' own scale
                                // (|X0 - C| and |v (t_c - t0)| are both `distance` here, and their sum
                                // cancels when the object is now at the camera).
                                ASSERT_NEAR(dist, delay, 1e-12 * std::max(dist, delay) + 1e-15 * (distance + size)) << what;
                            }
                            if (tol == 0) {
                                const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
                                EXPECT_TRUE(t.closed) << what;
                            }
                        }
                    }
                }
            }
        }
    }
    EXPECT_EQ(cases, 3 * 2 * 4 * 2 * (4 + 3));
}

// An object whose history passes through the camera event: the vertex at the camera has zero
// delay (d = 0 at e = 0), and nothing is NaN.
// A sphere that flies through the camera, refined to a tolerance in both models: every frame shows
// part of it (its history spans the whole view), and every output point is where it must be,
// checked by the closed forms directly: on the past cone, t_c - t_e = |x - C|, and on its rest
// point's worldline at its emission time, x = X0 + v t_e + q (Galilean) or X0 + v t_e + q
// contracted by 1 / gamma along v (Lorentz).
TEST(Stress, ObjectThroughTheCamera) {
    const RestMesh sphere = testmesh::icosphere(1, 1.0);
    const Vec3 x0{-5, 0, 0}, v{0.9, 0, 0};
    const double gamma = 1 / std::sqrt(1 - 0.81);
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotion(k, 0.0, x0, v);
        const World4D w = extrude(sphere, m, -100, 100, false, false);
        for (double t_c = 4; t_c <= 8; t_c += 0.25) {
            SliceSettings s;
            s.tolerance = 1e-3;
            const ApparentMesh out = sliceWorld(w, {ViewKind::PastCone, t_c, {0, 0, 0}}, s);
            ASSERT_FALSE(out.triangles.empty()) << t_c;
            ASSERT_EQ(out.rest_points.size(), out.positions.size());
            for (size_t i = 0; i < out.positions.size(); ++i) {
                const Vec3 x = out.absolutePosition(i);
                const double t_e = out.absoluteTime(i);
                ASSERT_TRUE(isFinite(x) && std::isfinite(t_e)) << t_c;
                ASSERT_NEAR(t_c - t_e, norm(x), 1e-12 * (1 + t_c)) << t_c << " vertex " << i;
                const Vec3 q = out.rest_points[i];
                const Vec3 carried = k == Kinematics::Lorentz ? Vec3{q.x / gamma, q.y, q.z} : q;
                ASSERT_LT(norm(x - (x0 + v * t_e + carried)), 1e-12 * (1 + t_c)) << t_c << " vertex " << i;
            }
        }
    }
}

// Relative accuracy far from the camera (sizes 1e-6..1e6 at distances up to 1e9): a rod on
// the line of sight has the distance-independent apparent lengths of Lampa, L/(1-b) or L/(1+b)
// (finite) and L sqrt((1+b)/(1-b)) or L sqrt((1-b)/(1+b)) (relativistic). The shape is computed
// relative to the object's origin (lightcone.h, ViewAnchor), so it keeps ~1e-12 relative
// accuracy where absolute doubles (ulp 1.2e-7 at 1e9) would leave nothing of a 1e-6 rod.
TEST(Stress, SmallRodFarAwayKeepsItsShape) {
    int cases = 0;
    for (double L : {1e-6, 1e-3, 1.0}) {
        const RestMesh rod = testmesh::rod(L, 1e-3 * L);
        for (double distance : {1e3, 1e6, 1e9}) {
            for (double b : {0.5, 0.9}) {
                for (int approach : {1, -1}) {
                    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
                        // The rod's origin is at -distance on the z axis now (t_c = distance, t0 = 0).
                        const Motion m = makeMotion(k, 0.0, {0, 0, -distance - approach * b * distance},
                                                    {0, 0, approach * b});
                        const ViewSurface view{ViewKind::PastCone, distance, {0, 0, 0}};
                        const World4D w = extrudeSeen(rod, m, view, L);
                        const ApparentMesh out = sliceWorld(w, view);
                        ASSERT_EQ(out.positions.size(), 3u);
                        const double apparent = norm(out.positions[1] - out.positions[0]);
                        double expected;
                        if (k == Kinematics::Galilean) expected = approach > 0 ? L / (1 - b) : L / (1 + b);
                        else expected = L * (approach > 0 ? std::sqrt((1 + b) / (1 - b)) : std::sqrt((1 - b) / (1 + b)));
                        EXPECT_NEAR(apparent / expected, 1.0, 1e-11)
                            << "L " << L << " distance " << distance << " b " << b << (approach > 0 ? " approaching" : " receding");
                        // And it is where it should be: the origin's light delay d solves the cone equation.
                        const double delay = view.t_c - out.time_origin;
                        EXPECT_NEAR(norm(out.origin - view.apex) / delay, 1.0, 1e-14);
                        ++cases;
                    }
                }
            }
        }
    }
    EXPECT_EQ(cases, 3 * 3 * 2 * 2 * 2);
}
