// The finite model with a moving camera (physics.h viewAt, lightcone.h ViewSurface::shear): light
// moves at c in the lab (the pre-relativistic medium) and the outputs are in the camera's frame by
// the Galilean map x' = x - v t, t' = t about (0, camera.position). Checked against computations
// written here: each object point's lab emission event found on the lab's past cone of the moving
// camera (the quadratic solved in long double), then sheared by this file's own map; the classical
// Doppler factor (1 - v.n) / (1 - u.n) with lab quantities; classical aberration of stars at rest;
// and the two-sided distance of refined frames to the exact sheared surface, for an object at rest
// in the lab (which the shear curves) and a moving one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "mesh4d/motion/motion.h"
#include "mesh4d/extrude.h"
#include "mesh4d/slice.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"
#include "box_scene.h"
#include "run_command.h"
#include "test_meshes.h"
#include "temp_dir.h"

using namespace apparent;
using mesh4d::Event;
using mesh4d::Vec3;
namespace fs = std::filesystem;

namespace {

// The lab emission event of the point moving as x(t) = x0 + u (t - t0) whose light reaches the lab
// event (t_c, c): |x(t_e) - c| = t_c - t_e, t_e <= t_c. With a = x(t_c) - c and d = t_c - t_e:
// (1 - u^2) d^2 + 2 (a.u) d - |a|^2 = 0, the non-negative root, in long double.
Event labEmission(const Vec3& x0, double t0, const Vec3& u, double t_c, const Vec3& c) {
    using L = long double;
    const L ax = L(x0.x) + L(u.x) * (L(t_c) - t0) - c.x, ay = L(x0.y) + L(u.y) * (L(t_c) - t0) - c.y,
            az = L(x0.z) + L(u.z) * (L(t_c) - t0) - c.z;
    const L au = ax * u.x + ay * u.y + az * u.z, aa = ax * ax + ay * ay + az * az;
    const L k = 1 - (L(u.x) * u.x + L(u.y) * u.y + L(u.z) * u.z);
    const L root = std::sqrt(au * au + k * aa);
    const L d = au >= 0 ? aa / (au + root) : (root - au) / k;
    return {double(t_c - d), {double(c.x + ax - u.x * d), double(c.y + ay - u.y * d), double(c.z + az - u.z * d)}};
}

// This file's Galilean map into the frame of a camera moving at v: (t, x) -> (t, x - v t).
Event shearIntoCamera(const Event& e, const Vec3& v) { return {e.t, e.x - v * e.t}; }

// The exact camera-frame image of rest point q of an object at x0 (t0) moving at u in the lab,
// seen at camera time t_c by a camera at p moving at v.
Event exactImage(const Vec3& x0, double t0, const Vec3& u, const Vec3& q, double t_c, const Vec3& p, const Vec3& v) {
    return shearIntoCamera(labEmission(x0 + q, t0, u, t_c, p + v * t_c), v);
}

using Fixture = BoxScene;

// Writes `scene_json` (objects may use box.obj) into a fresh folder and loads its stage.
void loadScene(const std::string& name, const std::string& scene_json, Fixture* f) {
    loadBoxScene("finite_camera_" + name, scene_json, f);
}

}  // namespace

