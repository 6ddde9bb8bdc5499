// The orthographic camera (scene camera.projection "orthographic") and the Vienna experiment
// (Hornof et al., Commun. Phys. 8, 161 (2025)) reproduced with it: data/scenes/vienna_cube.json and
// vienna_sphere.json, measured by `apparent measure` (pipeline/commands/measure.h) and by this file's own
// computations.
//
// The far-field view. An orthographic camera looking along the unit vector k sees the light that
// crosses its image plane (through C, normal to k) at the frame's time t_c travelling along -k:
// light emitted at (t, x) crosses the plane at t + (x - C).k, so the events seen lie on the null
// hyperplane t = t_c - (x - C).k (mesh4d/lightcone.h). A point moving as x(t) = C + e + v (t - t_c)
// (e: where it is at t_c) emits d before t_c with t_c - d = t_c - (e - v d).k, so
//     d = e.k / (1 + v.k),     image point y = C + e - v d.
// Terrell's rotation. Let v = b r (r the image's right axis, u its up axis, k normal to both), a
// body of rest coordinates (X, Y, Z) along (r, u, -k) (Z towards the camera), Lorentz-contracted
// along r: its point at t_c sits at e = e0 + (X / g) r + Y u - Z k with g = 1/sqrt(1 - b^2). Then
// e.k = e0.k - Z, and the image coordinates are
//     x = (e0 - v e0.k).r + X / g + b Z,     y = e0.u + Y.
// With cos(theta) = 1/g and sin(theta) = b: x = const + X cos(theta) + Z sin(theta), which is the
// projection along k of the body turned by theta = asin(b) about u (right-handed: the front, normal
// +Z, turns towards +r). So the cube of edge 1 at b = 0.8 shows its front face 0.6 wide and its
// trailing face (X = -1/2, normal -r) 0.8 wide: tan(theta) = 0.8 / 0.6, theta = 53.130 degrees.
// The finite model (Galilean, no contraction) of a cuboid with X already 1/g as long gives the same
// x = const + X' + b Z with X' = X / g: the same image, and the same 3D points (the experiment's
// pre-contracted lab twin).
// Penrose's sphere. The image of the sphere |(X, Y, Z)| = R is {(X cos(theta) + Z sin(theta), Y)},
// the outline of a turned sphere: a circle of radius R about the image of the centre. Its pole
// facing the camera, (0, 0, R), lands at x = R sin(theta) = b R from the centre: at b = 0.999 of the
// rim radius, next to the rim, facing along r. The mesh (data/meshes/icosphere20480.obj) has that
// pole as a vertex, and every point of the sphere within about 1.2 degrees of one (edge about 2
// degrees), so its outline is round within 1 - cos(1.2 deg) = 2.2e-4 and the rim radius, the largest
// distance of an image vertex from the centre, is R within far less.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mesh4d/angles.h"
#include "mesh4d/exact_side.h"
#include "mesh4d/lightcone.h"
#include "pipeline/commands/measure.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/view_hints.h"
#include "pipeline/trace/raytrace.h"
#include "quiet_stage.h"
#include "run_command.h"
#include "temp_dir.h"

using namespace apparent;
using mesh4d::Vec3;

namespace {

std::string source(const std::string& rel) { return std::string(APPARENT_SOURCE_DIR) + "/" + rel; }

std::string writeScene(const std::string& name, const std::string& text) {
    const std::string path = testio::processTempDir() + name;
    std::ofstream(path) << text;
    return path;
}

// The frame at camera time t of `model`, cut as `render` cuts it.
ExportFrame cutAt(const Stage& stage, Model model, double t) {
    FrameCutter cutter(stage, model);
    ExportFrame frame;
    std::string error;
    EXPECT_TRUE(cutter.cut(t, 0, &frame, &error)) << error;
    return frame;
}

}  // namespace

