// Motion beyond uniform (mesh4d/motion/worldline.h): spinning and rolling bodies, against
// closed forms and against a computation written here that shares nothing with the code under
// test (its own rotation, its own Lorentz boost as a matrix, its own root search by bisection).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/light_factors.h"
#include "mesh4d/ray4d.h"
#include "mesh4d/slice.h"
#include "slab_rays.h"
#include "test_meshes.h"
#include "mesh4d/motion/worldline.h"
#include "quiet_stage.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"
#include "pipeline/trace/raytrace.h"

#include "temp_dir.h"

using mesh4d::Event;
using mesh4d::Motion;
using mesh4d::Vec3;

namespace {

using testmesh::cylinder;

constexpr double kPi = 3.14159265358979323846;

mesh4d::ViewSurface cone(double t_c, const Vec3& apex) {
    mesh4d::ViewSurface v;
    v.kind = mesh4d::ViewKind::PastCone;
    v.t_c = t_c;
    v.apex = apex;
    return v;
}

// Independent kinematics: the centre-frame helix of q (rotation about z by w s written out), the
// Lorentz boost with velocity (b, 0, 0) as a matrix about the origin event (t0 = 0, X0), and the
// crossing with the past cone by plain bisection on s.
struct Independent {
    double b = 0, w = 0;
    Vec3 x0;
    Event event(double s, const Vec3& q) const {
        const double c = std::cos(w * s), sn = std::sin(w * s);
        const double yx = c * q.x - sn * q.y, yy = sn * q.x + c * q.y, yz = q.z;
        const double g = 1 / std::sqrt(1 - b * b);
        return {g * (s + b * yx), {x0.x + g * (yx + b * s), x0.y + yy, x0.z + yz}};
    }
    Event cross(double t_c, const Vec3& C, const Vec3& q) const {
        auto h = [&](double s) {
            const Event e = event(s, q);
            return (t_c - e.t) - std::hypot(e.x.x - C.x, e.x.y - C.y, e.x.z - C.z);
        };
        double lo = -1e3, hi = 1e3;
        for (int i = 0; i < 200; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (h(mid) > 0) lo = mid; else hi = mid;
        }
        return event(0.5 * (lo + hi), q);
    }
};

Motion spinMotion(mesh4d::Kinematics k, const Vec3& origin, const Vec3& v, const Vec3& w) {
    Motion m = mesh4d::makeMotion(k, 0, origin, v);
    m.angular_velocity = w;
    return m;
}

}  // namespace

// The crossing search against the independent bisection, a rolling wheel at b = 0.9 seen from the side.
TEST(Motion, CrossingMatchesAnIndependentBisection) {
    const Independent ind{0.9, -0.9, {-3, 0, 0}};
    const Motion m = spinMotion(mesh4d::Kinematics::Lorentz, ind.x0, {0.9, 0, 0}, {0, 0, -0.9});
    for (double t_c : {-2.0, 0.0, 3.5, 10.0})
        for (const Vec3& q : {Vec3{1, 0, 0}, Vec3{0, -1, 0.05}, Vec3{-0.7, 0.7, -0.05}, Vec3{0, 0, 0}}) {
            const Vec3 C{0, 0, 5};
            const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(cone(t_c, C), m, q);
            ASSERT_TRUE(c.ok);
            const Event e = ind.cross(t_c, C, q);
            EXPECT_NEAR(c.event.t, e.t, 1e-12 * (1 + std::fabs(e.t)));
            EXPECT_NEAR(c.event.x.x, e.x.x, 1e-12 * (1 + std::fabs(e.x.x)));
            EXPECT_NEAR(c.event.x.y, e.x.y, 1e-12);
            EXPECT_NEAR(c.event.x.z, e.x.z, 1e-12);
            // On the cone, to rounding.
            EXPECT_NEAR(t_c - c.event.t, mesh4d::norm(c.event.x - C), 1e-13 * (t_c - c.event.t));
        }
}

// Uniform motion keeps its closed forms: the worldline functions hand it to motion.h and lightcone.h.
TEST(Motion, UniformMotionIsTheClosedForm) {
    const Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 1, {2, 0, -3}, {0.6, 0.2, 0});
    const Vec3 q{0.3, -0.4, 0.5};
    const mesh4d::ViewSurface v = cone(4, {0, 0, 1});
    const Event closed = mesh4d::cutRestWorldline(v, m, mesh4d::nowBase(v, m), q);
    const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(v, m, q);
    EXPECT_EQ(c.event.t, closed.t);
    EXPECT_EQ(c.event.x, closed.x);
    const Event e = mesh4d::worldlineEvent(m, 0.7, q), l = mesh4d::labFromRest(m, 0.7, q);
    EXPECT_EQ(e.t, l.t);
    EXPECT_EQ(e.x, l.x);
    // The general Doppler form (d tau/ds over the received rate) equals 1 / (g (1 - v.n)).
    const double d_general = mesh4d::worldlineDoppler(m, v.kind, v.apex, c.s, q, c.event.x);
    const double d_uniform = mesh4d::dopplerFactor(m, v.kind, v.apex, c.event.x);
    EXPECT_NEAR(d_general, d_uniform, 1e-14 * d_uniform);
}