// Every output vertex of every frame (vertex mode) is the lab cone's emission event of its rest
// point, sheared into the camera's frame, to 1e-9 relative: objects at rest, moving along the
// camera's velocity, across it, and obliquely, a camera at 0.9c along x and one oblique at 0.7c.
TEST(FiniteCamera, OutputsAreTheLabConesEventsShearedIntoTheCameraFrame) {
    for (const char* camera : {R"("position": [0.5, -1, 2], "velocity": [0.9, 0, 0])",
                               R"("position": [0, 0, 0], "velocity": [0.3, -0.4, 0.5])"}) {
        Fixture f;
        loadScene("invariance", std::string(R"({ "camera": { )") + camera + R"( },
            "frames": { "start": -3, "end": 5, "fps": 1 }, "model": "finite", "tolerance": "vertex",
            "objects": [ { "name": "rest", "mesh": "box.obj", "position": [-2, 0, -4] },
                         { "name": "along", "mesh": "box.obj", "position": [-6, 1, -5], "velocity": [0.8, 0, 0], "t0": 1 },
                         { "name": "across", "mesh": "box.obj", "position": [1, -5, -6], "velocity": [0, 0.85, 0],
                           "rotation_deg": [10, 20, 30], "scale": 1.5 },
                         { "name": "oblique", "mesh": "box.obj", "position": [3, 3, -7], "velocity": [-0.3, -0.5, 0.4] } ] })",
                  &f);
        const Scene& scene = f.stage.scene;
        const Vec3 p = scene.camera.position, v = scene.camera.velocity;
        size_t checked = 0;
        for (long long k = 0; k < frameCount(scene.frames); ++k) {
            const double t_c = frameTime(scene.frames, k);
            for (const PreparedObject& o : f.stage.objects) {
                const mesh4d::World4D world = buildWorld(o, Model::Finite, scene, k, k);
                const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, Model::Finite, k), {});
                ASSERT_EQ(cut.positions.size(), o.rest.positions.size());
                for (size_t i = 0; i < cut.positions.size(); ++i) {
                    const Event want = exactImage(o.spec.position, o.spec.t0, o.spec.velocity, cut.rest_points[i], t_c, p, v);
                    const double scale = std::max({1.0, mesh4d::norm(want.x - p), std::fabs(want.t)});
                    EXPECT_NEAR(cut.absoluteTime(i), want.t, 1e-9 * scale) << o.spec.name << " frame " << k;
                    EXPECT_LT(mesh4d::norm(cut.absolutePosition(i) - want.x), 1e-9 * scale) << o.spec.name << " frame " << k;
                    ++checked;
                }
            }
        }
        EXPECT_EQ(checked, 8u * 8u * 4u);
        fs::remove_all(f.dir);
    }
}

// In the camera's frame the object moves at w = u - v and the delay solves the lab's quadratic
// with u: |e' - u d| = d, the image e' - w d (the lead's closed form), which must agree with the
// lab computation above; checked here once, independently of the program, so the test's own
// reference is not circular.
TEST(FiniteCamera, CameraFrameClosedFormAgreesWithTheShearedLabCut) {
    const Vec3 x0{3, -2, -7}, u{-0.2, 0.6, 0.3}, p{1, 0, 0}, v{0.7, 0.1, -0.2};
    const double t0 = 0.5, t_c = 4;
    const Event lab = exactImage(x0, t0, u, {0, 0, 0}, t_c, p, v);
    // Camera frame: the point at t_c is at x0 + u (t_c - t0) - v t_c, the camera at p.
    const Vec3 e = x0 + u * (t_c - t0) - v * t_c - p;
    const double k = 1 - mesh4d::dot(u, u), eu = mesh4d::dot(e, u);
    const double d = (-eu + std::sqrt(eu * eu + k * mesh4d::dot(e, e))) / k;
    EXPECT_NEAR(lab.t, t_c - d, 1e-12 * t_c);
    EXPECT_LT(mesh4d::norm(lab.x - (p + e - (u - v) * d)), 1e-12 * mesh4d::norm(e));
}

// Stars at rest in the lab seen from a camera at 0.6c in the finite model: classical aberration.
// A star in lab direction d from the camera's lab position at reception appears along d + v, so
// cos t' = (cos t + b) / sqrt(1 + 2 b cos t + b^2) (not the relativistic (cos t + b) / (1 + b cos t)).
TEST(FiniteCamera, StarFieldShowsClassicalAberration) {
    std::string objects;
    for (int i = 0; i < 12; ++i) {
        const double a = 0.25 + i * 0.5;
        const Vec3 d{1000 * std::cos(a), 100.0 * (i % 3 - 1), 1000 * std::sin(a)};
        objects += std::string(i ? "," : "") + R"({ "name": "s)" + std::to_string(i) +
                   R"(", "mesh": "box.obj", "scale": 0.001, "position": [)" + std::to_string(d.x) + "," +
                   std::to_string(d.y) + "," + std::to_string(d.z) + "] }";
    }
    Fixture f;
    const double b = 0.6;
    loadScene("stars", R"({ "camera": { "position": [0, 0, 0], "velocity": [0.6, 0, 0], "fov_deg": 170 },
        "frames": { "start": 3, "end": 4, "fps": 1 }, "model": "finite", "tolerance": "vertex",
        "objects": [ )" + objects + "] }",
              &f);
    const Scene& scene = f.stage.scene;
    const double t_c = frameTime(scene.frames, 0);
    const Vec3 c_lab{b * t_c, 0, 0};
    size_t n = 0;
    for (const PreparedObject& o : f.stage.objects) {
        const mesh4d::World4D world = buildWorld(o, Model::Finite, scene, 0, 0);
        const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, Model::Finite, 0), {});
        for (size_t i = 0; i < cut.positions.size(); ++i) {
            const Vec3 seen = cut.absolutePosition(i);
            const Vec3 lab_dir = o.spec.position + cut.rest_points[i] - c_lab;
            const double cos_t = lab_dir.x / mesh4d::norm(lab_dir);
            EXPECT_NEAR(seen.x / mesh4d::norm(seen), (cos_t + b) / std::sqrt(1 + 2 * b * cos_t + b * b), 1e-12);
            ++n;
        }
    }
    EXPECT_EQ(n, 12u * 8u);
    fs::remove_all(f.dir);
}