// The cut of one worldline against the closed form d = e.k / (1 + v.k) and against the side
// function solved by bisection (the event seen has h = 0).
TEST(Orthographic, WorldlineCutMatchesClosedFormAndBisection) {
    mesh4d::ViewSurface view;
    view.kind = mesh4d::ViewKind::Hyperplane;
    view.t_c = 7;
    view.apex = {1, 2, 3};
    const Vec3 k0{0.3, -0.4, -1};
    view.tilt = k0 / mesh4d::norm(k0);
    const Vec3 v{0.5, 0.2, 0.6};
    const mesh4d::Event anchor{-2, {4, -1, -9}};
    const double one_minus_b2 = 1 - mesh4d::norm2(v);
    const mesh4d::Event seen = mesh4d::cutWorldline(view, anchor, v, one_minus_b2).event;
    // Closed form, written out.
    const Vec3 e = anchor.x + v * (view.t_c - anchor.t) - view.apex;
    const double d = mesh4d::dot(e, view.tilt) / (1 + mesh4d::dot(v, view.tilt));
    EXPECT_NEAR(seen.t, view.t_c - d, 1e-13);
    EXPECT_NEAR(mesh4d::norm(seen.x - (view.apex + e - v * d)), 0, 1e-13);
    // Bisection on h(t) = t_c - t - (x(t) - C).k, decreasing in t.
    long double lo = -100, hi = 100;
    for (int i = 0; i < 200; ++i) {
        const long double t = 0.5L * (lo + hi);
        const long double x[3] = {anchor.x.x + v.x * (t - anchor.t), anchor.x.y + v.y * (t - anchor.t), anchor.x.z + v.z * (t - anchor.t)};
        const long double h = view.t_c - t - ((x[0] - view.apex.x) * view.tilt.x + (x[1] - view.apex.y) * view.tilt.y +
                                              (x[2] - view.apex.z) * view.tilt.z);
        (h > 0 ? lo : hi) = t;
    }
    EXPECT_NEAR(seen.t, double(lo), 1e-12);
    EXPECT_EQ(mesh4d::viewSideSign(view, {double(lo) + 1e-6, seen.x}), -1);
    EXPECT_EQ(mesh4d::viewSideSign(view, {double(lo) - 1e-6, seen.x}), 1);
}

TEST(Orthographic, ExactSideOfTheTiltedHyperplane) {
    mesh4d::ViewSurface view;
    view.kind = mesh4d::ViewKind::Hyperplane;
    view.t_c = 1;
    view.tilt = {0, 0, -1};
    // t = 1 - (x - 0).k = 1 + z: on it exactly, a hair before and after.
    EXPECT_EQ(mesh4d::viewSideSign(view, {-2, {5, 7, -3}}), 0);
    EXPECT_EQ(mesh4d::viewSideSign(view, {std::nextafter(-2.0, 0.0), {5, 7, -3}}), -1);
    EXPECT_EQ(mesh4d::viewSideSign(view, {std::nextafter(-2.0, -3.0), {5, 7, -3}}), 1);
}

// The Vienna cube in relativistic: turned by asin(0.8), by `apparent measure`'s fit and by the
// widths of its faces in the image (this file's own computation).
TEST(Orthographic, ViennaCubeTurnedByAsinBeta) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/vienna_cube.json"), &stage, &error, {Model::Relativistic})) << error;
    ASSERT_EQ(stage.objects[0].spec.name, "cube");
    const ExportFrame frame = cutAt(stage, Model::Relativistic, 3.0);
    const mesh4d::ApparentMesh& cube = frame.objects[0];
    ASSERT_EQ(cube.positions.size(), 8u);
    const double expected = std::asin(0.8) * 180 / mesh4d::kPi;  // 53.1301...
    // The command's fit of the projected face areas.
    const ImageAxes axes = imageAxes(stage.scene.camera);
    const ApparentMeasure m = measureApparent(cube, axes);
    ASSERT_TRUE(m.has_rotation);
    EXPECT_NEAR(m.rotation_deg, expected, 0.01);
    EXPECT_NEAR(m.rotation_residual, 0, 1e-9);
    EXPECT_NEAR(m.rotation_scale, 1, 1e-9);
    // Own computation: image x (along the camera's right, here +x) of the front face's corners (rest
    // z = +0.5, towards the camera) and of the trailing face's (rest x = -0.5); tan = side / front.
    double front_lo = INFINITY, front_hi = -INFINITY, side_lo = INFINITY, side_hi = -INFINITY;
    for (size_t i = 0; i < cube.positions.size(); ++i) {
        const double x = cube.absolutePosition(i).x;
        if (cube.rest_points[i].z > 0) front_lo = std::min(front_lo, x), front_hi = std::max(front_hi, x);
        if (cube.rest_points[i].x < 0) side_lo = std::min(side_lo, x), side_hi = std::max(side_hi, x);
    }
    const double front = front_hi - front_lo, side = side_hi - side_lo;
    EXPECT_NEAR(front, 0.6, 1e-12);
    EXPECT_NEAR(side, 0.8, 1e-12);
    EXPECT_NEAR(std::atan2(side, front) * 180 / mesh4d::kPi, expected, 0.01);
    std::cout << "vienna cube: fit " << m.rotation_deg << " deg, face widths " << front << " and " << side << " give "
              << std::atan2(side, front) * 180 / mesh4d::kPi << " deg, asin(0.8) = " << expected << " deg\n";
}