// A cylinder spinning about its own axis, centre at rest, camera on the axis at distance D: every
// output vertex lies on the rest surface, and the vertex at radius r, angle phi0 appears at angle
// phi0 + w (t_c - sqrt(D^2 + r^2)) (the spoke spiral), in vertex mode, to 1e-9 relative.
TEST(Motion, SpinningCylinderKeepsItsShapeAndDrawsTheSpokeSpiral) {
    const double r = 1, h = 0.2, w = 0.9, D = 4;
    const int n = 48;
    const mesh4d::RestMesh mesh = cylinder(r, h, n);
    const Motion m = spinMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {0, 0, 0}, {0, 0, w});
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -100, 100, false, false);
    for (double t_c : {0.0, 1.3, 7.25}) {
        const mesh4d::ViewSurface view = cone(t_c, {0, 0, D});
        const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
        ASSERT_EQ(out.positions.size(), mesh.positions.size());
        ASSERT_EQ(out.triangles.size(), mesh.triangles.size());
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const Vec3 p = out.absolutePosition(i);
            const Vec3& q = mesh.positions[i];
            EXPECT_NEAR(std::hypot(p.x, p.y), std::hypot(q.x, q.y), 1e-12);  // on the rest surface
            EXPECT_NEAR(p.z, q.z, 1e-15);
            if (i >= size_t(2 * n)) continue;
            const double rho = std::hypot(q.x, q.y), z = q.z;
            const double phi0 = std::atan2(q.y, q.x);
            const double expected = phi0 + w * (t_c - std::hypot(D - z, rho));
            const double got = std::atan2(p.y, p.x);
            const double diff = std::remainder(got - expected, 2 * kPi);
            EXPECT_LE(std::fabs(diff), 1e-9 * std::fabs(expected) + 1e-15) << "vertex " << i << " t_c " << t_c;
            EXPECT_NEAR(out.absoluteTime(i), t_c - std::hypot(D - z, rho), 1e-13 * (1 + std::fabs(t_c)));
        }
    }
}

// Rim clock: proper_time of a rim vertex advances by dt / gamma(w r) per lab second (centre at rest,
// camera on the axis, so the delay is constant), and the transverse Doppler factor is 1 / gamma.
TEST(Motion, RimClockRunsSlowByGammaOfTheRimSpeed) {
    const double r = 1, w = 0.8, D = 3;
    const mesh4d::RestMesh mesh = cylinder(r, 0.1, 24);
    const Motion m = spinMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {0, 0, 0}, {0, 0, w});
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -100, 100, false, false);
    const double inv_gamma = std::sqrt(1 - (w * r) * (w * r));
    double last = 0;
    for (int k = 0; k < 4; ++k) {
        const double t_c = 2.0 + 0.5 * k;
        const mesh4d::ViewSurface view = cone(t_c, {0, 0, D});
        mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
        mesh4d::addLightFactors(world, view, &out);
        const double t_emit = t_c - std::hypot(D + 0.1, r);  // vertex 0: z = -0.1
        EXPECT_NEAR(out.proper_time[0], t_emit * inv_gamma, 1e-12);
        EXPECT_NEAR(out.doppler[0], inv_gamma, 1e-12);
        EXPECT_NEAR(out.proper_time[2 * 24], (t_c - (D + 0.1)), 1e-12);  // the hub's clock: the centre's
        if (k > 0) {
            EXPECT_NEAR(out.proper_time[0] - last, 0.5 * inv_gamma, 1e-12);
        }
        last = out.proper_time[0];
    }
}