namespace {

struct PlyVertex {
    Vec3 x;
    double t = 0, doppler = 0;
};

// Renders `scene_json` (finite, one object of box.obj) to PLY with the light factors; frame 0.
std::vector<PlyVertex> renderPly(const std::string& name, const std::string& scene_json) {
    const fs::path dir = testio::tempPath() / ("apparent_finite_doppler_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(fs::path(APPARENT_SOURCE_DIR) / "data/meshes/box.obj", dir / "box.obj");
    std::ofstream(dir / "scene.json") << scene_json;
    const testcli::CommandResult r = testcli::apparentRun(
        {"render", (dir / "scene.json").string(), "--out", (dir / "out").string(), "--format", "ply", "--quiet"});
    EXPECT_EQ(r.code, 0) << r.err;
    std::ifstream in(dir / "out" / "finite" / "frame_00000.ply", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t end = bytes.find("end_header\n");
    EXPECT_NE(end, std::string::npos);
    const std::string header = bytes.substr(0, end);
    EXPECT_NE(header.find("property double quality\nproperty double doppler\nproperty double proper_time\nproperty uchar object\n"),
              std::string::npos)
        << header;
    const size_t n = std::stoul(header.substr(header.find("element vertex ") + 15));
    std::vector<PlyVertex> v(n);
    for (size_t i = 0; i < n; ++i) {
        double d[6];
        std::memcpy(d, bytes.data() + end + 11 + 49 * i, 48);  // x y z quality doppler proper_time, uchar object
        v[i] = {{d[0], d[1], d[2]}, d[3], d[4]};
    }
    fs::remove_all(dir);
    return v;
}

}  // namespace

// The classical Doppler factor with a moving camera, D = (1 - v.n) / (1 - u.n), n the lab direction
// from the emission point to the camera at reception: on the line of sight a camera approaching a
// source at rest at b receives 1 + b, receding 1 - b; and every vertex of an oblique case matches
// the form computed from its written (camera-frame) position and emission time.
TEST(FiniteCamera, DopplerIsTheClassicalFactorWithBothLabVelocities) {
    for (const auto& [vz, expected] : {std::pair{-0.5, 1.5}, std::pair{0.5, 0.5}}) {
        const auto v = renderPly(vz < 0 ? "approach" : "recede",
                                 R"({ "camera": { "velocity": [0, 0, )" + std::to_string(vz) + R"(] },
            "frames": { "start": 0, "end": 0.05, "fps": 10 }, "model": "finite", "tolerance": "vertex",
            "objects": [ { "mesh": "box.obj", "scale": 1e-4, "position": [0, 0, -10] } ] })");
        ASSERT_EQ(v.size(), 8u);
        for (const auto& p : v) EXPECT_NEAR(p.doppler, expected, 1e-8) << "camera vz " << vz;
    }
    const Vec3 cam_v{0.4, 0.2, -0.3}, u{-0.5, 0.1, 0.6};
    const double t_c = 2;
    const auto v = renderPly("oblique", R"({ "camera": { "position": [1, 0, 0], "velocity": [0.4, 0.2, -0.3] },
        "frames": { "start": 2, "end": 2.05, "fps": 10 }, "model": "finite", "tolerance": "vertex",
        "objects": [ { "mesh": "box.obj", "scale": 1.5, "position": [-2, 1, -6], "velocity": [-0.5, 0.1, 0.6] } ] })");
    ASSERT_EQ(v.size(), 8u);
    for (const auto& p : v) {
        const Vec3 lab_x = p.x + cam_v * p.t;  // back to the lab, by this file's map
        const Vec3 to_camera = Vec3{1, 0, 0} + cam_v * t_c - lab_x;
        EXPECT_NEAR(mesh4d::norm(to_camera), t_c - p.t, 1e-12 * t_c);  // on the lab's cone
        const Vec3 n = to_camera / mesh4d::norm(to_camera);
        EXPECT_NEAR(p.doppler, (1 - mesh4d::dot(cam_v, n)) / (1 - mesh4d::dot(u, n)), 1e-12 * p.doppler);
    }
}

