// The circular orbit (mesh4d/motion/motion.h Orbit, orbit.cpp) against closed forms and
// computations of this file's own: the lab path written out (a circle in the basis of its plane,
// the body contracted along the velocity), the retarded time by bisection, the clock by Simpson's
// rule on that path, the transverse Doppler factor; the tolerance mode by measure.h's two-sided
// distance; the scene field and its refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "mesh4d/extrude.h"
#include "mesh4d/refine/measure.h"
#include "mesh4d/motion/worldline.h"
#include "mesh4d/slice.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"
#include "quiet_stage.h"
#include "run_command.h"
#include "temp_dir.h"
#include "test_meshes.h"

using mesh4d::Event;
using mesh4d::Vec3;

namespace {

Vec3 unit(const Vec3& v) { return v / mesh4d::norm(v); }

// The orbit as this file writes it: centre c, unit axis k, speed v, origin X0 at lab time t0.
struct Circle {
    Vec3 c, k, x0;
    double v = 0, t0 = 0;
    bool locked = false, lorentz = true;
    Vec3 e() const { return unit(x0 - c - k * mesh4d::dot(k, x0 - c)); }
    Vec3 f() const { return mesh4d::cross(k, e()); }
    double R() const { return mesh4d::norm(x0 - c - k * mesh4d::dot(k, x0 - c)); }
    double gamma() const { return lorentz ? 1 / std::sqrt(1 - v * v) : 1.0; }
    // Rest point q's lab position at lab time t.
    Vec3 at(double t, const Vec3& q) const {
        const double a = v / R() * (t - t0);
        const Vec3 E = e(), F = f();
        const Vec3 axial = c + k * mesh4d::dot(k, x0 - c);
        const Vec3 P = axial + (E * std::cos(a) + F * std::sin(a)) * R();
        const Vec3 u = F * std::cos(a) - E * std::sin(a);
        const double qe = mesh4d::dot(q, E), qf = mesh4d::dot(q, F), qk = mesh4d::dot(q, k);
        const Vec3 Q = locked ? E * (qe * std::cos(a) - qf * std::sin(a)) + F * (qe * std::sin(a) + qf * std::cos(a)) + k * qk : q;
        return P + Q - u * ((1 - 1 / gamma()) * mesh4d::dot(Q, u));
    }
    mesh4d::Motion motion() const {
        mesh4d::Motion m = mesh4d::makeMotion(lorentz ? mesh4d::Kinematics::Lorentz : mesh4d::Kinematics::Galilean, t0, x0, {0, 0, 0});
        mesh4d::Orbit o;
        o.center = c;
        o.axis = k;
        o.speed = v;
        o.locked = locked;
        m.kinds.orbit = std::make_shared<const mesh4d::Orbit>(o);
        return m;
    }
};

Circle sample(bool lorentz, bool locked) {
    Circle o;
    o.c = {1, 2, -3};
    o.k = unit({0.3, 0.4, 1});
    o.x0 = {4, 1.5, -2};
    o.v = 0.8;
    o.t0 = 0.25;
    o.lorentz = lorentz;
    o.locked = locked;
    return o;
}

// The lab time at which q's light reaches camera C at t_c: t_c - t = |x(t) - C|, by bisection.
double retarded(const Circle& o, const Vec3& q, double t_c, const Vec3& C) {
    double lo = t_c - 1e3, hi = t_c;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (t_c - mid - mesh4d::norm(o.at(mid, q) - C) > 0) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace

// The crossing of a point's worldline with a past cone is at the retarded time of the path written
// out here, in both kinematics and both orientations; in relativistic the object's time there is
// the origin's clock, (t - t0) / gamma.
TEST(Orbit, RetardedTimeMatchesAnIndependentRootSearch) {
    for (bool lorentz : {true, false})
        for (bool locked : {false, true}) {
            const Circle o = sample(lorentz, locked);
            const mesh4d::Motion m = o.motion();
            for (const Vec3& q : {Vec3{0, 0, 0}, Vec3{0.3, -0.2, 0.1}})
                for (double t_c : {-3.0, 7.3, 41.0}) {
                    mesh4d::ViewSurface view;
                    view.t_c = t_c;
                    view.apex = {20, -5, 4};
                    const double t = retarded(o, q, t_c, view.apex);
                    const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(view, m, q);
                    ASSERT_TRUE(c.ok);
                    EXPECT_NEAR(c.event.t, t, 1e-11) << lorentz << locked << t_c;
                    EXPECT_NEAR(mesh4d::norm(c.event.x - o.at(t, q)), 0, 1e-10) << lorentz << locked << t_c;
                    EXPECT_NEAR(c.s, (t - o.t0) / o.gamma(), 1e-11);
                }
        }
}

// Relativistic clocks: the origin's reads t / gamma (t the lab time since t0); a locked body's point
// at distance rho from the axis reads t sqrt(1 - (v rho / R)^2); a fixed body's point off its
// origin (its contraction turns with the velocity, so its speed varies) the integral of
// sqrt(1 - |dx/dt|^2) along the path written out here (Simpson's rule, the velocity by central
// differences). Galilean clocks read t.
TEST(Orbit, ProperTimeIsLabTimeOverGamma) {
    for (bool locked : {false, true}) {
        const Circle o = sample(true, locked);
        const mesh4d::Motion m = o.motion();
        for (double s : {-2.0, 0.7, 13.0}) {
            const double t = mesh4d::worldlineEvent(m, s, {0, 0, 0}).t - o.t0;
            EXPECT_NEAR(t, o.gamma() * s, 1e-13 * o.gamma() * std::fabs(s));
            EXPECT_NEAR(mesh4d::worldlineProperTime(m, s, {0, 0, 0}), t / o.gamma(), 1e-13 * std::fabs(t));
        }
    }
    const Vec3 q{0.3, -0.2, 0.15};
    for (bool locked : {false, true}) {
        const Circle o = sample(true, locked);
        const mesh4d::Motion m = o.motion();
        for (double s : {0.9, 7.0, -4.0}) {
            const double t = o.gamma() * s;
            const int n = 20000;
            double sum = 0;
            for (int i = 0; i <= n; ++i) {
                const double ti = o.t0 + t * i / n, h = 1e-5;
                const Vec3 vel = (o.at(ti + h, q) - o.at(ti - h, q)) / (2 * h);
                const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
                sum += w * std::sqrt(1 - mesh4d::dot(vel, vel));
            }
            const double tau = sum * t / n / 3;
            EXPECT_NEAR(mesh4d::worldlineProperTime(m, s, q), tau, 1e-8 * std::fabs(t)) << locked << " s " << s;
            if (locked) {
                const Vec3 p = o.at(o.t0, q) - o.c;
                const double rho = mesh4d::norm(p - o.k * mesh4d::dot(o.k, p));
                const double w = o.v / o.R() * rho;
                EXPECT_NEAR(mesh4d::worldlineProperTime(m, s, q), t * std::sqrt(1 - w * w), 1e-13 * std::fabs(t));
            }
        }
    }
    const mesh4d::Motion g = sample(false, false).motion();
    EXPECT_EQ(mesh4d::worldlineProperTime(g, 3.5, q), 3.5);
}

// The transverse Doppler factor. Light emitted perpendicular to the emitter's velocity, both taken
// in the lab (the camera's frame) at the emission event, arrives at frequency ratio 1 / gamma (a
// redshift): for a camera at rest in the orbit's plane outside the circle, the light it receives
// from the point of the circle nearest to it (the closest approach, the velocity there tangent,
// the line of sight radial), and for a camera on the axis, the light from every point. Elsewhere
// the factor is sqrt(1 - v^2) / (1 - v n.u) (approaching: blue; receding: red beyond 1 / gamma).
// Galilean clocks: 1 at the closest point.
TEST(Orbit, TransverseDopplerAtClosestApproach) {
    Circle o = sample(true, false);
    o.x0 = o.c + (o.x0 - o.c - o.k * mesh4d::dot(o.k, o.x0 - o.c));  // X0 in the centre's plane
    const mesh4d::Motion m = o.motion();
    const double d = 5.5;
    mesh4d::ViewSurface view;
    view.apex = o.c + o.e() * (o.R() + d);
    view.t_c = o.t0 + d;  // the light of the emission at t0, at the closest point X0
    const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(view, m, {0, 0, 0});
    EXPECT_NEAR(c.s, 0, 1e-12);
    EXPECT_NEAR(mesh4d::norm(c.event.x - o.x0), 0, 1e-12);
    const double D = mesh4d::worldlineDoppler(m, mesh4d::ViewKind::PastCone, view.apex, c.s, {0, 0, 0}, c.event.x);
    EXPECT_NEAR(D, 1 / o.gamma(), 1e-12);
    // A quarter turn before and after the closest point the line of sight has a part along the
    // velocity: D = sqrt(1 - v^2) / (1 - v n.u), n toward the camera, u the direction of motion.
    for (double sign : {-1.0, 1.0}) {
        const double a = sign * M_PI / 2;
        const Vec3 P = o.c + (o.e() * std::cos(a) + o.f() * std::sin(a)) * o.R();
        const Vec3 u = o.f() * std::cos(a) - o.e() * std::sin(a);
        const Vec3 n = unit(view.apex - P);
        mesh4d::ViewSurface other = view;
        other.t_c = o.t0 + a / (o.v / o.R()) + mesh4d::norm(view.apex - P);
        const mesh4d::WorldlineCrossing e = mesh4d::crossWorldline(other, m, {0, 0, 0});
        EXPECT_NEAR(mesh4d::norm(e.event.x - P), 0, 1e-11);
        const double De = mesh4d::worldlineDoppler(m, mesh4d::ViewKind::PastCone, other.apex, e.s, {0, 0, 0}, e.event.x);
        EXPECT_NEAR(De, std::sqrt(1 - o.v * o.v) / (1 - o.v * mesh4d::dot(n, u)), 1e-12) << sign;
        EXPECT_GT(std::fabs(De - 1 / o.gamma()), 0.1) << sign;
    }
    // On the axis: perpendicular at every emission.
    mesh4d::ViewSurface axis = view;
    axis.apex = o.c + o.k * 3.0;
    for (double t_c : {2.0, 9.0}) {
        axis.t_c = t_c;
        const mesh4d::WorldlineCrossing e = mesh4d::crossWorldline(axis, m, {0, 0, 0});
        EXPECT_NEAR(mesh4d::worldlineDoppler(m, mesh4d::ViewKind::PastCone, axis.apex, e.s, {0, 0, 0}, e.event.x),
                    1 / o.gamma(), 1e-12);
    }
    Circle g = o;
    g.lorentz = false;
    const mesh4d::Motion gm = g.motion();
    const mesh4d::WorldlineCrossing e = mesh4d::crossWorldline(view, gm, {0, 0, 0});
    EXPECT_NEAR(mesh4d::worldlineDoppler(gm, mesh4d::ViewKind::PastCone, view.apex, e.s, {0, 0, 0}, e.event.x), 1.0, 1e-12);
}

// Tolerance mode: the two-sided distance (measure.h twoSided: the exact surface by bisection on the
// worldlines) within T, on the past cone in both kinematics and both orientations, and on the
// hyperplane (contracted).
TEST(Orbit, ToleranceTwoSidedWithinT) {
    const mesh4d::RestMesh mesh = testmesh::torus(16, 8, 0.4, 0.15);
    for (bool lorentz : {true, false})
        for (bool locked : {false, true})
            for (bool plane : {false, true}) {
                if (plane && !lorentz) continue;
                Circle o = sample(lorentz, locked);
                o.v = 0.6;
                const mesh4d::Motion m = o.motion();
                const mesh4d::World4D world = mesh4d::extrude(mesh, m, -1e3, 1e3, false, false);
                mesh4d::ViewSurface view;
                view.kind = plane ? mesh4d::ViewKind::Hyperplane : mesh4d::ViewKind::PastCone;
                view.t_c = 6.0;
                view.apex = {9, -2, 3};
                for (double T : {1e-2, 1e-3}) {
                    mesh4d::SliceSettings settings;
                    settings.tolerance = T;
                    const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view, settings);
                    ASSERT_FALSE(out.triangles.empty());
                    const double err = mesh4d::measure::twoSided(world, view, out);
                    EXPECT_LE(err, T) << lorentz << locked << plane << " T " << T;
                    EXPECT_EQ(out.limited_triangles, 0u);
                    std::printf("[ orbit ] %s %s %s T = %g: err/T %.3f, %zu -> %zu triangles\n",
                                lorentz ? "lorentz" : "galilean", locked ? "locked" : "fixed", plane ? "plane" : "cone", T,
                                err / T, mesh.triangles.size(), out.triangles.size());
                }
            }
}

namespace {

std::string writeFile(const std::string& name, const std::string& body) {
    const std::string path = testio::processTempDir() + "/" + name;
    FILE* f = std::fopen(path.c_str(), "w");
    std::fputs(body.c_str(), f);
    std::fclose(f);
    return path;
}

std::string orbitScene(const std::string& orbit, const std::string& extra = "", const std::string& camera = "") {
    const std::string mesh = std::string(APPARENT_SOURCE_DIR) + "/data/meshes/box.obj";
    return "{\"camera\": {\"position\": [0, 0, 8]" + camera + "}, \"frames\": {\"start\": 0, \"end\": 2, \"fps\": 2}, "
           "\"objects\": [{\"mesh\": \"" + mesh + "\", \"position\": [2, 0, 0], \"scale\": 0.2, \"orbit\": " + orbit + extra + "}]}";
}

}  // namespace

// The scene field: read in every model; refused with one line naming file and field.
TEST(Orbit, SceneFieldAndRefusals) {
    std::string error;
    {
        apparent::Stage st;
        ASSERT_TRUE(apparent::loadQuietStage(writeFile("ok.json", orbitScene("{\"center\": [0, 0, 0], \"axis\": [0, 0, 2], \"speed\": 0.9}")),
                                             &st, &error))
            << error;
        const mesh4d::Motion m = apparent::motionOf(st.scene.objects[0], apparent::Model::Relativistic);
        ASSERT_TRUE(m.kinds.orbit);
        EXPECT_EQ(mesh4d::kindOf(m), mesh4d::MotionKind::Orbit);
        EXPECT_EQ(m.kinds.orbit->axis.z, 1.0);
        EXPECT_FALSE(m.kinds.orbit->locked);
    }
    struct Bad {
        const char* file;
        std::string orbit, extra, camera, expect;
    };
    const Bad bad[] = {
        {"fast.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 1}", "", "", "fast.json: objects[0].orbit.speed: must be > 0 and < 1"},
        {"axis.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 0], \"speed\": 0.5}", "", "", "axis.json: objects[0].orbit.axis: must be non-zero"},
        {"on.json", "{\"center\": [0, 0, 0], \"axis\": [1, 0, 0], \"speed\": 0.5}", "", "",
         "on.json: objects[0].orbit: position lies on the axis through center"},
        {"rim.json", "{\"center\": [1.9, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.5, \"orientation\": \"locked\"}", "", "",
         "rim.json: objects[0].orbit: vertex "},
        {"turn.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.5, \"orientation\": \"spinning\"}", "", "",
         "turn.json: objects[0].orbit.orientation: expected \"fixed\" or \"locked\""},
        {"spin.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.5}", ", \"angular_velocity\": [0, 0, 0.1]", "",
         "spin.json: objects[0].orbit: give orbit alone"},
        {"accel.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.5}", ", \"acceleration\": [0.1, 0, 0]", "",
         "accel.json: objects[0].orbit: give orbit alone"},
        {"moving.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.5}", ", \"velocity\": [0.1, 0, 0]", "",
         "moving.json: objects[0].orbit: the orbit gives the motion: velocity must be [0, 0, 0]"},
        {"camera.json", "{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.5}", "", ", \"velocity\": [0.1, 0, 0]",
         "camera.json: objects[0].orbit: an orbiting object needs a camera at rest"},
    };
    for (const Bad& b : bad) {
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(writeFile(b.file, orbitScene(b.orbit, b.extra, b.camera)), &st, &error)) << b.file;
        EXPECT_NE(error.find(b.expect), std::string::npos) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
    }
    // The rim of a locked body just below c is accepted: the box's far corner at 2.1 + 0.2 sqrt(2)
    // from the centre at 0 moves at w rho < 1 with w = 0.4 / 2.
    apparent::Stage st;
    EXPECT_TRUE(apparent::loadQuietStage(
        writeFile("slow.json", orbitScene("{\"center\": [0, 0, 0], \"axis\": [0, 0, 1], \"speed\": 0.4, \"orientation\": \"locked\"}")),
        &st, &error))
        << error;
}