// The same through the command line: `apparent measure` prints the angle.
TEST(Orthographic, MeasureCommandPrintsTheAngle) {
    const testcli::CommandResult r =
        testcli::apparentRun({"measure", source("data/scenes/vienna_cube.json"), "--frames", "20:21", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::istringstream lines(r.out);
    std::string line;
    bool found = false;
    while (std::getline(lines, line)) {
        if (line.rfind("relativistic\t20\t", 0) != 0 || line.find("\tcube\t") == std::string::npos) continue;
        std::vector<std::string> cols;
        std::istringstream cells(line);
        for (std::string c; std::getline(cells, c, '\t');) cols.push_back(c);
        ASSERT_GE(cols.size(), 10u) << line;
        EXPECT_NEAR(std::stod(cols[9]), std::asin(0.8) * 180 / mesh4d::kPi, 0.01) << line;
        found = true;
    }
    EXPECT_TRUE(found) << r.out;
}

// The experiment's lab twin (1 x 1 x 0.6, finite light speed, Galilean) gives the relativistic
// cube's apparent mesh: every point the same to 1e-12 of the size (the twin sits 1.6 lower).
TEST(Orthographic, FiniteTwinEqualsRelativisticCube) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/vienna_cube.json"), &stage, &error,
                               {Model::Finite, Model::Relativistic}))
        << error;
    for (double t : {1.0, 2.35, 3.0, 4.9}) {
        const ExportFrame rel = cutAt(stage, Model::Relativistic, t);
        const ExportFrame fin = cutAt(stage, Model::Finite, t);
        const mesh4d::ApparentMesh &cube = rel.objects[0], &twin = fin.objects[1];
        ASSERT_EQ(cube.positions.size(), twin.positions.size());
        ASSERT_EQ(cube.triangles, twin.triangles);
        double worst = 0;
        for (size_t i = 0; i < cube.positions.size(); ++i) {
            worst = std::max(worst, mesh4d::norm(cube.absolutePosition(i) - (twin.absolutePosition(i) + Vec3{0, 1.6, 0})));
            EXPECT_NEAR(cube.absoluteTime(i), twin.absoluteTime(i), 1e-12);
        }
        EXPECT_LE(worst, 1e-12 * std::sqrt(3.0)) << "t = " << t;
    }
}

