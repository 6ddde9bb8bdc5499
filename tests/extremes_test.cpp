// Geometry at the edges, numerical stability: the view grazing a face, a frame at the
// exact instant an object begins or ends existing, an object that exists for a tiny proper time,
// nearly degenerate triangles, and very high and very low frame rates.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <quadmath.h>

#include "mesh4d/robust.h"
#include "mesh4d/slice.h"
#include "pipeline/input/mesh_check.h"
#include "pipeline/input/scene.h"
#include "test_meshes.h"
#include "temp_dir.h"

using namespace mesh4d;

namespace {

// Every output point finite and on the view surface (lab time from the local coordinates).
void expectOnTheCone(const ApparentMesh& out, const ViewSurface& view, double rel, const std::string& what) {
    for (size_t i = 0; i < out.positions.size(); ++i) {
        ASSERT_TRUE(isFinite(out.positions[i]) && std::isfinite(out.emission_times[i])) << what;
        const double dist = norm((out.origin - view.apex) + out.positions[i]);
        const double delay = (view.t_c - out.time_origin) - out.emission_times[i];
        ASSERT_NEAR(dist, delay, rel * std::max(1.0, delay)) << what << " point " << i;
    }
    for (const auto& t : out.triangles) {
        ASSERT_TRUE(t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) << what;
        for (uint32_t k : t) ASSERT_LT(k, out.positions.size()) << what;
    }
}

RestMesh square(double half) {
    RestMesh m;
    m.positions = {{-half, 0, -half}, {half, 0, -half}, {half, 0, half}, {-half, 0, half}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

}  // namespace

// A face seen exactly edge-on: the square lies in the plane y = 0, which holds the camera, so
// every line of sight to it grazes it. Its image stays in that plane, finite, in vertex mode and
// refined, while it passes at 0.9c.
TEST(Extremes, FaceSeenEdgeOn) {
    const RestMesh sq = square(1.0);
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotion(k, 0.0, {-10, 0, -10}, {0.9, 0, 0});
        const World4D w = extrude(sq, m, -200, 200, false, false);
        for (double t_c = 0; t_c <= 30; t_c += 2.5) {
            for (double tol : {0.0, 1e-2}) {
                SliceSettings s;
                s.tolerance = tol;
                const ViewSurface view{ViewKind::PastCone, t_c, {0, 0, 0}};
                const ApparentMesh out = sliceWorld(w, view, s);
                const std::string what = "t_c " + std::to_string(t_c) + " tol " + std::to_string(tol);
                expectOnTheCone(out, view, 1e-13, what);
                EXPECT_EQ(out.limited_triangles, 0u) << what;
                EXPECT_FALSE(out.triangles.empty()) << what;
                for (size_t i = 0; i < out.positions.size(); ++i) EXPECT_EQ(out.absolutePosition(i).y, 0.0) << what;
            }
        }
    }
}

// The cone grazing an edge: an edge on a line through the camera (its points are all seen along
// one line of sight), with the object approaching along that line at extreme speed.
TEST(Extremes, EdgeOnTheLineOfSight) {
    RestMesh tri;
    tri.positions = {{0, 0, 0}, {0, 0, -2}, {0.5, 0, -1}};
    tri.triangles = {{0, 1, 2}};
    for (double gamma : {2.0, 1e3, 1e7}) {
        const Motion m = makeMotionFromGamma(Kinematics::Lorentz, 0.0, {0, 0, -50}, {0, 0, 1}, gamma);
        const World4D w = extrude(tri, m, -1e17, 1e3, false, false);
        const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
        const ApparentMesh out = sliceWorld(w, view);
        expectOnTheCone(out, view, 1e-12, "gamma " + std::to_string(gamma));
        ASSERT_EQ(out.positions.size(), 3u);
        // Both ends of the edge stay on the z axis, stretched by gamma (1 + b) (Lampa, approaching).
        EXPECT_EQ(out.absolutePosition(0).x, 0.0);
        EXPECT_EQ(out.absolutePosition(1).x, 0.0);
        const double b = std::sqrt((gamma - 1) * (gamma + 1)) / gamma;
        EXPECT_NEAR(norm(out.positions[1] - out.positions[0]) / (2 * gamma * (1 + b)), 1.0, 1e-12) << gamma;
    }
}

// A frame at the exact instant the object begins existing: the one vertex whose light leaves at
// that instant is on the cone exactly (the exact sign says 0: inside); the clip points on its
// edges coincide with it and are it, so no zero-area triangle or duplicate point is emitted.
// Then the frames just after, and the frame at the instant the object ends.
TEST(Extremes, FrameAtTheExactStartAndEndOfExistence) {
    RestMesh tet;
    tet.positions = {{0, 0, 0}, {1, 0, -1}, {-1, 0, -1}, {0, 1, -1}};
    tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    // At rest at z = -5 (vertex 0 at distance exactly 5), existing for lab times [0, 10].
    const Motion m = makeMotion(Kinematics::Galilean, 0.0, {0, 0, -5}, {0, 0, 0});
    const World4D w = extrude(tet, m, 0.0, 10.0, true, true);
    {
        const ViewSurface view{ViewKind::PastCone, 5.0, {0, 0, 0}};
        const ApparentMesh out = sliceWorld(w, view);
        expectOnTheCone(out, view, 1e-15, "at the start");
        EXPECT_EQ(out.positions.size(), 1u);  // vertex 0 alone; everything else not yet
        EXPECT_TRUE(out.triangles.empty());
    }
    for (double dt : {1e-12, 1e-6, 0.5}) {
        const ViewSurface view{ViewKind::PastCone, 5.0 + dt, {0, 0, 0}};
        const ApparentMesh out = sliceWorld(w, view);
        expectOnTheCone(out, view, 1e-15, "just after the start");
        EXPECT_EQ(out.triangles.size(), 3u) << dt;  // the three faces at vertex 0, clipped
        const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
        EXPECT_TRUE(t.manifold) << dt;
    }
    {
        // The frame in which vertex 0's last light arrives: 15; the farther vertices still show.
        const ViewSurface view{ViewKind::PastCone, 15.0, {0, 0, 0}};
        const ApparentMesh out = sliceWorld(w, view);
        expectOnTheCone(out, view, 1e-15, "at the end");
        EXPECT_EQ(out.triangles.size(), 4u);
    }
    // The instant model at its start: the hyperplane t = 0 holds the whole cap: all of it shows.
    const Motion mi = makeMotion(Kinematics::Galilean, 0.0, {0, 0, -5}, {0.5, 0, 0});
    const World4D wi = extrude(tet, mi, 0.0, 10.0, true, true);
    const ApparentMesh at_start = sliceWorld(wi, {ViewKind::Hyperplane, 0.0, {}});
    EXPECT_EQ(at_start.triangles.size(), 4u);
    EXPECT_TRUE(sliceWorld(wi, {ViewKind::Hyperplane, std::nextafter(0.0, -1.0), {}}).triangles.empty());
    EXPECT_EQ(sliceWorld(wi, {ViewKind::Hyperplane, 10.0, {}}).triangles.size(), 4u);
    EXPECT_TRUE(sliceWorld(wi, {ViewKind::Hyperplane, std::nextafter(10.0, 11.0), {}}).triangles.empty());
}

// An object that exists for a proper time of 1e-9 s while passing at 0.9c: each frame shows the
// thin band of its surface whose light left in that instant. Every point is on the cone and
// within rounding of the existence interval (its proper time from the inverse map).
TEST(Extremes, TinyLifetime) {
    const RestMesh sphere = testmesh::icosphere(2, 1.0);
    const double life = 1e-9;
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotion(k, 0.0, {-1, 0, -10}, {0.9, 0, 0});
        const World4D w = extrude(sphere, m, 0.0, life, true, true);
        int shown = 0;
        for (double t_c = 8; t_c <= 12; t_c += 0.05) {
            for (double tol : {0.0, 1e-3}) {
                SliceSettings s;
                s.tolerance = tol;
                const ViewSurface view{ViewKind::PastCone, t_c, {0, 0, 0}};
                const ApparentMesh out = sliceWorld(w, view, s);
                expectOnTheCone(out, view, 1e-13, "t_c " + std::to_string(t_c));
                for (size_t i = 0; i < out.positions.size(); ++i) {
                    const double t = out.absoluteTime(i);
                    const Vec3 q = restFromLab(m, out.absolutePosition(i), t);
                    const double tau = properTimeAt(m, q, t);
                    ASSERT_GE(tau, -1e-13) << t_c;
                    ASSERT_LE(tau, life + 1e-13) << t_c;
                }
                if (!out.triangles.empty()) {
                    ++shown;
                    const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
                    EXPECT_TRUE(t.manifold) << t_c;
                }
            }
        }
        EXPECT_GT(shown, 10);
    }
}