// The ring of data/scenes: in every model each vertex's output point is its worldline's crossing
// of the frame's view, and the output has a point per rest vertex (vertex mode); `render` at the
// default tolerance (PLY and .glb with the doppler and proper_time attributes) and `raytrace`
// (plain and Doppler shading) run in every model.
TEST(Orbit, RingSceneRendersAndTracesInEveryModel) {
    const std::string scene = testcli::source("data/scenes/orbit_ring.json");
    for (apparent::Model model : {apparent::Model::Instant, apparent::Model::Finite, apparent::Model::Relativistic,
                                  apparent::Model::Contracted}) {
        apparent::Stage stage;
        std::string error;
        ASSERT_TRUE(apparent::loadQuietStage(scene, &stage, &error, {model})) << error;
        for (size_t o = 0; o < stage.objects.size(); o += 3) {
            const mesh4d::World4D world = apparent::buildWorld(stage.objects[o], model, stage.scene, 5, 5);
            const mesh4d::ViewSurface view = apparent::viewForFrame(stage.scene, model, 5);
            const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
            ASSERT_EQ(out.positions.size(), stage.objects[o].rest.positions.size());
            for (size_t i = 0; i < out.positions.size(); ++i) {
                const mesh4d::WorldlineCrossing c = mesh4d::crossWorldline(view, world.motion, out.rest_points[i]);
                EXPECT_NEAR(mesh4d::norm(out.absolutePosition(i) - c.event.x), 0, 1e-12);
            }
        }
    }
    testcli::TempDir dir;
    const auto render = testcli::apparentRun({"render", scene, "--out", (dir / "r").string(), "--model", "all", "--frames",
                                              "4:6", "--format", "ply,glb", "--attributes", "doppler,proper_time", "--quiet"});
    EXPECT_EQ(render.code, 0) << render.err;
    for (const char* shade : {"plain", "doppler"}) {
        const auto trace = testcli::apparentRun({"raytrace", scene, "--out", (dir / shade).string(), "--model", "all",
                                                 "--frames", "5:6", "--size", "48x32", "--shade", shade, "--quiet"});
        EXPECT_EQ(trace.code, 0) << trace.err;
        EXPECT_FALSE(std::filesystem::is_empty(dir / shade));
    }
}