// Rolling wheel (w R = |v| in the centre frame, b = 0.9): the contact point's lab velocity is 0 and
// the top's 2v / (1 + v^2), from the worldlines (finite differences of the independent events too);
// the frame-by-frame output matches the independent boost of the centre-frame helix to 1e-9; and
// the rim clock reads t'' sqrt(1 - w^2 rho^2) at the emission event's centre-frame time t''.
TEST(Motion, RollingWheelContactAtRestTopAtTwoVOverOnePlusVSquared) {
    const double b = 0.9, R = 1;
    const Independent ind{b, -b / R, {-4, 0, 0}};
    const Motion m = spinMotion(mesh4d::Kinematics::Lorentz, ind.x0, {b, 0, 0}, {0, 0, -b / R});
    for (double s : {0.0, 1.7, -3.2}) {
        // The rest point at the bottom (0, -R) at centre-frame time s, and the one at the top.
        const double a = -ind.w * s;  // q = R(-w s) of the point at the bottom (top) at time s
        const Vec3 q_bottom{R * std::sin(a), -R * std::cos(a), 0};
        const Vec3 q_top{-R * std::sin(a), R * std::cos(a), 0};
        const Vec3 v_bottom = mesh4d::worldlineVelocity(m, s, q_bottom);
        EXPECT_NEAR(mesh4d::norm(v_bottom), 0, 1e-15);
        const Vec3 v_top = mesh4d::worldlineVelocity(m, s, q_top);
        EXPECT_NEAR(v_top.x, 2 * b / (1 + b * b), 1e-15);
        EXPECT_NEAR(v_top.y, 0, 1e-15);
        // The same from the independent events by central differences.
        const double ds = 1e-5;
        const Event e0 = ind.event(s - ds, q_top), e1 = ind.event(s + ds, q_top);
        EXPECT_NEAR((e1.x.x - e0.x.x) / (e1.t - e0.t), 2 * b / (1 + b * b), 1e-8);
        const Event c0 = ind.event(s - ds, q_bottom), c1 = ind.event(s + ds, q_bottom);
        EXPECT_NEAR((c1.x.x - c0.x.x) / (c1.t - c0.t), 0, 1e-8);
    }
    // Frames: vertex mode output against the independent crossing of every rest vertex.
    const mesh4d::RestMesh mesh = cylinder(R, 0.05, 32);
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -100, 100, false, false);
    const Vec3 C{0, 0.5, 5};
    for (double t_c : {2.0, 5.0, 8.5}) {
        const mesh4d::ViewSurface view = cone(t_c, C);
        mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
        mesh4d::addLightFactors(world, view, &out);
        ASSERT_EQ(out.positions.size(), mesh.positions.size());
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const Vec3& q = mesh.positions[i];
            const Event e = ind.cross(t_c, C, q);
            const Vec3 p = out.absolutePosition(i);
            EXPECT_NEAR(p.x, e.x.x, 1e-9);
            EXPECT_NEAR(p.y, e.x.y, 1e-9);
            EXPECT_NEAR(p.z, e.x.z, 1e-9);
            EXPECT_NEAR(out.absoluteTime(i), e.t, 1e-9);
            // t'' of the emission event: the independent inverse of t = g (s + b y_x), by bisection.
            double lo = -1e3, hi = 1e3;
            for (int it = 0; it < 200; ++it) {
                const double mid = 0.5 * (lo + hi);
                if (ind.event(mid, q).t < e.t) lo = mid; else hi = mid;
            }
            const double t2 = 0.5 * (lo + hi);
            const double rho = std::hypot(q.x, q.y);
            EXPECT_NEAR(out.proper_time[i], t2 * std::sqrt(1 - b * b * rho * rho), 1e-9);
        }
    }
}

// No NaN up to a rim speed of 1 - 1e-9, in every model, centre at rest and moving at 0.9.
TEST(Motion, NoNaNUpToRimSpeedOneMinus1e9) {
    const mesh4d::RestMesh mesh = cylinder(1, 0.1, 16);
    for (double v : {0.0, 0.9})
        for (mesh4d::Kinematics k : {mesh4d::Kinematics::Lorentz, mesh4d::Kinematics::Galilean})
            for (mesh4d::ViewKind kind : {mesh4d::ViewKind::PastCone, mesh4d::ViewKind::Hyperplane}) {
                if (k == mesh4d::Kinematics::Galilean && kind == mesh4d::ViewKind::PastCone && v > 0) continue;  // refused: > c
                const Motion m = spinMotion(k, {0, 0, -3}, {v, 0, 0}, {0, 0, 1 - 1e-9});
                const mesh4d::World4D world = mesh4d::extrude(mesh, m, -1e3, 1e3, false, false);
                for (double t_c : {0.0, 2.5, 40.0}) {
                    mesh4d::ViewSurface view = cone(t_c, {0, 0, 1});
                    view.kind = kind;
                    mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
                    mesh4d::addLightFactors(world, view, &out);
                    ASSERT_EQ(out.positions.size(), mesh.positions.size());
                    for (size_t i = 0; i < out.positions.size(); ++i) {
                        ASSERT_TRUE(mesh4d::isFinite(out.positions[i]));
                        ASSERT_TRUE(std::isfinite(out.emission_times[i]));
                        ASSERT_TRUE(std::isfinite(out.doppler[i]) && out.doppler[i] > 0);
                        ASSERT_TRUE(std::isfinite(out.proper_time[i]));
                    }
                }
            }
}

