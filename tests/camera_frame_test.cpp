// A moving camera (scene camera.velocity; mesh4d/motion/camera_frame.h): the pipeline's outputs are in
// the camera's rest frame. Checked against computations written here, independent of the
// program's boost code: every output event, taken back to the lab by this file's own inverse
// boost, lies on the camera's past light cone and on the lab worldline of one of the object's rest
// vertices (so positions, emission times and the Thomas-Wigner rotation are all checked), and
// stars seen from a moving camera show the aberration formula.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mesh4d/motion/motion.h"
#include "mesh4d/motion/camera_frame.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"
#include "run_command.h"
#include "box_scene.h"
#include "temp_dir.h"

using namespace apparent;
using mesh4d::Event;
using mesh4d::Vec3;
namespace fs = std::filesystem;
using testcli::apparentRun;
using testcli::CommandResult;

namespace {

// The inverse of the camera-frame map, written from the textbook form: for a camera moving at v
// through the lab, an event (t', x') of its rest frame (about the event t = 0, x = P) is, in the
// lab, t = g (t' + v.r'), x = P + r'_perp + g (r'_par + v t'), r' = x' - P split along v.
Event labFromCamera(const Event& e, const Vec3& v, const Vec3& p) {
    const double b2 = mesh4d::dot(v, v);
    const double g = 1 / std::sqrt(1 - b2);
    const Vec3 r = e.x - p;
    const Vec3 r_par = v * (mesh4d::dot(r, v) / b2);
    const Vec3 r_perp = r - r_par;
    return {g * (e.t + mesh4d::dot(v, r)), p + r_perp + (r_par + v * e.t) * g};
}

using Fixture = BoxScene;

// Writes `scene_json` (objects may use box.obj) into a fresh folder and loads its stage.
void loadScene(const std::string& name, const std::string& scene_json, Fixture* f) {
    loadBoxScene("camera_" + name, scene_json, f);
}

// Checks every vertex of frame k of every object in vertex mode; returns the vertex count.
size_t checkInvariance(const Fixture& f, Model model, long long k, double rel_bound) {
    const Scene& scene = f.stage.scene;
    const Vec3 v = scene.camera.velocity, p = scene.camera.position;
    const double tau_k = frameTime(scene.frames, k);
    size_t checked = 0;
    for (const PreparedObject& o : f.stage.objects) {
        const mesh4d::World4D world = buildWorld(o, model, scene, k, k);
        const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, model, k), {});
        const mesh4d::Motion lab = motionOf(o.spec, model);
        for (size_t i = 0; i < cut.positions.size(); ++i) {
            const Event cam{cut.absoluteTime(i), cut.absolutePosition(i)};
            const double scale = std::max({1.0, mesh4d::norm(cam.x - p), std::fabs(cam.t)});
            // On the camera's past light cone, in the camera's frame (the camera at p, time tau_k).
            EXPECT_NEAR(tau_k - cam.t, mesh4d::norm(cam.x - p), rel_bound * scale) << o.spec.name << " vertex " << i;
            // In the lab: on the worldline of one of the rest vertices.
            const Event e = labFromCamera(cam, v, p);
            double best = INFINITY;
            for (const Vec3& q : o.rest.positions)
                best = std::min(best, mesh4d::norm(mesh4d::labPositionAt(lab, q, e.t) - e.x));
            EXPECT_LT(best, rel_bound * scale) << o.spec.name << " vertex " << i << " model " << modelName(model);
            ++checked;
        }
    }
    return checked;
}

}  // namespace

// The fly-by: a camera at 0.9c passing a row of boxes at rest in the lab, in the relativistic and
// contracted models (contracted: the camera frame's simultaneous shapes, on its hyperplane; the
// cone check does not apply, so only the instant-free relativistic model checks the cone).
TEST(CameraFrame, StaticObjectsFromAMovingCameraAreTheLabsWorldlinesSeenOnTheCamerasCone) {
    Fixture f;
    loadScene("flyby", R"({ "camera": { "position": [0, 0, 0], "velocity": [0.9, 0, 0] },
        "frames": { "start": -4, "end": 4, "fps": 1 }, "model": "relativistic", "tolerance": "vertex",
        "objects": [ { "name": "a", "mesh": "box.obj", "position": [-2, 0, -3] },
                     { "name": "b", "mesh": "box.obj", "position": [0, 0, -3] },
                     { "name": "c", "mesh": "box.obj", "position": [2, 0.5, -3] } ] })",
              &f);
    size_t n = 0;
    for (long long k = 0; k < 8; ++k) n += checkInvariance(f, Model::Relativistic, k, 1e-12);
    EXPECT_GT(n, 100u);
}

// Object and camera velocities not parallel: the object's rest frame is turned in the camera's
// frame by the Thomas-Wigner rotation; without it the events miss the vertex worldlines by 0.14
// to 0.35 ls here (measured by leaving the rotation out).
TEST(CameraFrame, NonParallelVelocitiesNeedTheThomasWignerRotation) {
    Fixture f;
    loadScene("wigner", R"({ "camera": { "position": [0, 0, 0], "velocity": [0.8, 0, 0] },
        "frames": { "start": 0, "end": 6, "fps": 1 }, "model": "relativistic", "tolerance": "vertex",
        "objects": [ { "name": "up", "mesh": "box.obj", "position": [0, -6, -4], "velocity": [0, 0.85, 0],
                       "rotation_deg": [10, 20, 30] },
                     { "name": "oblique", "mesh": "box.obj", "position": [-3, -3, -5], "velocity": [0.3, 0.5, 0.4] } ] })",
              &f);
    size_t n = 0;
    for (long long k = 0; k < 6; ++k) n += checkInvariance(f, Model::Relativistic, k, 1e-12);
    EXPECT_GT(n, 40u);
    // The rotation is really there: its angle for the first object, from the closed form
    // tan(theta) = g_u g_v b_u b_v / (g_u + g_v) for perpendicular velocities (theta about u x v).
    const mesh4d::MotionInCameraFrame m = cameraFrameMotionOf(f.stage.objects[0].spec, Model::Relativistic, f.stage.scene);
    const double bu = 0.85, bv = 0.8, gu = 1 / std::sqrt(1 - bu * bu), gv = 1 / std::sqrt(1 - bv * bv);
    const double theta = std::atan(gu * gv * bu * bv / (gu + gv));
    ASSERT_TRUE(m.rotated);
    // A rotation about z (u x v is along -z for u = y, v = x): the xx entry is cos theta.
    EXPECT_NEAR(m.rotation[0], std::cos(theta), 1e-14);
    EXPECT_NEAR(m.rotation[8], 1.0, 1e-14);
    EXPECT_NEAR(std::fabs(m.rotation[1]), std::sin(theta), 1e-14);
}