// Nearly degenerate triangles (a sliver 1e-12 wide, 1 long) moving at gamma 1e3: finite output
// on the cone, refinement terminates.
TEST(Extremes, NearlyDegenerateTriangles) {
    RestMesh sliver;
    sliver.positions = {{0, 0, 0}, {1, 0, 0}, {0.5, 1e-12, 0}, {0.5, 0, 1e-12}};
    sliver.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotionFromGamma(k, 0.0, {-3, 0, -5}, Vec3{1, 0, 1} / std::sqrt(2.0), 1e3);
        const World4D w = extrude(sliver, m, -1e9, 1e9, false, false);
        for (double tol : {0.0, 1e-3}) {
            SliceSettings s;
            s.tolerance = tol;
            const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
            const ApparentMesh out = sliceWorld(w, view, s);
            expectOnTheCone(out, view, 1e-12, "sliver");
            EXPECT_FALSE(out.triangles.empty());
        }
    }
}

namespace {
std::string writeScene(const std::string& name, const std::string& frames) {
    const auto dir = testio::tempPath() / "apparent_extremes";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const auto path = dir / (name + ".json");
    std::ofstream(path) << R"({"camera": {"position": [0, 0, 0]}, "frames": )" << frames
                        << R"(, "model": "relativistic", "objects": [{"mesh": "tri.obj", "position": [0, 0, -5]}]})";
    return path.string();
}
}  // namespace