// The instant model carries the spin (Galilean): x = X0 + R(w (t - t0)) q + v (t - t0) at t = t_c.
TEST(Motion, InstantModelShowsTheCarriedSpin) {
    const mesh4d::RestMesh mesh = cylinder(1, 0.1, 8);
    const Motion m = spinMotion(mesh4d::Kinematics::Galilean, {1, 2, 3}, {0.5, 0, 0}, {0, 0, 2});
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -10, 10, false, false);
    mesh4d::ViewSurface view = cone(1.5, {0, 0, 0});
    view.kind = mesh4d::ViewKind::Hyperplane;
    const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
    for (size_t i = 0; i < out.positions.size(); ++i) {
        const Vec3& q = mesh.positions[i];
        const double a = 2 * 1.5, c = std::cos(a), s = std::sin(a);
        const Vec3 expected{1 + c * q.x - s * q.y + 0.75, 2 + s * q.x + c * q.y, 3 + q.z};
        const Vec3 p = out.absolutePosition(i);
        EXPECT_NEAR(p.x, expected.x, 1e-14 * 8);
        EXPECT_NEAR(p.y, expected.y, 1e-14 * 8);
        EXPECT_NEAR(p.z, expected.z, 1e-14 * 8);
    }
}

// An object that begins existing: the cap at centre-frame time s = 0 is flat (affine in q), and the
// clip points lie on the true worldlines (their emission time is the crossing of their own).
TEST(Motion, ExistenceCapClipsOnTheTrueWorldlines) {
    const mesh4d::RestMesh mesh = cylinder(1, 0.1, 32);
    const Motion m = spinMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {0.5, 0, 0}, {0, 0, 0.7});
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, 0, 100, true, false);
    // A frame whose cone meets the cap: part of the wheel has begun existing.
    const mesh4d::ViewSurface view = cone(3.2, {-3, 0, 0});
    const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
    ASSERT_GT(out.clipped_triangles, 0u);
    for (size_t i = 0; i < out.positions.size(); ++i) {
        const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(view, m, out.rest_points[i]);
        EXPECT_GE(c.s, -1e-9);  // never before the object exists
        EXPECT_NEAR(mesh4d::norm(out.absolutePosition(i) - c.event.x), 0, 1e-12);
    }
}

// The stage refuses what a spin cannot be: a vertex at or above c (file, field, speed), a tolerance
// other than vertex mode, a moving camera, a spinning mirror; the raytracer refuses spin.
TEST(Motion, StageRefusalsNameFileFieldAndSpeed) {
    const std::string dir = testio::processTempDir();
    auto write = [&](const std::string& name, const std::string& body) {
        const std::string path = dir + "/" + name;
        FILE* f = std::fopen(path.c_str(), "w");
        std::fputs(body.c_str(), f);
        std::fclose(f);
        return path;
    };
    const std::string mesh = std::string(APPARENT_SOURCE_DIR) + "/data/meshes/wheel.obj";
    auto scene = [&](const std::string& object_extra, const std::string& top_extra) {
        return "{\"camera\": {\"position\": [0, 0, 5]" + std::string(top_extra.empty() ? "" : ", ") + top_extra +
               "}, \"frames\": {\"start\": 0, \"end\": 1, \"fps\": 2}, \"tolerance\": \"vertex\", "
               "\"objects\": [{\"mesh\": \"" + mesh + "\"" + object_extra + "}]}";
    };
    apparent::Stage stage;
    std::string error;
    {
        apparent::Stage huge;  // a mesh of one point at the origin moves at 0 whatever w: |w| is bounded
        std::string point = scene(", \"scale\": 1e-300, \"angular_velocity\": [0, 0, 1e300]", "");
        EXPECT_FALSE(apparent::loadQuietStage(write("huge.json", point), &huge, &error));
        EXPECT_NE(error.find("huge.json: objects[0].angular_velocity: |angular_velocity| = 1.0000000000000001e+300 must be <= 1e12 rad/s"),
                  std::string::npos)
            << error;
    }
    const std::string fast = write("fast.json", scene(", \"angular_velocity\": [0, 0, 1.0]", ""));
    EXPECT_FALSE(apparent::loadQuietStage(fast, &stage, &error));
    EXPECT_NE(error.find("fast.json: objects[0].angular_velocity: a vertex would move at 1"), std::string::npos) << error;
    const std::string ok = write("ok.json", scene(", \"angular_velocity\": [0, 0, 0.99]", ""));
    apparent::Stage s1;
    EXPECT_TRUE(apparent::loadQuietStage(ok, &s1, &error)) << error;
    // Finite: the carried rim adds to the velocity in the lab.
    const std::string finite = write("finite.json", scene(", \"velocity\": [0.5, 0, 0], \"angular_velocity\": [0, 0, 0.6]", ""));
    apparent::Stage s2;
    EXPECT_TRUE(apparent::loadQuietStage(finite, &s2, &error, {apparent::Model::Relativistic})) << error;
    EXPECT_FALSE(apparent::loadQuietStage(finite, &s2, &error, {apparent::Model::Finite}));
    EXPECT_NE(error.find("a vertex would move at 1.1"), std::string::npos) << error;
    apparent::Stage s3;
    EXPECT_TRUE(apparent::loadQuietStage(finite, &s3, &error, {apparent::Model::Instant})) << error;
    apparent::Stage s4;
    const std::string moving = write("moving.json", scene(", \"angular_velocity\": [0, 0, 0.5]", "\"velocity\": [0.1, 0, 0]"));
    EXPECT_FALSE(apparent::loadQuietStage(moving, &s4, &error));
    EXPECT_NE(error.find("angular_velocity: a spinning object needs a camera at rest"), std::string::npos) << error;
    apparent::Stage s5;
    std::string tol = scene(", \"angular_velocity\": [0, 0, 0.5]", "");
    tol.replace(tol.find("\"vertex\""), 8, "\"1e-3\"");
    EXPECT_TRUE(apparent::loadQuietStage(write("tol.json", tol), &s5, &error)) << error;  // worldline_refine.h
    apparent::Stage s5b;
    std::string tol_exists = scene(", \"angular_velocity\": [0, 0, 0.5], \"exists\": [-5, 100]", "");
    tol_exists.replace(tol_exists.find("\"vertex\""), 8, "\"1e-3\"");
    EXPECT_FALSE(apparent::loadQuietStage(write("tol_exists.json", tol_exists), &s5b, &error));
    EXPECT_NE(error.find("angular_velocity: a spinning object that begins or ends existing (exists) is cut in vertex mode only"),
              std::string::npos)
        << error;
    apparent::Stage s5c;  // an existence far outside the frames makes no cap: the tolerance holds
    std::string tol_always = scene(", \"angular_velocity\": [0, 0, 0.5], \"exists\": [-1e30, 1e30]", "");
    tol_always.replace(tol_always.find("\"vertex\""), 8, "\"1e-3\"");
    EXPECT_TRUE(apparent::loadQuietStage(write("tol_always.json", tol_always), &s5c, &error)) << error;
    {
        apparent::Stage s5d;  // seen in a mirror: its reflections' worlds may be clipped, so refused
        std::string tol_mirror = scene(", \"angular_velocity\": [0, 0, 0.5]}, {\"mesh\": \"" + std::string(APPARENT_SOURCE_DIR) +
                                           "/data/meshes/backdrop.obj\", \"mirror\": true, \"position\": [0, 0, -3]", "");
        tol_mirror.replace(tol_mirror.find("\"vertex\""), 8, "\"1e-3\"");
        EXPECT_FALSE(apparent::loadQuietStage(write("tol_mirror.json", tol_mirror), &s5d, &error));
        EXPECT_NE(error.find("tol_mirror.json: objects[0].angular_velocity: a spinning object seen in a mirror is cut in vertex mode only"),
                  std::string::npos)
            << error;
    }
    apparent::Stage s6;
    EXPECT_FALSE(apparent::loadQuietStage(write("mirror.json", scene(", \"mirror\": true, \"angular_velocity\": [0, 0, 0.5]", "")),
                                          &s6, &error));
    EXPECT_NE(error.find("angular_velocity: a mirror must be at rest (angular_velocity"), std::string::npos) << error;
}