// Stars at rest in the lab, 1000 ls away in many directions, seen from a camera at 0.6c: the
// direction of each in the camera's frame follows cos t' = (cos t + b) / (1 + b cos t), t the
// angle between the velocity and the star seen from the camera's lab position at reception.
TEST(CameraFrame, StarFieldShowsTheAberrationFormula) {
    std::string objects;
    int count = 0;
    for (int i = 0; i < 12; ++i) {
        const double a = 0.25 + i * 0.5;  // radians around the y axis, away from the exact axis
        const Vec3 d{1000 * std::cos(a), 100.0 * (i % 3 - 1), 1000 * std::sin(a)};
        objects += std::string(count++ ? "," : "") + R"({ "name": "s)" + std::to_string(i) + R"(", "mesh": "box.obj", "scale": 0.001, "position": [)" +
                   std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z) + "] }";
    }
    Fixture f;
    const double b = 0.6;
    loadScene("stars", R"({ "camera": { "position": [0, 0, 0], "velocity": [0.6, 0, 0], "fov_deg": 170 },
        "frames": { "start": 3, "end": 4, "fps": 1 }, "model": "relativistic", "tolerance": "vertex",
        "objects": [ )" + objects + "] }",
              &f);
    const Scene& scene = f.stage.scene;
    const double tau = frameTime(scene.frames, 0);
    const double g = 1 / std::sqrt(1 - b * b);
    const Vec3 c_lab{b * g * tau, 0, 0};  // the camera's lab position at reception (lab time g tau)
    size_t n = 0;
    for (const PreparedObject& o : f.stage.objects) {
        const mesh4d::World4D world = buildWorld(o, Model::Relativistic, scene, 0, 0);
        const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, Model::Relativistic, 0), {});
        for (size_t i = 0; i < cut.positions.size(); ++i) {
            const Vec3 seen = cut.absolutePosition(i);  // camera frame; the camera at the origin
            const Vec3 star = o.spec.position + cut.rest_points[i];  // at rest: no rotation
            const Vec3 lab_dir = star - c_lab;
            const double cos_t = lab_dir.x / mesh4d::norm(lab_dir);
            const double cos_t_seen = seen.x / mesh4d::norm(seen);
            EXPECT_NEAR(cos_t_seen, (cos_t + b) / (1 + b * cos_t), 1e-12) << o.spec.name;
            ++n;
        }
    }
    EXPECT_EQ(n, 12u * 8u);
}

// A camera at 1 - 1e-12 of light speed: finite everywhere and the invariance to a stated bound
// (the boost's terms reach g = 7.1e5, so the checks hold to about g^2 ulps of the scale).
TEST(CameraFrame, NearLightSpeedCameraStaysFiniteAndInvariant) {
    Fixture f;
    loadScene("fast", R"({ "camera": { "position": [0, 0, 0], "velocity": [0.999999999999, 0, 0] },
        "frames": { "start": -1e-5, "end": 1e-5, "fps": 100000 }, "model": "relativistic", "tolerance": "vertex",
        "objects": [ { "name": "a", "mesh": "box.obj", "position": [0, 0, -3] } ] })",
              &f);
    const Scene& scene = f.stage.scene;
    for (long long k = 0; k < 2; ++k) {
        const mesh4d::World4D world = buildWorld(f.stage.objects[0], Model::Relativistic, scene, k, k);
        const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, Model::Relativistic, k), {});
        ASSERT_FALSE(cut.positions.empty());
        for (size_t i = 0; i < cut.positions.size(); ++i) {
            EXPECT_TRUE(mesh4d::isFinite(cut.absolutePosition(i)));
            EXPECT_TRUE(std::isfinite(cut.absoluteTime(i)));
        }
    }
    checkInvariance(f, Model::Relativistic, 0, 1e-4);
}

// Refusals, one line each: a camera at or beyond light speed.
TEST(CameraFrame, ImpossibleOrUnsupportedCamerasAreRefused) {
    const fs::path dir = testio::tempPath() / ("apparent_camera_bad_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(fs::path(APPARENT_SOURCE_DIR) / "data/meshes/box.obj", dir / "box.obj");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {R"("camera": { "velocity": [0.6, 0.8, 0] }, "model": "relativistic")",
         "camera.velocity: |velocity| = 1 must be < 1 (the speed of light): the camera is an observer"},
    };
    for (const auto& [fields, expected] : cases) {
        std::ofstream(dir / "scene.json") << "{ " << fields
                                          << R"(, "frames": { "start": 0, "end": 1, "fps": 1 }, "objects": [ { "mesh": "box.obj", "position": [0, 0, -3] } ] })";
        const CommandResult r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "out").string()});
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    fs::remove_all(dir);
}