namespace {

// Both one-sided distances between a refined mesh and the exact sheared surface, sampled:
// output -> exact at barycentric samples of every output triangle (the rest point interpolated
// with the position), exact -> output on a grid of every input triangle.
struct TwoSided {
    double forward = 0, backward = 0;
};
TwoSided twoSided(const mesh4d::ApparentMesh& m, const mesh4d::RestMesh& rest, const Vec3& x0, const Vec3& u,
                  double t_c, const Vec3& p, const Vec3& v, int grid) {
    static const double kSamples[7][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
                                          {1. / 3, 1. / 3, 1. / 3}};
    TwoSided r;
    for (const auto& t : m.triangles)
        for (const auto& b : kSamples) {
            Vec3 q{0, 0, 0}, out{0, 0, 0};
            for (int c = 0; c < 3; ++c) {
                q += m.rest_points[t[c]] * b[c];
                out += m.positions[t[c]] * b[c];
            }
            r.forward = std::max(r.forward, mesh4d::norm(exactImage(x0, 0, u, q, t_c, p, v).x - m.origin - out));
        }
    std::vector<std::vector<size_t>> by_source(rest.triangles.size());
    for (size_t t = 0; t < m.triangles.size(); ++t) by_source[m.source_triangles[t]].push_back(t);
    for (size_t f = 0; f < rest.triangles.size(); ++f) {
        const Vec3 a = rest.positions[rest.triangles[f][0]], b = rest.positions[rest.triangles[f][1]],
                   c = rest.positions[rest.triangles[f][2]];
        const Vec3 n = mesh4d::cross(b - a, c - a);
        for (int i = 0; i <= grid; ++i)
            for (int j = 0; i + j <= grid; ++j) {
                const double l1 = double(i) / grid, l2 = double(j) / grid;
                const Vec3 q = a * (1 - l1 - l2) + b * l1 + c * l2;
                const Vec3 exact = exactImage(x0, 0, u, q, t_c, p, v).x - m.origin;
                double best = INFINITY;
                for (size_t t : by_source[f]) {
                    const auto& ot = m.triangles[t];
                    const Vec3 p0 = m.rest_points[ot[0]], p1 = m.rest_points[ot[1]], p2 = m.rest_points[ot[2]];
                    const double area = mesh4d::dot(mesh4d::cross(p1 - p0, p2 - p0), n);
                    if (area == 0) continue;
                    const double l[3] = {mesh4d::dot(mesh4d::cross(p1 - q, p2 - q), n) / area,
                                         mesh4d::dot(mesh4d::cross(p2 - q, p0 - q), n) / area,
                                         mesh4d::dot(mesh4d::cross(p0 - q, p1 - q), n) / area};
                    if (std::min({l[0], l[1], l[2]}) < -1e-9) continue;
                    best = std::min(best, mesh4d::norm(exact - (m.positions[ot[0]] * l[0] + m.positions[ot[1]] * l[1] +
                                                                m.positions[ot[2]] * l[2])));
                }
                r.backward = std::max(r.backward, best);
            }
    }
    return r;
}

}  // namespace