// The shipped scenes load and render their first frame in the scene's model; the rocket's measured
// length in the contracted model at lab time 4 s is the Born-rigid closed form: tail and nose on the
// hyperbolas (x + 1/a)^2 - t^2 = xi^2, xi = 1 and 3 (a = 0.5, tail and nose 1 ls from the origin),
// so sqrt(9 + 16) - sqrt(1 + 16).
TEST(Motion, ShippedScenesBuildAndCut) {
    {
        apparent::Stage stage;
        std::string error;
        ASSERT_TRUE(apparent::loadQuietStage("data/scenes/rocket.json", &stage, &error, {apparent::Model::Contracted}))
            << error;
        const mesh4d::World4D world = apparent::buildWorld(stage.objects[0], apparent::Model::Contracted, stage.scene,
                                                           stage.first, stage.last_excl - 1);
        const mesh4d::ApparentMesh out =
            mesh4d::sliceWorld(world, apparent::viewAt(stage.scene, apparent::Model::Contracted, 4.0 + 6.0));
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < out.positions.size(); ++i) {
            lo = std::min(lo, out.absolutePosition(i).x);
            hi = std::max(hi, out.absolutePosition(i).x);
        }
        EXPECT_NEAR(hi - lo, 5 - std::sqrt(17.0), 1e-12);
    }
    for (const char* name : {"data/scenes/rolling_wheel.json", "data/scenes/spinning_wheel.json", "data/scenes/rocket.json"}) {
        apparent::Stage stage;
        std::string error;
        ASSERT_TRUE(apparent::loadQuietStage(name, &stage, &error)) << error;
        const mesh4d::World4D world =
            apparent::buildWorld(stage.objects[0], stage.scene.model, stage.scene, stage.first, stage.last_excl - 1);
        const mesh4d::ApparentMesh out =
            mesh4d::sliceWorld(world, apparent::viewForFrame(stage.scene, stage.scene.model, stage.first));
        EXPECT_EQ(out.positions.size(), stage.objects[0].rest.positions.size()) << name;
    }
}