// Very high and very low frame rates: a trillion frames per second over a nanosecond, one frame
// per ten days; and a rate the doubles cannot resolve at that time, refused on frames.fps.
TEST(Extremes, FrameRates) {
    apparent::Scene scene;
    const apparent::Status fast = apparent::loadScene(writeScene("fast", R"({"start": 0, "end": 1e-9, "fps": 1e12})"), &scene);
    ASSERT_TRUE(fast.ok) << fast.message;
    EXPECT_EQ(apparent::frameCount(scene.frames), 1000);
    for (long long k = 1; k < 1000; ++k)
        ASSERT_NEAR(apparent::frameTime(scene.frames, k) - apparent::frameTime(scene.frames, k - 1), 1e-12, 1e-24);
    ASSERT_TRUE(apparent::loadScene(writeScene("slow", R"({"start": 0, "end": 1e7, "fps": 1.1574074074074074e-6})"), &scene).ok);
    EXPECT_EQ(apparent::frameCount(scene.frames), 12);  // every 864000 s (10 days) from 0 to 1e7 s
    const apparent::Status late =
        apparent::loadScene(writeScene("late", R"({"start": 1e9, "end": 1.0000001e9, "fps": 1e9})"), &scene);
    ASSERT_FALSE(late.ok);
    EXPECT_NE(late.message.find("frames.fps"), std::string::npos) << late.message;
    EXPECT_NE(late.message.find("closer than doubles resolve"), std::string::npos) << late.message;

    // A motion sampled at 1e12 fps: an object at 0.5c moves 5e-13 ls per frame, and the apparent
    // shift per frame (b / (1 - b) of the frame time head-on: 1e-12) is resolved. (1e-2 ls from
    // the camera, where doubles resolve 3.5e-18 ls.)
    const Motion m = makeMotion(Kinematics::Lorentz, 0.0, {0, 0, -1e-2}, {0, 0, 0.5});
    const World4D w = extrude(testmesh::rod(1e-4, 1e-5), m, -1, 1, false, false);
    const ViewSurface v0{ViewKind::PastCone, 0.0, {0, 0, 0}}, v1{ViewKind::PastCone, 1e-12, {0, 0, 0}};
    const ApparentMesh a0 = sliceWorld(w, v0), a1 = sliceWorld(w, v1);
    const double shift = a1.absolutePosition(0).z - a0.absolutePosition(0).z;
    EXPECT_NEAR(shift / (0.5e-12 / (1 - 0.5)), 1.0, 1e-4);
}