// The Vienna sphere at 0.999c: a round outline, the pole at 0.999 of the rim radius.
TEST(Orthographic, ViennaSphereRoundWithThePoleAtTheRim) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/vienna_sphere.json"), &stage, &error, {Model::Relativistic})) << error;
    ASSERT_EQ(stage.objects[1].spec.name, "pole");
    const ImageAxes axes = imageAxes(stage.scene.camera);
    for (double t : {3.0, 4.0, 5.5}) {
        const ExportFrame frame = cutAt(stage, Model::Relativistic, t);
        const mesh4d::ApparentMesh &sphere = frame.objects[0], &pole = frame.objects[1];
        // The command's measures: roundness and the marker's place.
        const ApparentMeasure s = measureApparent(sphere, axes), p = measureApparent(pole, axes);
        EXPECT_LT(s.rim_radius / s.min_radius - 1, 1e-3) << "t = " << t;
        const double dx = p.mean[0] - s.centre[0], dy = p.mean[1] - s.centre[1];
        EXPECT_NEAR(std::hypot(dx, dy) / s.rim_radius, 0.999, 1e-4) << "t = " << t;
        // Own computation: the centre is the mean of the image vertices (the mesh is symmetric
        // about its centre and the picture affine), the rim the largest distance from it, the pole
        // the vertex whose rest point is (0, 0, 1).
        double cx = 0, cy = 0;
        const size_t n = sphere.positions.size();
        for (size_t i = 0; i < n; ++i) cx += sphere.absolutePosition(i).x / double(n), cy += sphere.absolutePosition(i).y / double(n);
        double rim = 0, pole_r = -1;
        for (size_t i = 0; i < n; ++i) {
            const double r = std::hypot(sphere.absolutePosition(i).x - cx, sphere.absolutePosition(i).y - cy);
            rim = std::max(rim, r);
            if (mesh4d::norm(sphere.rest_points[i] - Vec3{0, 0, 1}) < 1e-12) pole_r = r;
        }
        ASSERT_GE(pole_r, 0);
        EXPECT_NEAR(rim, 1, 1e-4);
        EXPECT_NEAR(pole_r / rim, 0.999, 1e-4) << "t = " << t;
        if (t == 4.0)
            std::cout << "vienna sphere at t = 4: roundness " << s.rim_radius / s.min_radius << ", marker at "
                      << std::hypot(dx, dy) / s.rim_radius << " of the rim; own: pole vertex at " << pole_r / rim << "\n";
    }
}

// The raytracer's orthographic picture: the cube's image 1.4 wide (front 0.6 and side 0.8) in a view
// 5 wide, so 1.4 / 5 of the pixels of a row through its middle.
TEST(Orthographic, RaytracedCubeWidth) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/vienna_cube.json"), &stage, &error, {Model::Relativistic})) << error;
    const int width = 500, height = 280;
    const long long k = 20;  // t = 3
    SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, Model::Relativistic, k, k);
    const TracedFrame frame = tracer.traceFrame(k, width, height);
    // The cube's middle row: y = 0.8 is 0.8 / (5 * 280 / 500 / 2) of the half height above the centre.
    const double half_h = 0.5 * 5.0 * height / width;
    const int row = int(std::lround((1 - 0.8 / half_h) * height / 2 - 0.5));
    int hits = 0, first = -1;
    for (int px = 0; px < width; ++px)
        if (frame.object[size_t(row) * width + px] == 0) {
            ++hits;
            if (first < 0) first = px;
        }
    EXPECT_NEAR(hits, 1.4 / 5.0 * width, 1.5);
    // Its left edge: the trailing face's far corner, X = Z = -1/2: x = 0.8 (3 - 3) - 0.3 - 0.4 = -0.7.
    EXPECT_NEAR(first, (-0.7 / 5.0 + 0.5) * width, 1.5);
}

TEST(Orthographic, SceneFields) {
    const std::string base = R"({"objects": [{"mesh": ")" + source("data/meshes/box.obj") + R"("}], "camera": {)";
    Scene scene;
    Status s = loadScene(writeScene("ortho_nowidth.json", base + R"("projection": "orthographic"}})"), &scene);
    EXPECT_FALSE(s.ok);
    EXPECT_NE(s.message.find("camera.width: missing"), std::string::npos) << s.message;
    s = loadScene(writeScene("ortho_zero.json", base + R"("projection": "orthographic", "width": 0}})"), &scene);
    EXPECT_NE(s.message.find("camera.width: must be > 0"), std::string::npos) << s.message;
    s = loadScene(writeScene("ortho_bad.json", base + R"("projection": "fisheye"}})"), &scene);
    EXPECT_NE(s.message.find("camera.projection: expected"), std::string::npos) << s.message;
    s = loadScene(writeScene("persp_width.json", base + R"("width": 3}})"), &scene);
    ASSERT_TRUE(s.ok) << s.message;
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("camera.width: ignored"), std::string::npos) << scene.warnings[0];
    s = loadScene(writeScene("ortho_ok.json", base + R"("projection": "orthographic", "width": 3}})"), &scene);
    ASSERT_TRUE(s.ok) << s.message;
    EXPECT_TRUE(scene.camera.orthographic());
    EXPECT_EQ(scene.camera.width, 3);
    // What the orthographic camera does not model is refused, with exit code 2.
    const std::string spin = writeScene("ortho_spin.json", R"({"objects": [{"mesh": ")" + source("data/meshes/box.obj") +
                                                               R"(", "angular_velocity": [0, 0.1, 0]}], "camera": {"projection": "orthographic", "width": 3}})");
    const testcli::CommandResult r = testcli::apparentRun({"render", spin, "--out", testio::processTempDir() + "spin_out"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("not modelled with camera.projection \"orthographic\""), std::string::npos) << r.err;
}