// ---- Constant proper acceleration (Born-rigid, from t0 on) ----

namespace {

Motion accelMotion(mesh4d::Kinematics k, const Vec3& v, const Vec3& a) {
    Motion m = mesh4d::makeMotion(k, 0, {0, 0, 0}, v);
    m.acceleration = a;
    return m;
}

}  // namespace

// Hyperbolic motion from rest: the origin's retarded event for a camera behind it on the line of
// motion is the closed form of x(t) = (sqrt(1 + (a t)^2) - 1)/a: with k = t_c - L + 1/a (camera at
// x = -L), t_e = k/2 - 1/(2 a^2 k); its clock reads asinh(a t_e)/a. Off the line, against a
// bisection on that x(t).
TEST(Motion, HyperbolicRetardedEventAndProperTimeAreTheClosedForms) {
    const double a = 0.7, L = 3;
    const Motion m = accelMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {a, 0, 0});
    auto x_of = [&](double t) { return (std::sqrt(1 + (a * t) * (a * t)) - 1) / a; };
    for (double t_c : {3.5, 5.0, 12.0, 40.0}) {
        const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(cone(t_c, {-L, 0, 0}), m, {0, 0, 0});
        ASSERT_TRUE(c.ok);
        const double k = t_c - L + 1 / a;
        const double t_e = k / 2 - 1 / (2 * a * a * k);
        ASSERT_GT(t_e, 0);
        EXPECT_NEAR(c.event.t, t_e, 1e-13 * t_c);
        EXPECT_NEAR(c.event.x.x, x_of(t_e), 1e-13 * t_c);
        EXPECT_NEAR(mesh4d::worldlineProperTime(m, c.s, {0, 0, 0}), std::asinh(a * t_e) / a, 1e-13 * t_c);
        // Off the line of motion.
        const Vec3 C{1, 4, -2};
        const mesh4d::WorldlineCrossing o = mesh4d::crossWorldline(cone(t_c, C), m, {0, 0, 0});
        double lo = -100, hi = t_c;
        for (int i = 0; i < 200; ++i) {
            const double mid = 0.5 * (lo + hi);
            const double h = (t_c - mid) - std::hypot(mid > 0 ? x_of(mid) - C.x : -C.x, C.y, C.z);
            if (h > 0) lo = mid; else hi = mid;
        }
        EXPECT_NEAR(o.event.t, 0.5 * (lo + hi), 1e-12 * t_c);
    }
    // Before t0 the object rests (velocity 0): an early frame sees it at the origin.
    const mesh4d::WorldlineCrossing early = mesh4d::crossWorldline(cone(1.0, {-L, 0, 0}), m, {0, 0, 0});
    EXPECT_DOUBLE_EQ(early.event.t, 1.0 - L);
    EXPECT_EQ(early.event.x, (Vec3{0, 0, 0}));
}

// Born-rigid: the point at q.k = d moves on the hyperbola (x + 1/a)^2 - t^2 = (1/a + d)^2 (proper
// acceleration 1/(1/a + d)), its clock runs at (1 + a d) of the origin's, and the distance between
// points at one instant of the momentary rest frame stays their rest distance.
TEST(Motion, BornRigidBodyKeepsItsRestLength) {
    const double a = 0.5;
    const Motion m = accelMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {a, 0, 0});
    for (double d : {-1.5, -0.3, 0.0, 2.0}) {
        const Vec3 q{d, 0.25, 0};
        for (double s : {0.3, 2.0, 6.0}) {
            const Event e = mesh4d::worldlineEvent(m, s, q);
            const double xi = 1 / a + d;
            EXPECT_NEAR((e.x.x + 1 / a) * (e.x.x + 1 / a) - e.t * e.t, xi * xi, 1e-11 * xi * xi * std::cosh(a * s));
            EXPECT_EQ(e.x.y, 0.25);
            EXPECT_NEAR(mesh4d::worldlineProperTime(m, s, q), (1 + a * d) * s, 1e-14 * s);
            // The momentary rest frame at origin time s is the line through the hyperbolas' centre
            // (x, t) = (-1/a, 0) at rapidity a s: the two points at one s lie on it, their distance
            // along it (invariant interval) is the rest distance.
            const Event o = mesh4d::worldlineEvent(m, s, {0, 0, 0});
            const double interval = std::sqrt((e.x.x - o.x.x) * (e.x.x - o.x.x) - (e.t - o.t) * (e.t - o.t));
            EXPECT_NEAR(interval, std::fabs(d), 1e-12 * (1 + std::cosh(a * s)));
        }
    }
}