// The 4D-box cull (SliceSettings::cull) skips runs of triangles, never a visible point: a long
// strip of 4000 triangles entering and leaving existence while it passes gives bit-identical
// frames with and without the cull, in every kind of cut, and the cull skips work in most.
TEST(Extremes, CullSkipsOnlyWhatCannotShow) {
    RestMesh strip;
    const int n = 2000;
    for (int i = 0; i <= n; ++i) {
        strip.positions.push_back({0.1 * i, 0, 0});
        strip.positions.push_back({0.1 * i, 1, 0.2 * std::sin(0.05 * i)});
    }
    for (uint32_t i = 0; i < uint32_t(n); ++i) {
        strip.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 1});
        strip.triangles.push_back({2 * i + 1, 2 * i + 2, 2 * i + 3});
    }
    struct Case { Kinematics k; ViewKind view; double tol; };
    const Case cases[] = {{Kinematics::Galilean, ViewKind::Hyperplane, 0.0},
                          {Kinematics::Galilean, ViewKind::PastCone, 0.0},
                          {Kinematics::Lorentz, ViewKind::PastCone, 0.0},
                          {Kinematics::Lorentz, ViewKind::PastCone, 1e-2}};
    for (const Case& c : cases) {
        const Motion m = makeMotion(c.k, 0.0, {-100, 0, -30}, {0.8, 0, 0});
        const World4D w = extrude(strip, m, 20.0, 120.0, true, true);
        ASSERT_EQ(w.chunks.size(), (2u * n + kChunkTriangles - 1) / kChunkTriangles);
        int frames_culled = 0, frames_shown = 0;
        for (double t_c = 0; t_c <= 400; t_c += 4) {
            const ViewSurface view{c.view, t_c, {0, 0, 0}};
            SliceSettings on, off;
            on.tolerance = off.tolerance = c.tol;
            off.cull = false;
            const ApparentMesh a = sliceWorld(w, view, on), b = sliceWorld(w, view, off);
            ASSERT_EQ(a.triangles, b.triangles) << t_c;
            ASSERT_EQ(a.positions.size(), b.positions.size()) << t_c;
            for (size_t i = 0; i < a.positions.size(); ++i) {
                ASSERT_EQ(a.positions[i].x, b.positions[i].x);
                ASSERT_EQ(a.positions[i].y, b.positions[i].y);
                ASSERT_EQ(a.positions[i].z, b.positions[i].z);
            }
            EXPECT_EQ(b.culled_triangles, 0u);
            frames_culled += a.culled_triangles > 0;
            frames_shown += !a.triangles.empty();
        }
        EXPECT_GT(frames_culled, 50) << int(c.view);
        EXPECT_GT(frames_shown, 10) << int(c.view);
    }
}