// The .glb's camera: glTF's orthographic camera, xmag half the width.
TEST(Orthographic, GlbCamera) {
    const std::string out = testio::processTempDir() + "ortho_glb";
    const testcli::CommandResult r =
        testcli::apparentRun({"render", source("data/scenes/vienna_cube.json"), "--out", out, "--frames", "0:2", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream in(out + "/relativistic.glb", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 20u);
    uint32_t json_length = 0;
    std::memcpy(&json_length, bytes.data() + 12, 4);
    const nlohmann::json doc = nlohmann::json::parse(bytes.substr(20, json_length));
    const auto& camera = doc["cameras"][0];
    EXPECT_EQ(camera["type"], "orthographic");
    EXPECT_DOUBLE_EQ(camera["orthographic"]["xmag"].get<double>(), 2.5);
    EXPECT_GT(camera["orthographic"]["zfar"].get<double>(), camera["orthographic"]["znear"].get<double>());
    // Through job-array shards and merge (the shard header carries the camera): the same file.
    const std::string sharded = testio::processTempDir() + "ortho_shards";
    for (const char* shard : {"0/2", "1/2"})
        ASSERT_EQ(testcli::apparentRun({"render", source("data/scenes/vienna_cube.json"), "--out", sharded, "--frames", "0:2",
                                        "--quiet", "--shard", shard})
                      .code,
                  0);
    ASSERT_EQ(testcli::apparentRun({"merge", sharded, "--quiet"}).code, 0);
    std::ifstream merged_in(sharded + "/relativistic.glb", std::ios::binary);
    const std::string merged((std::istreambuf_iterator<char>(merged_in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(merged, bytes);
}

// Hints instead of blanks: the contracted model of a scene whose object is far from the camera, with
// no camera.instant_delay, names the object, the model and the look-back to set.
TEST(Orthographic, OutOfViewHintNamesTheCause) {
    const std::string path = writeScene("far.json", R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 20},
        "frames": {"start": 80, "end": 82, "fps": 1},
        "objects": [{"name": "far cube", "mesh": ")" + source("data/meshes/box.obj") +
                                                    R"(", "position": [0, 0, -80], "velocity": [0.8, 0, 0]}]})");
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(path, &stage, &error, {Model::Contracted, Model::Relativistic})) << error;
    const std::vector<std::string> contracted = outOfViewWarnings(stage, Model::Contracted, {0, 1});
    ASSERT_EQ(contracted.size(), 1u);
    EXPECT_NE(contracted[0].find("far cube"), std::string::npos) << contracted[0];
    EXPECT_NE(contracted[0].find("model contracted"), std::string::npos) << contracted[0];
    EXPECT_NE(contracted[0].find("camera.instant_delay"), std::string::npos) << contracted[0];
    EXPECT_TRUE(outOfViewWarnings(stage, Model::Relativistic, {0, 1}).empty());
    // The figure prints it.
    const testcli::CommandResult r = testcli::apparentRun(
        {"figure", path, "--models", "contracted", "--frames", "0:1", "--size", "32x18", "--no-labels", "--out",
         testio::processTempDir() + "far.png"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + path + ": objects[0] (\"far cube\"): outside the camera's view in every frame of "
                         "model contracted (frames 0..0); model relativistic sees it"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("set camera.instant_delay to about that"), std::string::npos) << r.err;
}