// With a start velocity the start-frame hyperbola is boosted: the origin's lab worldline against a
// boost matrix applied here, and the crossing against a bisection on it; the Galilean carry follows
// the same lab path with every point at the same lab offset.
TEST(Motion, AcceleratedFromAMovingStartAgainstAnIndependentBoost) {
    const double a = 0.4, b = 0.6, g = 1 / std::sqrt(1 - b * b);
    const Motion m = accelMotion(mesh4d::Kinematics::Lorentz, {0, b, 0}, {a, 0, 0});
    auto lab = [&](double s, double d) {  // origin (d = 0) or a point at q.k = d, start frame -> lab (boost along y)
        const double xi = 1 / a + d;
        const double T = s > 0 ? xi * std::sinh(a * s) : s;
        const double X = s > 0 ? d + xi * (std::cosh(a * s) - 1) : d;
        return Event{g * T, {X, g * b * T, 0}};
    };
    for (double s : {-1.0, 0.5, 3.0}) {
        const Event e = mesh4d::worldlineEvent(m, s, {0, 0, 0}), f = lab(s, 0);
        EXPECT_NEAR(e.t, f.t, 1e-13 * (1 + std::fabs(f.t)));
        EXPECT_NEAR(e.x.x, f.x.x, 1e-13 * (1 + std::fabs(f.x.x)));
        EXPECT_NEAR(e.x.y, f.x.y, 1e-13 * (1 + std::fabs(f.x.y)));
    }
    const Vec3 C{-2, 1, 3};
    for (double t_c : {2.0, 6.0, 15.0})
        for (double d : {0.0, 0.8}) {
            const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(cone(t_c, C), m, {d, 0, 0});
            double lo = -100, hi = 100;
            for (int i = 0; i < 200; ++i) {
                const double mid = 0.5 * (lo + hi);
                const Event e = lab(mid, d);
                const double h = (t_c - e.t) - std::hypot(e.x.x - C.x, e.x.y - C.y, e.x.z - C.z);
                if (h > 0) lo = mid; else hi = mid;
            }
            const Event e = lab(0.5 * (lo + hi), d);
            EXPECT_NEAR(c.event.t, e.t, 1e-12 * t_c);
            EXPECT_NEAR(c.event.x.x, e.x.x, 1e-12 * t_c);
            EXPECT_NEAR(c.event.x.y, e.x.y, 1e-12 * t_c);
        }
    // Galilean: x = x_origin(t) + q at lab time t = t0 + s.
    const Motion gm = accelMotion(mesh4d::Kinematics::Galilean, {0, b, 0}, {a, 0, 0});
    for (double s_o : {0.5, 3.0}) {
        const Event o = lab(s_o, 0);
        const Event e = mesh4d::worldlineEvent(gm, o.t, {0.3, -0.2, 0.1});
        EXPECT_NEAR(e.t, o.t, 1e-15 * o.t);
        EXPECT_NEAR(e.x.x, o.x.x + 0.3, 1e-12);
        EXPECT_NEAR(e.x.y, o.x.y - 0.2, 1e-12);
        EXPECT_NEAR(e.x.z, 0.1, 1e-15);
        EXPECT_NEAR(mesh4d::originProperTime(gm, o.t), s_o, 1e-12);
    }
}

// An accelerated body through the stage: refusals (behind the horizon, with a spin, rapidity past
// the limit) and a rendered cut whose every vertex lies on the cone and on its own hyperbola.
TEST(Motion, AcceleratedBodyThroughTheStage) {
    const std::string dir = testio::processTempDir();
    auto write = [&](const std::string& name, const std::string& body) {
        const std::string path = dir + "/" + name;
        FILE* f = std::fopen(path.c_str(), "w");
        std::fputs(body.c_str(), f);
        std::fclose(f);
        return path;
    };
    const std::string mesh = std::string(APPARENT_SOURCE_DIR) + "/data/meshes/box.obj";
    auto scene = [&](const std::string& extra, double end) {
        return "{\"camera\": {\"position\": [0, 0, 5]}, \"frames\": {\"start\": 0, \"end\": " + std::to_string(end) +
               ", \"fps\": 2}, \"tolerance\": \"vertex\", \"objects\": [{\"mesh\": \"" + mesh + "\"" + extra + "}]}";
    };
    std::string error;
    {
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(write("horizon.json", scene(", \"acceleration\": [4, 0, 0]", 2)), &st, &error));
        EXPECT_NE(error.find("horizon.json: objects[0].acceleration: vertex "), std::string::npos) << error;
        EXPECT_NE(error.find("horizon of a Born-rigid body"), std::string::npos) << error;
    }
    {
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(
            write("both.json", scene(", \"acceleration\": [0.1, 0, 0], \"angular_velocity\": [0, 0, 0.1]", 2)), &st, &error));
        EXPECT_NE(error.find("give angular_velocity or acceleration, not both"), std::string::npos) << error;
    }
    {
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(
            write("fast.json", scene(", \"scale\": 1e-13, \"acceleration\": [1e12, 0, 0]", 1e4)), &st, &error));
        EXPECT_NE(error.find("fast.json: objects[0].acceleration: the origin's rapidity |a| tau reaches"), std::string::npos)
            << error;
    }
    apparent::Stage st;
    ASSERT_TRUE(apparent::loadQuietStage(write("ok.json", scene(", \"acceleration\": [0.5, 0, 0]", 10)), &st, &error)) << error;
    const mesh4d::World4D world = apparent::buildWorld(st.objects[0], apparent::Model::Relativistic, st.scene, 0, 19);
    for (long long k : {0LL, 9LL, 19LL}) {
        const mesh4d::ViewSurface view = apparent::viewForFrame(st.scene, apparent::Model::Relativistic, k);
        mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
        mesh4d::addLightFactors(world, view, &out);
        ASSERT_EQ(out.positions.size(), st.objects[0].rest.positions.size());
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const Vec3 p = out.absolutePosition(i);
            const double t = out.absoluteTime(i);
            EXPECT_NEAR(view.t_c - t, mesh4d::norm(p - view.apex), 1e-12 * (1 + view.t_c));
            const Vec3& q = out.rest_points[i];
            const double xi = 2 + q.x;
            if (t > 0) {
                EXPECT_NEAR((p.x + 2) * (p.x + 2) - t * t, xi * xi, 1e-11 * (1 + t * t));
                EXPECT_NEAR(out.proper_time[i], xi * std::asinh(t / xi), 1e-12 * (1 + t));  // proper acceleration 1/xi
            } else {
                EXPECT_EQ(p.x, q.x);
            }
        }
    }
}