// The bounding sphere of the apparent shape (for view culling) holds every output point, at
// speeds up to gamma 1e3 and from every direction, in both cuts.
TEST(Extremes, ApparentBoundHoldsTheShape) {
    const RestMesh sphere = testmesh::icosphere(2, 1.0);
    RestMesh shifted = sphere;  // origin off the mesh: the bound is about the origin, not the centre
    for (auto& p : shifted.positions) p = p + Vec3{2, 0, 0};
    int checked = 0;
    for (const RestMesh* mesh : {&sphere, static_cast<const RestMesh*>(&shifted)})
        for (double gamma : {1.0, 2.0, 1e3})
            for (const Vec3& dir : {Vec3{1, 0, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}})
                for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
                    const Motion m = makeMotionFromGamma(k, 0.0, {0, 0, -10}, dir, gamma);
                    const World4D w = extrude(*mesh, m, -1e9, 1e9, false, false);
                    for (ViewKind kind : {ViewKind::PastCone, ViewKind::Hyperplane}) {
                        const ViewSurface view{kind, 0.0, {0, 0, 0}};
                        const ApparentMesh out = sliceWorld(w, view);
                        const BoundingSphere bound = apparentBound(w, view);
                        double reach = 0;
                        for (size_t i = 0; i < out.positions.size(); ++i)
                            reach = std::max(reach, norm(out.absolutePosition(i) - bound.center));
                        EXPECT_LE(reach, bound.radius) << gamma;
                        EXPECT_GT(reach, 0.0);
                        EXPECT_TRUE(std::isfinite(bound.radius));
                        ++checked;
                    }
                }
    EXPECT_EQ(checked, 2 * 3 * 3 * 2 * 2);
}

// Clip points far away: a 1e-3 ls rod, transverse, 1e9 ls from the camera, passing at 0.8c
// (Galilean), seen while its start of existence cuts it. Every output point, clip points included,
// is the image of its rest point to 1e-9 of the rod's length, against the same cut computed
// independently in binary128 from the scene's doubles. (Clip points interpolated between the
// absolute 4D events were off by the rounding of the 1e9 distance, about 1e-7 ls.)
TEST(Extremes, ClipPointsFarAwayStayOnTheSurface) {
    typedef __float128 Quad;
    const double L = 1e-3, D = 1e9, b = 0.8;
    const RestMesh rod = testmesh::rod(L, 1e-4 * L);
    RestMesh transverse = rod;  // along x instead of z
    for (auto& p : transverse.positions) p = {-p.z, p.x, 0};
    // At lab time 0, when it begins existing, the rod is 1e9 ls away, 0.6 of that off the axis:
    // light from its points leaves at t = 0 and arrives at t_c = 1e9 + 0.6 x, so for 0.6 L of
    // camera time the frames see part of it existing and part not yet.
    const Motion m = makeMotion(Kinematics::Galilean, 0.0, {0.6 * D, 0, -0.8 * D}, {b, 0, 0});
    const World4D w = extrude(transverse, m, 0.0, 10.0, true, false);
    int clipped_frames = 0;
    for (double dt = -2e-4; dt <= 8e-4; dt += 2.5e-5) {
        const ViewSurface view{ViewKind::PastCone, D + dt, {0, 0, 0}};
        const ApparentMesh out = sliceWorld(w, view);
        clipped_frames += out.clipped_triangles > 0;
        // Binary128: e = X0 - C + v (t_c - t0) + q, d the positive root, y = C + e - v d. The shape
        // is what is compared: every point relative to the first (the absolute place of the whole
        // carries the rounding of the 1e9 distance, in both computations).
        auto image = [&](const Vec3& q, Quad* y) {
            const Quad ex = Quad(0.6 * D) + Quad(b) * Quad(view.t_c) + Quad(q.x), ey = Quad(q.y),
                       ez = Quad(-0.8 * D) + Quad(q.z);
            const Quad ev = ex * Quad(b), ee = ex * ex + ey * ey + ez * ez, a = 1 - Quad(b) * Quad(b);
            const Quad d = (sqrtq(ev * ev + a * ee) - ev) / a;
            y[0] = ex - Quad(b) * d;
            y[1] = ey;
            y[2] = ez;
        };
        if (out.positions.empty()) continue;
        Quad y0[3];
        image(out.rest_points[0], y0);
        for (size_t i = 1; i < out.positions.size(); ++i) {
            Quad y[3];
            image(out.rest_points[i], y);
            const Vec3 got = out.positions[i] - out.positions[0];
            ASSERT_NEAR(got.x, double(y[0] - y0[0]), 1e-9 * L) << dt << " point " << i;
            ASSERT_NEAR(got.y, double(y[1] - y0[1]), 1e-9 * L) << dt << " point " << i;
            ASSERT_NEAR(got.z, double(y[2] - y0[2]), 1e-9 * L) << dt << " point " << i;
        }
    }
    EXPECT_GT(clipped_frames, 10);
}