// A refined finite frame from a camera at 0.9c: within T of the exact sheared surface both ways,
// for a sphere at rest in the lab (affine in the lab, curved by the shear: w = -v) and one moving
// across the camera's path (w = u - v); vertex mode is off by more than T, so the test can fail.
TEST(FiniteCamera, RefinedFramesAreWithinTheToleranceBothWays) {
    const mesh4d::RestMesh sphere = testmesh::icosphere(0, 1.0);
    const Vec3 p{0, 0, 0}, v{0.9, 0, 0};
    const double t_c = 1;
    for (const Vec3& u : {Vec3{0, 0, 0}, Vec3{0, 0.6, 0.3}}) {
        const Vec3 x0{0.5, -0.4, -3.5};
        const mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Galilean, 0.0, x0, u);
        const mesh4d::World4D w = mesh4d::extrude(sphere, m, -100, 100, false, false);
        mesh4d::ViewSurface view{mesh4d::ViewKind::PastCone, t_c, p + v * t_c};
        view.shear = v;
        const mesh4d::ApparentMesh coarse = mesh4d::sliceWorld(w, view, {});
        const double vertex_error = twoSided(coarse, sphere, x0, u, t_c, p, v, 4).forward;
        for (double tol : {3e-2, 3e-3, 3e-4}) {
            ASSERT_GT(vertex_error, tol) << "the test must be able to fail";
            mesh4d::SliceSettings s;
            s.tolerance = tol;
            s.max_segments = 4096;
            const mesh4d::ApparentMesh out = mesh4d::sliceWorld(w, view, s);
            EXPECT_EQ(out.limited_triangles, 0u);
            EXPECT_GT(out.triangles.size(), sphere.triangles.size()) << "refined";
            const TwoSided e = twoSided(out, sphere, x0, u, t_c, p, v, tol >= 3e-3 ? 9 : 7);
            EXPECT_LE(e.forward, tol) << "|u| = " << mesh4d::norm(u) << ", T = " << tol << ", " << out.triangles.size()
                                      << " triangles";
            EXPECT_LE(e.backward, tol) << "|u| = " << mesh4d::norm(u) << ", T = " << tol;
            EXPECT_GT(e.forward, 0.2 * tol) << "the bound is used, not wasted";
            std::cout << "[finite camera] |u| = " << mesh4d::norm(u) << ", T = " << tol << ": " << out.triangles.size()
                      << " triangles, error " << e.forward / tol << " T (output -> exact), " << e.backward / tol
                      << " T (exact -> output); vertex mode " << vertex_error / tol << " T\n";
        }
    }
}

// A camera at 1 - 1e-12 of light speed in the finite model: every output finite, and each vertex
// the sheared lab event to 1e-9 of the scale (the shear is exact arithmetic on bounded terms:
// nothing grows with the camera's speed in Galilean kinematics).
TEST(FiniteCamera, NearLightSpeedCameraStaysFiniteAndExact) {
    Fixture f;
    loadScene("fast", R"({ "camera": { "position": [0, 0, 0], "velocity": [0.999999999999, 0, 0] },
        "frames": { "start": -2, "end": 2, "fps": 1 }, "model": "finite", "tolerance": "vertex",
        "objects": [ { "name": "rest", "mesh": "box.obj", "position": [0, 0, -3] },
                     { "name": "with", "mesh": "box.obj", "position": [-1, 1, -3], "velocity": [0.99, 0, 0] } ] })",
              &f);
    const Scene& scene = f.stage.scene;
    for (long long k = 0; k < 4; ++k) {
        const double t_c = frameTime(scene.frames, k);
        for (const PreparedObject& o : f.stage.objects) {
            const mesh4d::World4D world = buildWorld(o, Model::Finite, scene, k, k);
            mesh4d::SliceSettings s;
            s.tolerance = 1e-3;
            for (const mesh4d::SliceSettings& settings : {mesh4d::SliceSettings{}, s}) {
                const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, Model::Finite, k), settings);
                ASSERT_FALSE(cut.positions.empty());
                for (size_t i = 0; i < cut.positions.size(); ++i) {
                    ASSERT_TRUE(mesh4d::isFinite(cut.absolutePosition(i)) && std::isfinite(cut.absoluteTime(i)));
                    const Event want = exactImage(o.spec.position, o.spec.t0, o.spec.velocity, cut.rest_points[i], t_c,
                                                  scene.camera.position, scene.camera.velocity);
                    const double scale = std::max({1.0, mesh4d::norm(want.x), std::fabs(want.t)});
                    EXPECT_LT(mesh4d::norm(cut.absolutePosition(i) - want.x), 1e-9 * scale) << o.spec.name << " frame " << k;
                }
            }
        }
    }
    fs::remove_all(f.dir);
}