// The 4D raytracer meets spinning and accelerated histories through time slabs (mesh4d/extrude.h):
// every hit, taken back to the object's own frame by an inverse written here (the inverse boost,
// then the rotation back by w T, or the Born-rigid hyperbola's xi = sqrt((x + 1/a)^2 - t^2)), lies on
// the plane of the rest triangle it hit within the slabs' chord (plus rounding); one slab over the
// same span misses by far more (the test can fail).
TEST(Motion, RaytracedHitsLieOnTheRestSurfaceThroughTimeSlabs) {
    const mesh4d::RestMesh mesh = cylinder(1, 0.3, 24);
    struct Case {
        Motion m;
        Vec3 camera;
    };
    Motion spin = spinMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {0.6, 0, 0}, {0, 0, 0.8});
    Motion rocket = accelMotion(mesh4d::Kinematics::Lorentz, {0, 0, 0}, {0.5, 0, 0});
    for (const Case& c : {Case{spin, {0, 0, 6}}, Case{rocket, {0, 0, 6}}}) {
        const bool spinning = norm(c.m.angular_velocity) > 0;
        const double t_c = 6.5, chord = 1e-2;
        const mesh4d::ViewSurface view = cone(t_c, c.camera);
        // The span this frame can see, padded.
        double lo = INFINITY, hi = -INFINITY;
        for (const Vec3& q : mesh.positions) {
            const double s = mesh4d::crossWorldline(view, c.m, q).s;
            lo = std::min(lo, s);
            hi = std::max(hi, s);
        }
        lo -= 0.5;
        hi += 0.5;
        const double g = c.m.gamma;
        const std::vector<double> samples = mesh4d::slabSamples(mesh, c.m, lo, hi, chord / (g * (1 + c.m.beta)), 4096);
        ASSERT_GT(samples.size(), 10u);
        auto rest_point = [&](const Event& e) {
            if (spinning) {  // inverse boost along x (b = 0.6), then back by w T
                const double b = 0.6, gb = 1 / std::sqrt(1 - b * b);
                const double T = gb * (e.t - b * e.x.x);
                const Vec3 Y{gb * (e.x.x - b * e.t), e.x.y, e.x.z};
                const double a = -0.8 * T;
                return Vec3{std::cos(a) * Y.x - std::sin(a) * Y.y, std::sin(a) * Y.x + std::cos(a) * Y.y, Y.z};
            }
            // Born-rigid along x, a = 0.5 (e.t > 0 here)
            return Vec3{e.t > 0 ? std::sqrt((e.x.x + 2) * (e.x.x + 2) - e.t * e.t) - 2 : e.x.x, e.x.y, e.x.z};
        };
        double worst[2] = {0, 0};
        for (int pass = 0; pass < 2; ++pass) {
            const testslab::OffPlanes r = testslab::slabHitsOffTheirPlanes(
                mesh, c.m, pass == 0 ? samples : std::vector<double>{lo, hi}, t_c, c.camera, rest_point);
            worst[pass] = r.worst;
            if (pass == 0) {
                EXPECT_GT(r.hits, 100) << (spinning ? "spin" : "rocket");
            }
        }
        EXPECT_LE(worst[0], 2 * chord) << (spinning ? "spin" : "rocket");
        EXPECT_GT(worst[1], 10 * chord) << (spinning ? "spin" : "rocket");
    }
}
