// The paper's 4D raytracer (mesh4d/ray4d.h, pipeline/trace/raytrace.h): hits against the closed-form
// retarded point, the lab normal against the boosted triangle, PNG round trip, command errors,
// and the cross-check of both: the apparent meshes of the cone cut, ray-cast in plain 3D from
// the camera, show the same object as the 4D raytracer in at least 99% of the covered pixels.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <sstream>

#include <unistd.h>

#include "exporters/png.h"
#include "exporters/text.h"
#include "mesh4d/angles.h"
#include "mesh4d/doppler_colour.h"
#include "mesh4d/ray4d.h"
#include "mesh4d/slice.h"
#include "pipeline/commands/cli.h"
#include "pipeline/stage/mirror.h"
#include "pipeline/stage/worlds.h"
#include "pipeline/trace/raytrace.h"
#include "keyed_gltf.h"
#include "test_meshes.h"
#include "mesh_caster.h"
#include "quiet_stage.h"

#include "temp_dir.h"
#include "srgb.h"

using namespace apparent;
using mesh4d::Vec3;

namespace {

std::string source(const std::string& rel) { return std::string(APPARENT_SOURCE_DIR) + "/" + rel; }

// Absolute lab position of output point i (the one place that knows how ApparentMesh stores them).
Vec3 absolutePoint(const mesh4d::ApparentMesh& m, size_t i) { return m.absolutePosition(i); }

// Two triangles of a 2 x 2 square in z = 0 (rest frame), corners (-1,-1) .. (1,1).
mesh4d::RestMesh square() {
    mesh4d::RestMesh m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

}  // namespace

// A square at rest 5 light-seconds ahead: the ray along the axis meets it at s = 5, i.e. at the
// event 5 s before the camera time; along the hyperplane the event is at the camera time.
TEST(Ray4D, StaticSquareOnTheAxis) {
    const mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Galilean, 0, {0, 0, -5}, {0, 0, 0});
    const mesh4d::World4D w = mesh4d::extrude(square(), m, -100, 100, false, false);
    const mesh4d::TraceWorld tw = mesh4d::prepareTrace(w);
    mesh4d::Ray4D ray;
    ray.origin = {3, {0.25, 0.1, 0}};
    ray.direction = {0, 0, -1};
    const auto hit = mesh4d::intersectWorld(tw, ray, INFINITY);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->s, 5, 1e-12);
    EXPECT_NEAR(hit->event.t, -2, 1e-12);
    EXPECT_NEAR(std::fabs(hit->lab_normal.z), 1, 1e-15);
    ray.along_cone = false;
    const auto flat = mesh4d::intersectWorld(tw, ray, INFINITY);
    ASSERT_TRUE(flat);
    EXPECT_NEAR(flat->event.t, 3, 0);
    // Outside the square, and behind the camera: misses.
    ray.origin.x = {1.5, 0, 0};
    EXPECT_FALSE(mesh4d::intersectWorld(tw, ray, INFINITY));
    ray.origin.x = {0, 0, -10};
    EXPECT_FALSE(mesh4d::intersectWorld(tw, ray, INFINITY));
}

// For random rest points on a moving square (speeds up to 0.99c, both kinematics, random
// directions), the ray from the camera towards the point's closed-form apparent position
// (docs/DESIGN.md section 5, lightcone.h) hits the 4D history at that distance and emission time.
TEST(Ray4D, HitsTheClosedFormRetardedPoint) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0;
    for (int iter = 0; iter < 400; ++iter) {
        const double beta = std::vector<double>{0, 0.5, 0.866, 0.99}[size_t(iter % 4)];
        const auto kin = iter % 8 < 4 ? mesh4d::Kinematics::Galilean : mesh4d::Kinematics::Lorentz;
        Vec3 dir{u(rng), u(rng), u(rng)};
        dir = dir / mesh4d::norm(dir);
        const mesh4d::Motion m = mesh4d::makeMotion(kin, 0, {u(rng) * 3, u(rng) * 3, -8 + u(rng)}, dir * beta);
        const mesh4d::World4D w = mesh4d::extrude(square(), m, -1e4, 1e4, false, false);
        const mesh4d::TraceWorld tw = mesh4d::prepareTrace(w);
        mesh4d::ViewSurface view;
        view.t_c = u(rng) * 5;
        const double a = 0.5 * (u(rng) + 1), b = 0.5 * (u(rng) + 1) * (1 - a);  // inside triangle 0
        const Vec3 q = (1 - a - b) * w.mesh.positions[0] + a * w.mesh.positions[1] + b * w.mesh.positions[2];
        const mesh4d::Event e = mesh4d::exactApparentPoint(w, view, q);
        const double dist = mesh4d::norm(e.x - view.apex);
        mesh4d::Ray4D ray;
        ray.origin = {view.t_c, view.apex};
        ray.direction = (e.x - view.apex) / dist;
        const auto hit = mesh4d::intersectWorld(tw, ray, INFINITY);
        ASSERT_TRUE(hit) << "iter " << iter << " beta " << beta;
        // The square may hide itself only at grazing angles; the nearest hit is never farther.
        EXPECT_LE(hit->s, dist * (1 + 1e-9)) << iter;
        if (hit->triangle == 0 || std::fabs(hit->s - dist) < 1e-6 * dist) {
            EXPECT_NEAR(hit->s, dist, 1e-9 * dist) << "iter " << iter;
            EXPECT_NEAR(hit->event.t, e.t, 1e-9 * dist) << "iter " << iter;
            worst = std::max(worst, std::fabs(hit->s - dist) / dist);
        }
    }
    std::cout << "[ray4d] worst relative distance error against the closed form: " << worst << "\n";
}

// The lab normal at a hit is that of the object's triangle at one lab instant: under a boost the
// contracted triangle's normal (labPositionAt at equal t), under a shear the rest normal.
TEST(Ray4D, LabNormalIsTheTriangleAtOneLabInstant) {
    mesh4d::RestMesh tri;
    tri.positions = {{0, 0, 0}, {1, 0.2, 0.5}, {0.3, 1, -0.4}};
    tri.triangles = {{0, 1, 2}};
    for (const auto kin : {mesh4d::Kinematics::Galilean, mesh4d::Kinematics::Lorentz}) {
        const mesh4d::Motion m = mesh4d::makeMotion(kin, 0, {0, 0, -5}, {0.6, 0, 0.5});
        const mesh4d::World4D w = mesh4d::extrude(tri, m, -10, 10, false, false);
        const auto t = w.tet(0);
        const auto n4 = mesh4d::flatNormal({w.events[t[0]], w.events[t[1]], w.events[t[2]], w.events[t[3]]});
        Vec3 n{n4[1], n4[2], n4[3]};
        n = n / mesh4d::norm(n);
        const Vec3 p0 = mesh4d::labPositionAt(m, tri.positions[0], 1.5), p1 = mesh4d::labPositionAt(m, tri.positions[1], 1.5),
                   p2 = mesh4d::labPositionAt(m, tri.positions[2], 1.5);
        Vec3 expect = mesh4d::cross(p1 - p0, p2 - p0);
        expect = expect / mesh4d::norm(expect);
        EXPECT_NEAR(std::fabs(mesh4d::dot(n, expect)), 1, 1e-14);
        // The Lorentz normal differs from the rest normal (the test can see the contraction).
        Vec3 rest = mesh4d::cross(tri.positions[1] - tri.positions[0], tri.positions[2] - tri.positions[0]);
        rest = rest / mesh4d::norm(rest);
        if (kin == mesh4d::Kinematics::Lorentz) EXPECT_LT(std::fabs(mesh4d::dot(n, rest)), 0.999);
        else EXPECT_NEAR(std::fabs(mesh4d::dot(n, rest)), 1, 1e-14);
    }
}

TEST(Mirror, ReflectionIsAnInvolutionAndKeepsPathLengths) {
    MirrorPlane m{0, {0, 0, -23.675}, {0, 0, 1}};
    const Vec3 c{0, 0, 0}, x{3, 1, -18}, mp{1.2, 0.3, -23.675};
    EXPECT_EQ(reflectPoint(m, reflectPoint(m, x)), x);
    // Any path camera -> mirror point -> x is as long as mirror point -> x plus mirror point -> image camera.
    EXPECT_NEAR(mesh4d::norm(mp - c), mesh4d::norm(mp - reflectPoint(m, c)), 1e-12);
    EXPECT_EQ(reflectPoint(m, c), Vec3(0, 0, -47.35));
}

TEST(Png, RoundTrip) {
    RgbImage img(7, 3);
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = uint8_t(i * 37);
    const std::string path = (testio::tempPath() / ("apparent_png_" + std::to_string(::getpid()) + ".png")).string();
    std::string error;
    ASSERT_TRUE(writePng(path, img, &error)) << error;
    RgbImage back;
    ASSERT_TRUE(readPng(path, &back, &error)) << error;
    EXPECT_EQ(back.width, 7);
    EXPECT_EQ(back.height, 3);
    EXPECT_EQ(back.rgb, img.rgb);
    std::filesystem::remove(path);
    EXPECT_FALSE(writePng("/nonexistent-dir/x.png", img, &error));
    EXPECT_NE(error.find("/nonexistent-dir/x.png"), std::string::npos) << error;
}

namespace {

struct CommandRun {
    int code;
    std::string out, err;
};

CommandRun run(std::vector<std::string> args) {
    args.insert(args.begin(), "apparent");
    std::vector<const char*> argv;
    for (const auto& a : args) argv.push_back(a.c_str());
    std::ostringstream out, err;
    const int code = runCommandLine(int(argv.size()), argv.data(), out, err);
    return {code, out.str(), err.str()};
}

}  // namespace

TEST(RaytraceCommand, WritesPngFramesAndRefusesBadInput) {
    const auto dir = testio::tempPath() / ("apparent_rt_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    const CommandRun r = run({"raytrace", source("data/scenes/flanges.json"), "--out", dir.string(), "--model",
                       "instant,relativistic", "--size", "64x36", "--frames", "99:101"});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* f : {"instant/frame_00099.png", "instant/frame_00100.png", "relativistic/frame_00100.png"}) {
        RgbImage img;
        std::string error;
        ASSERT_TRUE(readPng((dir / f).string(), &img, &error)) << error;
        EXPECT_EQ(img.width, 64);
        EXPECT_EQ(img.height, 36);
    }
    std::filesystem::remove_all(dir);
    const std::pair<std::vector<std::string>, std::string> bad[] = {
        {{"raytrace", source("data/scenes/flanges.json"), "--size", "64by36"}, "--size: '64by36' is not WxH"},
        {{"raytrace", source("data/scenes/flanges.json"), "--model", "slow"}, "--model: unknown model 'slow'"},
        {{"raytrace", source("data/fixtures/scene_mirror_not_planar.json"), "--out", dir.string()},
         "scene_mirror_not_planar.json: objects[0].mirror: the mesh is not planar"},
        {{"raytrace", source("data/fixtures/scene_mirror_moving.json"), "--out", dir.string()},
         "scene_mirror_moving.json: objects[0].mirror: a mirror must be at rest"},
        {{"figure", source("data/scenes/flanges.json"), "--columns", "0"}, "--columns: must be in 1..64"},
        {{"figure", source("data/scenes/flanges.json"), "--times", "99"}, "--times: t = 99 s is outside the scene's frames (0 to 19.9 s)"},
        {{"figure", source("data/scenes/flanges.json"), "--times", "5,x"}, "--times: 'x' is not a number"},
        {{"figure", source("data/scenes/flanges.json"), "--models", "slow"}, "--models: unknown model 'slow'"},
        {{"figure", source("data/scenes/flanges.json"), "--video", "v.mp4", "--times", "3"}, "--times: not with --video"},
    };
    for (const auto& [args, expected] : bad) {
        const CommandRun b = run(args);
        EXPECT_EQ(b.code, 2) << expected;
        EXPECT_NE(b.err.find(expected), std::string::npos) << b.err;
        EXPECT_EQ(std::count(b.err.begin(), b.err.end(), '\n'), 1) << b.err;
    }
    EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(RaytraceCommand, FigureLaysOutRowsAndColumns) {
    const auto path = testio::tempPath() / ("apparent_sheet_" + std::to_string(::getpid()) + ".png");
    const CommandRun r = run({"figure", source("data/scenes/flanges.json"), "--out", path.string(), "--columns", "2",
                                 "--size", "32x18", "--quiet", "--no-labels"});
    ASSERT_EQ(r.code, 0) << r.err;
    RgbImage img;
    std::string error;
    ASSERT_TRUE(readPng(path.string(), &img, &error)) << error;
    // Two 32-pixel columns and three 18-pixel rows, with 4-pixel gaps around and between (no label bands).
    EXPECT_EQ(img.width, 2 * 32 + 3 * 4);
    EXPECT_EQ(img.height, 3 * 18 + 4 * 4);
    std::filesystem::remove(path);
}

// The light's and the mirrors' scene fields give one-line errors naming the field.
TEST(RaytraceScene, BadLightAndMirrorFields) {
    const auto dir = testio::tempPath() / ("apparent_scenes_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::pair<const char*, const char*> cases[] = {
        {R"("light": {"position": [0, 1, 0], "direction": [0, 1, 0]})", "light: give exactly one of position"},
        {R"("light": {"direction": [0, 1, 0], "ambient": 2})", "light.ambient: must be in [0, 1]"},
        {R"("light": {"direction": [0, 0, 0]})", "light.direction: must be non-zero"},
        {R"("light": {"colour": [1, 1, 1], "direction": [0, 1, 0]})", "light.colour: unknown field"},
        {R"("camera": {"instant_delay": "soon"})", "camera.instant_delay: expected a number"},
        {R"("camera": {"fov": 40})", "camera.fov: unknown field (did you mean fov_deg?; known: position, look_at"},
        {R"("light": {"ambiant": 0.2, "direction": [0, 1, 0]})", "light.ambiant: unknown field (did you mean ambient?;"},
    };
    for (const auto& [field, expected] : cases) {
        const auto path = dir / "scene.json";
        std::ofstream(path) << "{ " << field << R"(, "objects": [{"mesh": ")" << source("data/fixtures/tetra.obj")
                            << R"("}] })";
        Scene scene;
        const Status st = loadScene(path.string(), &scene);
        EXPECT_FALSE(st.ok) << field;
        EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
        EXPECT_EQ(st.message.find('\n'), std::string::npos);
    }
    std::filesystem::remove_all(dir);
}

using testcast::MeshCaster;

// The cross-check on one scene with one mirror, every model, every `stride`-th frame
// at 240 x 135: the object each pixel shows first, by the 4D raytracer and by a 3D ray cast over
// the cone cut's output (tolerance 1e-3 ls), agree on >= 99% of covered pixels; so do the
// reflections where the raytracer's ray meets the mirror. Returns per model the frames whose
// reflections are empty (`empty_reflections`). A scene without a mirror (the fly-by) checks the
// objects alone; "moving" there means moving relative to the camera.
namespace {

struct CrossCheckResult {
    std::map<Model, std::vector<long long>> empty_reflections;
};

void crossCheck(const std::string& scene_file, long long stride, long long min_mirror_pixels, CrossCheckResult* result) {
    Scene scene;
    ASSERT_TRUE(loadScene(source(scene_file), &scene).ok);
    std::vector<PreparedObject> objects;
    std::ostringstream log;
    ASSERT_TRUE(prepareObjects(scene, {}, &objects, log, true).ok);
    std::vector<MirrorPlane> mirrors;
    ASSERT_TRUE(findMirrors(objects, scene.path, &mirrors).ok);
    const int w = 240, h = 135;
    const long long frames = frameCount(scene.frames);
    mesh4d::SliceSettings slice;
    slice.tolerance = 1e-3;
    for (Model model : {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted}) {
        if (!checkSceneForModel(scene, model).ok) {  // a model the scene cannot be shown in
            std::cout << "[cross-check] " << modelName(model) << ": refused for this scene, skipped\n";
            continue;
        }
        SceneTracer tracer(scene, objects, mirrors, model, 0, frames - 1);
        std::vector<mesh4d::World4D> worlds;
        for (const auto& o : objects) worlds.push_back(buildWorld(o, model, scene, 0, frames - 1));
        const MirrorReflections reflections(scene, objects, mirrors, model, 0, frames - 1);
        std::vector<int32_t> reflected_object;  // scene index of each reflection mesh (one mirror)
        for (size_t i = 0; i < objects.size() && !mirrors.empty(); ++i)
            if (!objects[i].spec.mirror) reflected_object.push_back(int32_t(i));
        ASSERT_LE(mirrors.size(), 1u);
        long long covered = 0, agree = 0, moving_covered = 0, moving_agree = 0, mirror_covered = 0, mirror_agree = 0;
        auto moving = [&](int32_t id) {
            return id >= 0 && mesh4d::norm(scene.objects[size_t(id)].velocity - scene.camera.velocity) > 0;
        };
        double worst_frame = 1;
        for (long long k = 0; k < frames; k += stride) {
            const TracedFrame traced = tracer.traceFrame(k, w, h);
            MeshCaster caster(scene.camera, w, h);
            const mesh4d::ViewSurface view = viewForFrame(scene, model, k);
            std::vector<mesh4d::ApparentMesh> cut;  // the scene's objects, then their reflections
            for (size_t i = 0; i < worlds.size(); ++i) {
                cut.push_back(mesh4d::sliceWorld(worlds[i], view, slice));
                const mesh4d::ApparentMesh& m = cut.back();
                for (const auto& t : m.triangles)
                    caster.add(absolutePoint(m, t[0]), absolutePoint(m, t[1]), absolutePoint(m, t[2]), int32_t(i));
            }
            // The reflections, cast on their own: behind the mirror, they show where the ray bounces.
            MeshCaster mirror_caster(scene.camera, w, h);
            reflections.append(view, slice, &cut);
            ASSERT_EQ(cut.size(), worlds.size() + reflected_object.size());
            size_t reflected_triangles = 0;
            for (size_t i = worlds.size(); i < cut.size(); ++i) reflected_triangles += cut[i].triangles.size();
            if (reflected_triangles == 0 && result) result->empty_reflections[model].push_back(k);
            for (size_t i = 0; i < reflected_object.size(); ++i) {
                const mesh4d::ApparentMesh& r = cut[worlds.size() + i];
                for (const auto& t : r.triangles)
                    mirror_caster.add(absolutePoint(r, t[0]), absolutePoint(r, t[1]), absolutePoint(r, t[2]),
                                      reflected_object[i]);
            }
            long long frame_covered = 0, frame_agree = 0;
            for (int py = 0; py < h; ++py)
                for (int px = 0; px < w; ++px) {
                    const int32_t a = traced.object[size_t(py * w + px)], b = caster.cast(px, py);
                    if (a >= 0 && !mirrors.empty() && size_t(a) == mirrors[0].object) {
                        const int32_t ra = traced.reflected[size_t(py * w + px)], rb = mirror_caster.cast(px, py);
                        if (ra >= 0 || rb >= 0) {
                            ++mirror_covered;
                            mirror_agree += ra == rb;
                        }
                    }
                    if (a < 0 && b < 0) continue;
                    ++frame_covered;
                    frame_agree += a == b;
                    if (moving(a) || moving(b)) {
                        ++moving_covered;
                        moving_agree += a == b;
                    }
                }
            covered += frame_covered;
            agree += frame_agree;
            if (frame_covered > 0) worst_frame = std::min(worst_frame, double(frame_agree) / double(frame_covered));
        }
        const double share = double(agree) / double(covered);
        std::cout << "[cross-check] " << modelName(model) << ": " << agree << " of " << covered
                  << " covered pixels agree (" << 100 * share << "%), worst frame " << 100 * worst_frame
                  << "%; pixels showing a moving object in either: " << moving_agree << " of " << moving_covered << " ("
                  << 100.0 * double(moving_agree) / double(moving_covered) << "%)\n";
        if (!mirrors.empty()) {
            std::cout << "[cross-check] " << modelName(model) << ": in the mirror, " << mirror_agree << " of "
                      << mirror_covered << " pixels showing a reflection agree ("
                      << 100.0 * double(mirror_agree) / double(mirror_covered) << "%)\n";
            EXPECT_GT(mirror_covered, min_mirror_pixels);
            EXPECT_GE(double(mirror_agree) / double(mirror_covered), 0.99) << modelName(model);
        }
        EXPECT_GT(moving_covered, 0) << modelName(model);
        // The flanges alone (a few percent of the picture) must agree as well.
        EXPECT_GE(double(moving_agree) / double(moving_covered), 0.99) << modelName(model);
        EXPECT_GT(covered, 0);
        EXPECT_GE(share, 0.99) << modelName(model);
        EXPECT_GE(worst_frame, 0.99) << modelName(model);
    }
}

}  // namespace

// The cross-check on the default scene (flanges, stage, mirrored backdrop).
TEST(RaytraceCrossCheck, ApparentMeshesShowWhatThe4DRaytracerShows) {
    crossCheck("data/scenes/flanges.json", 10, 1000, nullptr);
}

// The same agreement for a moving camera, the fly-by (camera at 0.9c past seven boxes at
// rest): every model the scene allows (instant, relativistic, contracted; finite is refused for a
// moving camera), every 10th frame.
TEST(RaytraceCrossCheck, FlybyFromAMovingCamera) {
    crossCheck("data/scenes/flyby.json", 10, 0, nullptr);
}

// Mirrors seen by a moving camera (pipeline/stage/mirror.h): the mirror, at rest in the lab, moves in the
// camera's frame. The raytracer bounces each ray off it as the lab reflects it (mirror.h
// reflectRayDirection), independently of the meshes' lab cut, reflection and map.
TEST(RaytraceCrossCheck, MirrorSeenFromAMovingCamera) {
    crossCheck("data/fixtures/scene_mirror_camera.json", 10, 1000, nullptr);
}

// A mirror's `exists` applies to what it reflects: the backdrop of scene_mirror_exists.json is
// there for lab time [-16, -10] only. With finite light speed its points (23.675 to 28.65 ls from
// the camera) are seen from t = 7.675 s to 18.65 s, so its reflections are empty before and after
// (closed form), present in between, and agree with the raytracer (which meets only the mirror's
// existing 4D tetrahedra) on >= 99% of pixels in every model, partly present mirrors included.
// The backdrop is two 30 x 8 ls triangles whose nearest corners are 28.10 ls away: from t = 7.675
// s to 12.1 s every corner is still unseen while their middle is seen, which the clip of objects
// at rest (slice.cpp restTriangle) must find.
TEST(RaytraceCrossCheck, ReflectionsFollowTheMirrorsExistence) {
    CrossCheckResult result;
    crossCheck("data/fixtures/scene_mirror_exists.json", 10, 100, &result);
    const double fps = 10, nearest = 23.675, farthest = std::sqrt(15.0 * 15.0 + 5.95 * 5.95 + 23.675 * 23.675);
    for (Model model : {Model::Finite, Model::Relativistic}) {
        const std::vector<long long>& empty = result.empty_reflections[model];
        size_t present = 0;
        for (long long k = 0; k < 200; k += 10) {
            const double t = double(k) / fps;
            const bool is_empty = std::find(empty.begin(), empty.end(), k) != empty.end();
            if (t < nearest - 16 || t > farthest - 10) {
                EXPECT_TRUE(is_empty) << modelName(model) << " frame " << k;
            } else {
                EXPECT_FALSE(is_empty) << modelName(model) << " frame " << k;  // the stage shows in the mirror
            }
            present += !is_empty;
        }
        std::cout << "[mirror exists] " << modelName(model) << ": reflections in " << present << " of 20 frames\n";
    }
}

// The rolling wheel at 0.9c (rolling_wheel.json, 1.8 ls spokes turning at 0.9 rad/s)
// raytraced through time slabs for two frames as it passes in front of the camera, against the
// cut of the same frames with a tolerance of T = 1e-3 x its size (worldline_refine.h), cast in 3D.
// The slabs' stated error: every point of their tetrahedra within 1e-3 of the wheel's size of the
// true history in the lab (slab_planner.h, extrude.h); with the cut's T, at most 5.7e-3 ls, 0.29 of
// a pixel at the wheel's nearest (4 ls; 160 x 90 at 20 degrees). So the two pictures of which
// pixel shows the wheel must agree up to the sampling: every pixel where they differ has the
// other picture's value within one pixel. The cut in vertex mode (straight spokes where the
// raytracer's and the refined cut's curve) fails that check: the test can fail.
TEST(RaytraceCrossCheck, RollingWheelThroughTimeSlabsMatchesTheRefinedCut) {
    Scene scene;
    ASSERT_TRUE(loadScene(source("data/scenes/rolling_wheel.json"), &scene).ok);
    scene.camera.fov_deg = 20;  // the wheel fills the frame
    std::vector<PreparedObject> objects;
    std::ostringstream log;
    ASSERT_TRUE(prepareObjects(scene, {}, &objects, log, true).ok);
    ASSERT_EQ(objects.size(), 1u);
    const int w = 160, h = 90;
    const long long first = 100, last = 101;
    SceneTracer tracer(scene, objects, {}, Model::Relativistic, first, last);
    std::cout << "[rolling wheel] " << tracer.worldCount() << " time slabs\n";
    EXPECT_GT(tracer.worldCount(), 100u);
    const mesh4d::World4D world = buildWorld(objects[0], Model::Relativistic, scene, first, last);
    mesh4d::EventBox box;
    for (const Vec3& p : objects[0].rest.positions) box.addPoint(p);
    for (long long k = first; k <= last; ++k) {
        const TracedFrame traced = tracer.traceFrame(k, w, h);
        const mesh4d::ViewSurface view = viewForFrame(scene, Model::Relativistic, k);
        for (const double tolerance : {1e-3 * box.diagonal(), 0.0}) {
            mesh4d::SliceSettings slice;
            slice.tolerance = tolerance;
            const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, view, slice);
            const std::vector<int32_t> cast = testcast::castCut(scene.camera, w, h, cut);
            const testcast::ImageDifference d = testcast::compareObjectImages(traced.object, cast, w, h);
            const long long covered = d.shown, differ = d.differ, far = d.far;
            std::cout << "[rolling wheel] frame " << k << ", cut with T = " << tolerance << " ls: " << covered
                      << " pixels show the wheel, " << differ << " differ, " << far << " of them by more than a pixel\n";
            EXPECT_GT(covered, 1500) << k;
            if (tolerance > 0) {
                EXPECT_EQ(far, 0) << k;
            } else {
                EXPECT_GT(far, 20) << k;
            }
        }
    }
}

namespace {

using testio::linearToSrgb8;
using testio::srgbToLinear;

// Writes a unit cube whose six faces are separate objects (one quad each), rotated by
// `rotation_deg`, at [0, 0, -5] at t = 0 moving at 0.9c along x, lit by a distant light.
std::string writeFacesScene(const std::filesystem::path& dir, const std::string& rotation_deg, const std::string& light) {
    std::filesystem::create_directories(dir);
    const char* faces[6][4] = {{"0.5 -0.5 -0.5", "0.5 0.5 -0.5", "0.5 0.5 0.5", "0.5 -0.5 0.5"},
                               {"-0.5 -0.5 -0.5", "-0.5 -0.5 0.5", "-0.5 0.5 0.5", "-0.5 0.5 -0.5"},
                               {"-0.5 0.5 -0.5", "-0.5 0.5 0.5", "0.5 0.5 0.5", "0.5 0.5 -0.5"},
                               {"-0.5 -0.5 -0.5", "0.5 -0.5 -0.5", "0.5 -0.5 0.5", "-0.5 -0.5 0.5"},
                               {"-0.5 -0.5 0.5", "0.5 -0.5 0.5", "0.5 0.5 0.5", "-0.5 0.5 0.5"},
                               {"-0.5 -0.5 -0.5", "-0.5 0.5 -0.5", "0.5 0.5 -0.5", "0.5 -0.5 -0.5"}};
    std::ostringstream scene;
    scene << R"({ "camera": {"position": [0, 0, 0], "look_at": [0, 0, -5], "up": [0, 1, 0], "fov_deg": 60},
  )" << light << R"( "frames": {"start": 0, "end": 10, "fps": 10}, "objects": [)";
    for (int f = 0; f < 6; ++f) {
        std::ofstream obj(dir / ("face" + std::to_string(f) + ".obj"));
        for (const char* v : faces[f]) obj << "v " << v << "\n";
        obj << "f 1 2 3\nf 1 3 4\n";
        scene << (f ? ", " : "") << R"({"mesh": "face)" << f << R"(.obj", "position": [0, 0, -5], "velocity": [0.9, 0, 0], "rotation_deg": )"
              << rotation_deg << "}";
    }
    scene << "] }";
    const auto path = dir / "faces.json";
    std::ofstream(path) << scene.str();
    return path.string();
}

}  // namespace

// Every pixel of a flat face under uniform motion has one shade, Lambert's law with the
// face's outward lab normal, in every model: the rest normal (Galilean) or the contracted one,
// n + (gamma - 1)(n . u) u normalised (Lorentz), from the rest mesh and the closed form alone.
// Before the fix the normal was turned by the spatial test n . d, which aberration flips across
// the trailing face: a strip of it was lit from the wrong side (about 2x brighter). Lit by a given
// light, and by the default pair (docs/SCENES.md): overhead with weight 0.3 and a key light
// towards (back 1, left 0.45, up 0.15) in the camera's basis with weight 0.7.
TEST(RaytraceShading, EveryPixelOfAFlatFaceHasItsFacesShade) {
    const auto dir = testio::tempPath() / ("apparent_faces_" + std::to_string(::getpid()));
    const double beta = 0.9, gamma = 1 / std::sqrt(1 - beta * beta);
    const Vec3 u{1, 0, 0};
    struct Light {
        std::string json;
        std::vector<std::pair<Vec3, double>> lights;  // unit direction towards the light, weight
    };
    const Vec3 key = Vec3{-0.45, 0.15, 1} / mesh4d::norm(Vec3{-0.45, 0.15, 1});  // camera looks down -z
    const Light lights[] = {{R"("light": {"direction": [0.3, 1, 0.6], "ambient": 0.2},)",
                             {{Vec3{0.3, 1, 0.6} / mesh4d::norm(Vec3{0.3, 1, 0.6}), 1.0}}},
                            {"", {{Vec3{0, 1, 0}, 0.3}, {key, 0.7}}}};
    for (const auto& [rotation, light] : {std::pair{"[0, 0, 30]", lights[0]}, std::pair{"[20, 30, 10]", lights[0]},
                                          std::pair{"[0, 0, 30]", lights[1]}, std::pair{"[20, 30, 10]", lights[1]}}) {
        StageOptions options;
        options.scene_path = writeFacesScene(dir, rotation, light.json);
        options.all_models = true;
        Stage stage;
        std::ostringstream log;
        std::string error;
        ASSERT_TRUE(loadStage(options, &stage, log, &error)) << error;
        for (Model model : stage.models) {
            const bool lorentz = model == Model::Relativistic || model == Model::Contracted;
            SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, model, 50, 50);
            const TracedFrame frame = tracer.traceFrame(50, 320, 180);
            std::map<int32_t, int> pixels;
            for (size_t i = 0; i < frame.object.size(); ++i) {
                const int32_t o = frame.object[i];
                if (o < 0) continue;
                // Step: the face's outward rest normal (the cube is centred on the mesh origin).
                const mesh4d::RestMesh& rest = stage.objects[size_t(o)].rest;
                const auto& t = rest.triangles[0];
                Vec3 n = mesh4d::cross(rest.positions[t[1]] - rest.positions[t[0]], rest.positions[t[2]] - rest.positions[t[0]]);
                n = n / mesh4d::norm(n);
                if (mesh4d::dot(n, rest.positions[t[0]]) < 0) n = -n;
                if (lorentz) n = n + (gamma - 1) * mesh4d::dot(n, u) * u;
                n = n / mesh4d::norm(n);
                double diffuse = 0;
                for (const auto& [l, weight] : light.lights) diffuse += weight * std::max(0.0, mesh4d::dot(n, l));
                const double lambert = 0.2 + 0.8 * diffuse;
                const auto color = objectBaseColor(stage.objects, size_t(o));
                const uint8_t* p = frame.image.rgb.data() + 3 * i;
                for (size_t c = 0; c < 3; ++c) {
                    const double expect = color[c] * lambert;
                    const bool ok = testio::levelShows(p[c], expect);
                    ASSERT_TRUE(ok) << modelName(model) << " rotation " << rotation << " face " << o << " pixel (" << i % 320
                                    << ", " << i / 320 << ") channel " << c << ": " << int(p[c]) << " != "
                                    << linearToSrgb8(expect);
                }
                ++pixels[o];
            }
            // The picture shows at least three faces, each over many pixels.
            int shown = 0;
            for (const auto& [o, count] : pixels) shown += count >= 30;
            EXPECT_GE(shown, 3) << modelName(model) << " rotation " << rotation;
        }
    }
    std::filesystem::remove_all(dir);
}

// The default light shows a box's faces apart: a single-coloured static cube seen from above left
// shows three faces in three shades; the overhead light alone shows the two side faces alike.
TEST(RaytraceShading, DefaultLightShowsTheFacesOfABoxApart) {
    const auto dir = testio::tempPath() / ("apparent_box_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::filesystem::copy_file(source("data/meshes/box.obj"), dir / "box.obj", std::filesystem::copy_options::overwrite_existing);
    for (const bool overhead_only : {false, true}) {
        std::ofstream(dir / "box.json") << R"({ "camera": {"position": [-1.6, 1.3, 2.2], "look_at": [0, 0, 0]},)"
                                        << (overhead_only ? R"("light": {"direction": [0, 1, 0]},)" : "")
                                        << R"( "objects": [{"mesh": "box.obj"}] })";
        StageOptions options;
        options.scene_path = (dir / "box.json").string();
        Stage stage;
        std::ostringstream log;
        std::string error;
        ASSERT_TRUE(loadStage(options, &stage, log, &error)) << error;
        SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, stage.models[0], 0, 0);
        const TracedFrame frame = tracer.traceFrame(0, 160, 90);
        std::map<std::array<uint8_t, 3>, int> shades;
        for (size_t i = 0; i < frame.object.size(); ++i)
            if (frame.object[i] == 0) ++shades[{frame.image.rgb[3 * i], frame.image.rgb[3 * i + 1], frame.image.rgb[3 * i + 2]}];
        int faces = 0;
        for (const auto& [shade, count] : shades) faces += count >= 100;
        EXPECT_EQ(faces, overhead_only ? 2 : 3) << (overhead_only ? "overhead light" : "default light");
    }
    std::filesystem::remove_all(dir);
}

namespace {

// ffprobe's view of a video's first stream: "key=value" lines.
std::map<std::string, std::string> probeVideo(const std::string& path) {
    std::map<std::string, std::string> fields;
    const std::string cmd = "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                            "stream=codec_name,nb_read_frames,r_frame_rate,width,height,pix_fmt -of default=nw=1 '" +
                            path + "'";
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return fields;
    char line[512];
    while (std::fgets(line, sizeof line, p)) {
        std::string l(line);
        while (!l.empty() && (l.back() == '\n' || l.back() == '\r')) l.pop_back();
        const auto eq = l.find('=');
        if (eq != std::string::npos) fields[l.substr(0, eq)] = l.substr(eq + 1);
    }
    ::pclose(p);
    return fields;
}

}  // namespace

// raytrace --video and figure --video: H.264 MP4 in yuv420p that ffprobe reads, with the frame
// count asked for, the scene's 10 fps and odd sizes padded to even; without ffmpeg one line, exit 2.
TEST(RaytraceVideo, RaytraceAndFigureWriteH264) {
    const auto dir = testio::tempPath() / ("apparent_video_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    const std::string one = (dir / "one.mp4").string(), side = (dir / "side.mp4").string();
    const CommandRun r = run({"raytrace", source("data/scenes/flanges.json"), "--model", "relativistic", "--size", "65x37",
                              "--frames", "95:102", "--video", one, "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(std::filesystem::exists("out/relativistic/frame_00095.png"));  // --video without --out: no PNGs
    auto f = probeVideo(one);
    EXPECT_EQ(f["codec_name"], "h264");
    EXPECT_EQ(f["pix_fmt"], "yuv420p");
    EXPECT_EQ(f["nb_read_frames"], "7");
    EXPECT_EQ(f["r_frame_rate"], "10/1");
    EXPECT_EQ(f["width"], "66");
    EXPECT_EQ(f["height"], "38");
    const CommandRun fig = run({"figure", source("data/scenes/flanges.json"), "--models", "finite,relativistic", "--size",
                                "64x36", "--frames", "99:102", "--video", side, "--quiet"});
    ASSERT_EQ(fig.code, 0) << fig.err;
    f = probeVideo(side);
    EXPECT_EQ(f["codec_name"], "h264");
    EXPECT_EQ(f["nb_read_frames"], "3");
    EXPECT_EQ(f["r_frame_rate"], "10/1");
    EXPECT_GE(std::stoi(f["width"]), 2 * 64 + 3 * 4);
    // Several models in one raytrace video, and no ffmpeg in PATH: one line each, exit 2, no file.
    const CommandRun two = run({"raytrace", source("data/scenes/flanges.json"), "--model", "finite,relativistic",
                                "--video", (dir / "two.mp4").string()});
    EXPECT_EQ(two.code, 2);
    EXPECT_NE(two.err.find("--video: a video shows one model"), std::string::npos) << two.err;
    const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
    ::setenv("PATH", (dir / "empty").string().c_str(), 1);
    const CommandRun none = run({"raytrace", source("data/scenes/flanges.json"), "--model", "relativistic", "--video",
                                 (dir / "none.mp4").string()});
    const CommandRun none_fig = run({"figure", source("data/scenes/flanges.json"), "--video", (dir / "none.mp4").string()});
    ::setenv("PATH", path.c_str(), 1);
    for (const CommandRun& c : {none, none_fig}) {
        EXPECT_EQ(c.code, 2);
        EXPECT_NE(c.err.find("--video: the ffmpeg program is not in PATH"), std::string::npos) << c.err;
        EXPECT_EQ(std::count(c.err.begin(), c.err.end(), '\n'), 1) << c.err;
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "two.mp4"));
    EXPECT_FALSE(std::filesystem::exists(dir / "none.mp4"));
    std::filesystem::remove_all(dir);
}

// figure's labels: with them, bands left of and above the panels hold text (bright pixels drawn by
// FreeType); with --no-labels the sheet is the bare grid, every pixel between panels gap grey.
TEST(RaytraceCommand, FigureLabelsRowsAndColumns) {
    const auto base = testio::tempPath() / ("apparent_labels_" + std::to_string(::getpid()));
    const std::string labelled = base.string() + "_on.png", bare = base.string() + "_off.png";
    const std::vector<std::string> common = {"figure", source("data/scenes/flanges.json"), "--times", "5,10", "--models",
                                             "instant,relativistic", "--size", "96x54", "--quiet"};
    std::vector<std::string> a = common, b = common;
    a.insert(a.end(), {"--out", labelled});
    b.insert(b.end(), {"--out", bare, "--no-labels"});
    const CommandRun ra = run(a), rb = run(b);
    ASSERT_EQ(ra.code, 0) << ra.err;
    ASSERT_EQ(rb.code, 0) << rb.err;
    RgbImage on, off;
    std::string error;
    ASSERT_TRUE(readPng(labelled, &on, &error)) << error;
    ASSERT_TRUE(readPng(bare, &off, &error)) << error;
    constexpr int kGap = 4;
    ASSERT_EQ(off.width, 2 * 96 + 3 * kGap);
    ASSERT_EQ(off.height, 2 * 54 + 3 * kGap);
    // The bare sheet: gap grey everywhere outside the panels.
    auto inPanel = [&](int x, int y) {
        const int cx = (x - kGap) % (96 + kGap), cy = (y - kGap) % (54 + kGap);
        return x >= kGap && y >= kGap && cx < 96 && cy < 54;
    };
    int stray = 0;
    for (int y = 0; y < off.height; ++y)
        for (int x = 0; x < off.width; ++x)
            if (!inPanel(x, y))
                for (int c = 0; c < 3; ++c) stray += off.pixel(x, y)[c] != 96;
    EXPECT_EQ(stray, 0);
    // The labelled sheet: the same panels shifted by the bands, text in both bands.
    const int left = on.width - off.width, top = on.height - off.height;
    ASSERT_GT(left, 0);
    ASSERT_GT(top, 0);
    auto brightIn = [&](int x0, int y0, int x1, int y1) {
        int n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const uint8_t* p = on.pixel(x, y);
                n += p[0] > 200 && p[1] > 200 && p[2] > 200;
            }
        return n;
    };
    EXPECT_GT(brightIn(0, top, left, on.height), 20) << "row labels";
    EXPECT_GT(brightIn(left, 0, on.width, top), 20) << "column labels";
    for (int y = 0; y < off.height; ++y)
        EXPECT_TRUE(std::equal(off.pixel(0, y), off.pixel(0, y) + 3 * off.width, on.pixel(left, top + y))) << "row " << y;
    std::filesystem::remove(labelled);
    std::filesystem::remove(bare);
}

// The bounding hierarchy (co-moving boxes, ray4d.h) finds the nearest hit the linear scan finds:
// random rays from random camera events at a torus of 2000 triangles, at rest and moving at up to
// 0.99c in both kinematics, along the cone and along t = t_c.
TEST(Ray4D, HierarchyFindsWhatTheLinearScanFinds) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    mesh4d::RestMesh torus;
    const int nu = 50, nv = 20;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double a = 2 * mesh4d::kPi * i / nu, b = 2 * mesh4d::kPi * j / nv;
            torus.positions.push_back({(2 + 0.5 * std::cos(b)) * std::cos(a), 0.5 * std::sin(b), (2 + 0.5 * std::cos(b)) * std::sin(a)});
        }
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const uint32_t p00 = uint32_t(i * nv + j), p10 = uint32_t(((i + 1) % nu) * nv + j),
                           p01 = uint32_t(i * nv + (j + 1) % nv), p11 = uint32_t(((i + 1) % nu) * nv + (j + 1) % nv);
            torus.triangles.push_back({p00, p10, p11});
            torus.triangles.push_back({p00, p11, p01});
        }
    long hits = 0, rays = 0;
    for (int world_i = 0; world_i < 8; ++world_i) {
        const double beta = std::vector<double>{0, 0.5, 0.9, 0.99}[size_t(world_i % 4)];
        const auto kin = world_i < 4 ? mesh4d::Kinematics::Galilean : mesh4d::Kinematics::Lorentz;
        Vec3 dir{u(rng), u(rng), u(rng)};
        dir = dir / mesh4d::norm(dir);
        const mesh4d::Motion m = mesh4d::makeMotion(kin, 0, {0, 0, -8}, dir * beta);
        const mesh4d::World4D w = mesh4d::extrude(torus, m, -30, 30, false, false);
        const mesh4d::TraceWorld fast = mesh4d::prepareTrace(w), slow = mesh4d::prepareTrace(w, false);
        ASSERT_FALSE(fast.nodes.empty());
        ASSERT_TRUE(slow.nodes.empty());
        for (int k = 0; k < 1500; ++k) {
            mesh4d::Ray4D ray;
            ray.origin = {u(rng) * 5, {u(rng), u(rng), u(rng)}};
            // Aim near the torus's position at the origin's time (or its light-delayed one).
            const Vec3 target = mesh4d::labPositionAt(m, {2 * u(rng), 0.6 * u(rng), 2 * u(rng)}, ray.origin.t - 8 * (k % 2));
            ray.direction = (target - ray.origin.x) / mesh4d::norm(target - ray.origin.x);
            ray.along_cone = k % 2 == 1;
            const auto a = mesh4d::intersectWorld(fast, ray, INFINITY), b = mesh4d::intersectWorld(slow, ray, INFINITY);
            ++rays;
            ASSERT_EQ(bool(a), bool(b)) << "world " << world_i << " ray " << k;
            if (!a) continue;
            ++hits;
            EXPECT_NEAR(a->s, b->s, 1e-12 * (1 + b->s)) << "world " << world_i << " ray " << k;
            if (a->s != b->s) continue;
            EXPECT_EQ(a->triangle, b->triangle) << "world " << world_i << " ray " << k;
        }
    }
    std::cout << "[hierarchy] " << hits << " of " << rays << " rays hit; hierarchy and linear scan agree on all\n";
    EXPECT_GT(hits, rays / 4);
}

// The label font: DejaVu Sans is found (setup.sh installs fonts-dejavu-core) and draws; a missing
// font file is one line naming the path and the Debian package.
TEST(RaytraceCommand, LabelFontLoadsOrSaysWhichPackage) {
    TextPainter painter;
    std::string error;
    ASSERT_TRUE(painter.open(kLabelFontPath, &error)) << error;
    EXPECT_GT(painter.width("relativistic", 16), 40);
    RgbImage img(80, 20);
    painter.draw(&img, 2, 15, "t = 10 s", 14, {255, 255, 255});
    EXPECT_GT(std::count_if(img.rgb.begin(), img.rgb.end(), [](uint8_t v) { return v > 128; }), 30);
    TextPainter none;
    EXPECT_FALSE(none.open("/nonexistent/DejaVuSans.ttf", &error));
    EXPECT_NE(error.find("/nonexistent/DejaVuSans.ttf: font not found (Debian package fonts-dejavu-core"), std::string::npos)
        << error;
    EXPECT_EQ(error.find('\n'), std::string::npos);
}

// `raytrace --shade doppler` of a keyframed object takes the Doppler factor of
// its worldline at each hit (raytrace.h). Three collinear keys at constant velocity v, the middle
// one at a lab time the frame sees (so the history is traced in several slabs, cut at the key),
// give the uniform model with velocity v, whose factor is the closed form 1 / (g (1 - v.n))
// (light_factors.h dopplerFactor, not the worldline's): the same pixels show the box and every
// channel agrees within one level of rounding; and the Doppler picture is not the plain one.
TEST(RaytraceShading, DopplerOfAKeyframedPathIsTheUniformModelsAtConstantSpeed) {
    const Vec3 v{0.4, 0, 0.3}, x0{0, 0, -3};  // seen at t = -4.87 s, 4.87 ls away, approaching
    testkeys::KeyedGltf keyed, uniform;
    keyed.translation = uniform.translation = {x0.x, x0.y, x0.z};
    testkeys::Channel ch;
    ch.times = {-40, -5, 40};
    for (double t : {-40.0, -5.0, 40.0})
        for (double c : {x0.x + v.x * t, x0.y + v.y * t, x0.z + v.z * t}) ch.values.push_back(float(c));
    keyed.channels.push_back(ch);
    uniform.object_extras = {{"t0", 0}, {"velocity", {v.x, v.y, v.z}}};
    const std::string dir = testio::processTempDir();
    RgbImage image[3];
    std::vector<int32_t> object[3];
    size_t worlds[2] = {0, 0};
    for (int i = 0; i < 3; ++i) {  // keyed with Doppler, uniform with Doppler, uniform plain
        Stage stage;
        std::string error;
        ASSERT_TRUE(loadQuietStage(i == 0 ? keyed.write(dir, "doppler_keys") : uniform.write(dir, "doppler_uniform"), &stage,
                                   &error))
            << error;
        SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, Model::Relativistic, 0, 0);
        tracer.setShadeDoppler(i < 2);
        const TracedFrame f = tracer.traceFrame(0, 160, 90);
        image[i] = f.image;
        object[i] = f.object;
        if (i < 2) worlds[i] = tracer.worldCount();
    }
    EXPECT_GE(worlds[0], 2u);  // the key cuts the keyed history
    EXPECT_EQ(worlds[1], 1u);
    long long covered = 0, off = 0, shifted = 0;
    int worst = 0;
    for (size_t p = 0; p < object[0].size(); ++p) {
        if (object[0][p] != object[1][p]) ++off;
        if (object[1][p] < 0) continue;
        ++covered;
        bool differs = false;
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(int(image[0].rgb[3 * p + c]) - int(image[1].rgb[3 * p + c])));
            differs |= image[1].rgb[3 * p + c] != image[2].rgb[3 * p + c];
        }
        shifted += differs;
    }
    std::cout << "[keyed doppler] " << worlds[0] << " slabs; " << covered << " pixels show the box, " << off
              << " differ in what they show, largest channel difference " << worst << ", " << shifted
              << " pixels shifted by Doppler\n";
    EXPECT_GT(covered, 100);
    EXPECT_EQ(off, 0);
    EXPECT_LE(worst, 1);
    EXPECT_GT(shifted, covered / 2);
}

namespace {

// The Doppler pictures' check of the tests below: the stage traced at t = 0 without and with
// --shade doppler (relativistic); at every pixel of object 0 where `factor` (of the pixel's ray
// direction d) gives D, each channel of at least `least` levels in both pictures compared as the
// ratio doppler / plain (linear light: the Lambert factor cancels) against dopplerColour(base, D) /
// base.
struct DopplerRatios {
    long long checked = 0;
    double worst = 0;  // largest |measured / expected - 1|
    double smallest_d = INFINITY, largest_d = 0;
};
DopplerRatios dopplerRatios(const Stage& stage, int width, int height, int least,
                            const std::function<std::optional<double>(const Vec3& d)>& factor) {
    TracedFrame frame[2];
    for (int i = 0; i < 2; ++i) {
        SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, Model::Relativistic, 0, 0);
        tracer.setShadeDoppler(i == 1);
        frame[i] = tracer.traceFrame(0, width, height);
    }
    const std::array<double, 4> base4 = objectBaseColor(stage.objects, 0);
    const std::array<double, 3> base{base4[0], base4[1], base4[2]};
    DopplerRatios r;
    for (int py = 0; py < height; ++py)
        for (int px = 0; px < width; ++px) {
            const size_t p = size_t(py * width + px);
            if (frame[0].object[p] < 0) continue;
            const std::optional<double> D = factor(pixelDirection(stage.scene.camera, width, height, px, py));
            if (!D) continue;
            r.smallest_d = std::min(r.smallest_d, *D);
            r.largest_d = std::max(r.largest_d, *D);
            const std::array<double, 3> shifted = mesh4d::dopplerColour(base, *D);
            for (int c = 0; c < 3; ++c) {
                const uint8_t plain = frame[0].image.rgb[3 * p + size_t(c)], doppler = frame[1].image.rgb[3 * p + size_t(c)];
                if (plain < least || doppler < least) continue;
                const double expected = shifted[size_t(c)] / base[size_t(c)];
                const double measured = srgbToLinear(doppler) / srgbToLinear(plain);
                r.worst = std::max(r.worst, std::fabs(measured / expected - 1));
                ++r.checked;
            }
        }
    return r;
}

}  // namespace

// The same for a path whose segments' velocities are not its mean velocity (which the uniform
// model's factor would use): out along u = (0.4, 0, 0.3) until t = 0 and back by t = 40, mean
// velocity 0. Every hit of the frame at t = 0 lies on the first segment, so each pixel's factor is
// D = sqrt(1 - u^2) / (1 + u.d), d the pixel's ray direction (light from the hit towards the camera
// runs along -d), written here; the shaded colour is Lambert * dopplerColour(base, D), so the
// ratio of a channel with and without Doppler is dopplerColour(base, D) / base, whatever the
// Lambert factor (to the 8-bit rounding: 3% on channels of at least 60 levels).
TEST(RaytraceShading, DopplerOfAKeyframedPathIsItsSegmentsVelocitys) {
    const Vec3 u{0.4, 0, 0.3}, x0{0, 0, -3};
    testkeys::KeyedGltf keyed;
    keyed.translation = {x0.x, x0.y, x0.z};
    testkeys::Channel ch;
    ch.times = {-40, 0, 40};
    for (const Vec3& p : {x0 - 40 * u, x0, x0 - 40 * u})
        for (double c : {p.x, p.y, p.z}) ch.values.push_back(float(c));
    keyed.channels.push_back(ch);
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(keyed.write(testio::processTempDir(), "doppler_segments"), &stage, &error)) << error;
    const DopplerRatios r = dopplerRatios(stage, 160, 90, 60, [&](const Vec3& d) -> std::optional<double> {
        return std::sqrt(1 - mesh4d::dot(u, u)) / (1 + mesh4d::dot(u, d));
    });
    const long long checked = r.checked;
    const double worst = r.worst, smallest_d = r.smallest_d;
    std::cout << "[keyed doppler] segment velocity: " << checked << " channels checked, D >= " << smallest_d
              << ", worst relative difference " << worst << "\n";
    EXPECT_GT(checked, 200);
    EXPECT_GT(smallest_d, 1.2);  // far from the mean velocity's D = 1
    EXPECT_LE(worst, 0.03);
}

// `raytrace --shade doppler` of a spinning object: a flat disk of radius 1 in the plane
// z = -3, its centre X0 = (1.6, 0, -3) at rest (off the axis, so that u.d is not small), spinning
// about z at w = 0.5 rad/s (rim speed 0.5). The disk's plane holds still, so the pixel with ray
// direction d sees the point x where its ray meets z = -3, moving at u = w x (x - X0)
// (worldline.h: dY/ds = w x Y, no boost); its Doppler factor to the camera (light runs along -d)
// is D = sqrt(1 - u^2) / (1 + u.d), written here. As above, the ratio of a channel with and without
// Doppler is dopplerColour(base, D) / base, checked inside 0.95 of the rim (the 64-gon's edges kept
// out) on channels of at least 100 levels, where the 8-bit rounding of the two pictures stays
// within 3% (at 60 levels it reaches about 4%).
TEST(RaytraceShading, DopplerOfASpinningDiskIsItsRimVelocitys) {
    const std::filesystem::path dir = std::filesystem::path(testio::processTempDir()) / "doppler_spin";
    std::filesystem::create_directories(dir);
    const int n = 64;
    {
        std::ofstream obj(dir / "disk.obj");
        obj << "v 0 0 0\n";
        for (int i = 0; i < n; ++i)
            obj << "v " << std::cos(2 * mesh4d::kPi * i / n) << " " << std::sin(2 * mesh4d::kPi * i / n) << " 0\n";
        for (int i = 0; i < n; ++i) obj << "f 1 " << 2 + i << " " << 2 + (i + 1) % n << "\n";
    }
    const Vec3 x0{1.6, 0, -3}, w{0, 0, 0.5};
    std::ofstream(dir / "spin.json") << R"({ "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},)"
                                     << R"( "frames": {"start": 0, "end": 1, "fps": 1},)"
                                     << R"( "objects": [{"mesh": "disk.obj", "position": [1.6, 0, -3], "angular_velocity": [0, 0, 0.5]}] })";
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage((dir / "spin.json").string(), &stage, &error)) << error;
    const DopplerRatios r = dopplerRatios(stage, 160, 90, 100, [&](const Vec3& d) -> std::optional<double> {
        const Vec3 x = (x0.z / d.z) * d;
        if (mesh4d::norm(x - x0) > 0.95) return std::nullopt;
        const Vec3 u = mesh4d::cross(w, x - x0);
        return std::sqrt(1 - mesh4d::dot(u, u)) / (1 + mesh4d::dot(u, d));
    });
    const long long checked = r.checked;
    const double worst = r.worst, smallest_d = r.smallest_d, largest_d = r.largest_d;
    std::cout << "[spin doppler] " << checked << " channels checked, D in [" << smallest_d << ", " << largest_d
              << "], worst relative difference " << worst << "\n";
    EXPECT_GT(checked, 200);
    EXPECT_LT(smallest_d, 0.8);  // both sides of the disk: receding and approaching
    EXPECT_GT(largest_d, 1.05);
    EXPECT_LE(worst, 0.03);
}

namespace {

// A rolling cylinder (radius 1, height 0.3, 24 sides; b = 0.6 along x, w R = b, Lorentz) cut into
// `count` time slabs of `step` seconds from s = -12: the slabs, each slab's own linear scan, and
// one hierarchy over all of them (ray4d.h prepareSlabsTrace).
struct RollingSlabs {
    std::vector<mesh4d::World4D> slabs;
    std::vector<mesh4d::TraceWorld> scans;
    mesh4d::TraceWorld joint;
};
RollingSlabs rollingCylinderSlabs(int count, double step) {
    const mesh4d::RestMesh mesh = testmesh::cylinder(1, 0.3, 24);
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {0, 0, 0}, {0.6, 0, 0});
    m.angular_velocity = {0, 0, -0.6};
    std::vector<double> samples;
    for (int k = 0; k <= count; ++k) samples.push_back(-12 + step * k);
    RollingSlabs r;
    r.slabs = mesh4d::extrudeSlabs(mesh, m, samples, false, false);
    std::vector<const mesh4d::World4D*> pointers;
    for (const auto& w : r.slabs) {
        pointers.push_back(&w);
        r.scans.push_back(mesh4d::prepareTrace(w, false));
    }
    r.joint = mesh4d::prepareSlabsTrace(pointers);
    return r;
}

}  // namespace

// One hierarchy over the time slabs of a history (ray4d.h prepareSlabsTrace, splitting along time
// too) finds the hit the slabs' own linear scans find, nearest over all: the same ray parameter,
// slab and triangle, for rays across a rolling cylinder (b = 0.6, w R = b) cut into 60 slabs.
TEST(Ray4D, SlabsHierarchyFindsWhatEachSlabsScanFinds) {
    const RollingSlabs rolling = rollingCylinderSlabs(60, 0.2);
    const std::vector<mesh4d::World4D>& slabs = rolling.slabs;
    const std::vector<mesh4d::TraceWorld>& scans = rolling.scans;
    const mesh4d::TraceWorld& joint = rolling.joint;
    ASSERT_EQ(joint.slabs.size(), slabs.size());
    int hits = 0;
    for (int iy = -20; iy <= 20; ++iy)
        for (int ix = -40; ix <= 40; ++ix) {
            mesh4d::Ray4D ray;
            ray.origin = {6, {0, 0, 6}};
            const Vec3 d{0.02 * ix, 0.02 * iy, -1};
            ray.direction = d / mesh4d::norm(d);
            std::optional<mesh4d::WorldHit> expected;
            uint32_t expected_slab = 0;
            for (size_t k = 0; k < scans.size(); ++k)
                if (const auto h = mesh4d::intersectWorld(scans[k], ray, expected ? expected->s : INFINITY)) {
                    expected = h;
                    expected_slab = uint32_t(k);
                }
            const auto got = mesh4d::intersectWorld(joint, ray, INFINITY);
            ASSERT_EQ(got.has_value(), expected.has_value()) << ix << " " << iy;
            if (!got) continue;
            ++hits;
            EXPECT_EQ(got->s, expected->s);
            EXPECT_EQ(got->slab, expected_slab);
            EXPECT_EQ(got->triangle, expected->triangle);
        }
    EXPECT_GT(hits, 150);
}

// A slab of a spin twists its prisms: their tetrahedra lie in three 3-flats (ray4d.h
// flat_prisms), so no prism-level flat may drop a ray. With coarse slabs (0.5 rad a slab) the
// hierarchy over the slabs and each slab's linear scan find the nearest hit over every
// tetrahedron of every slab tested one by one (intersectTet alone): the same ray parameter.
TEST(Ray4D, TwistedPrismsOfSpinSlabsLoseNoHit) {
    const RollingSlabs rolling = rollingCylinderSlabs(30, 0.8);
    const std::vector<mesh4d::World4D>& slabs = rolling.slabs;
    const std::vector<mesh4d::TraceWorld>& scans = rolling.scans;
    const mesh4d::TraceWorld& joint = rolling.joint;
    EXPECT_FALSE(joint.flat_prisms);
    int hits = 0;
    for (int iy = -20; iy <= 20; ++iy)
        for (int ix = -40; ix <= 40; ++ix) {
            mesh4d::Ray4D ray;
            ray.origin = {6, {0, 0, 6}};
            const Vec3 d{0.02 * ix, 0.02 * iy, -1};
            ray.direction = d / mesh4d::norm(d);
            double nearest = INFINITY;
            for (const auto& w : slabs)
                for (size_t t = 0; t < w.tetCount(); ++t) {
                    const auto tet = w.tet(t);
                    const std::array<mesh4d::Event, 4> v{w.events[tet[0]], w.events[tet[1]], w.events[tet[2]], w.events[tet[3]]};
                    if (const auto h = mesh4d::intersectTet(ray, v, nearest)) nearest = h->s;
                }
            double scanned = INFINITY;
            for (const auto& scan : scans)
                if (const auto h = mesh4d::intersectWorld(scan, ray, scanned)) scanned = h->s;
            const auto got = mesh4d::intersectWorld(joint, ray, INFINITY);
            ASSERT_EQ(got.has_value(), nearest < INFINITY) << ix << " " << iy;
            EXPECT_EQ(scanned, nearest) << ix << " " << iy;
            if (!got) continue;
            ++hits;
            EXPECT_EQ(got->s, nearest) << ix << " " << iy;
        }
    EXPECT_GT(hits, 150);
}

// The thick flat of a twisted prism (ray4d.h Prism offset + below, offset + above) holds every event of its
// three tetrahedra, N . V summed here in long double: the rejection by it cannot drop a hit. The
// slabs of a fast spin cut coarsely are twisted well beyond the widening, so the test has teeth.
TEST(Ray4D, TwistedPrismsThickFlatHoldsTheirTetrahedra) {
    const mesh4d::RestMesh mesh = testmesh::cylinder(1, 0.3, 24);
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {0, 0, 0}, {0.6, 0, 0});
    m.angular_velocity = {0, 0, -0.6};
    const std::vector<double> samples{-12, -11.2, -10.4, -9.6};
    const std::vector<mesh4d::World4D> slabs = mesh4d::extrudeSlabs(mesh, m, samples, false, false);
    std::vector<const mesh4d::World4D*> pointers;
    for (const auto& w : slabs) pointers.push_back(&w);
    const mesh4d::TraceWorld trace = mesh4d::prepareSlabsTrace(pointers);
    ASSERT_FALSE(trace.flat_prisms);
    ASSERT_EQ(trace.prisms.size(), 3 * mesh.triangles.size());
    long double thickest = 0;
    for (size_t k = 0; k < slabs.size(); ++k)
        for (size_t f = 0; f < mesh.triangles.size(); ++f) {
            const mesh4d::TraceWorld::Prism& p = trace.prisms[trace.slab_first[k] + f];
            const long double len = std::sqrt((long double)p.normal[0] * p.normal[0] + (long double)p.normal[1] * p.normal[1] +
                                              (long double)p.normal[2] * p.normal[2] + (long double)p.normal[3] * p.normal[3]);
            ASSERT_GT(len, 0);
            long double lo = INFINITY, hi = -INFINITY;
            for (size_t j = 0; j < 3; ++j)
                for (uint32_t e : slabs[k].tet(3 * f + j)) {
                    const mesh4d::Event& v = slabs[k].events[e];
                    const long double across = (long double)p.normal[0] * v.t + (long double)p.normal[1] * v.x.x +
                                               (long double)p.normal[2] * v.x.y + (long double)p.normal[3] * v.x.z;
                    EXPECT_GE(across, (long double)p.offset + p.below) << k << " " << f;
                    EXPECT_LE(across, (long double)p.offset + p.above) << k << " " << f;
                    lo = std::min(lo, across);
                    hi = std::max(hi, across);
                }
            thickest = std::max(thickest, (hi - lo) / len);
        }
    // The slabs turn 0.48 rad each about the cylinder's axis: events leave the first flat by a
    // good fraction of the radius (1), not by rounding.
    EXPECT_GT(thickest, 1e-3L);
}

namespace {

// A cube of edge 0.3 ls (data/meshes/box.obj scaled) accelerating from rest at t0 = 0 along +x
// with 0.2 ls/s^2, 6 ls in front of the camera: short beside 1/|a|, so its seen span closes
// (worlds.h pathSpanSeen).
std::string writeSmallRocketScene(const std::string& dir) {
    std::filesystem::create_directories(dir);
    std::filesystem::copy_file(source("data/meshes/box.obj"), dir + "/box.obj",
                               std::filesystem::copy_options::overwrite_existing);
    const std::string path = dir + "/small_rocket.json";
    std::ofstream(path) << R"({ "camera": {"position": [0, 0, 6], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 20, "instant_delay": 6},
  "frames": {"start": 0, "end": 16, "fps": 10}, "model": "relativistic",
  "objects": [{"mesh": "box.obj", "scale": [0.3, 0.3, 0.3], "position": [-1, 0, 0], "t0": 0,
               "acceleration": [0.2, 0, 0]}] })";
    return path;
}

struct TracedRun {
    std::vector<RgbImage> images;
    std::vector<std::vector<int32_t>> objects;
    size_t worlds = 0;  // after the first frame
    SceneTracer::SlabCounts counts;
};

// Frames `frames` of `stage` traced by one SceneTracer over first..last with `options`, 160 x 90.
TracedRun traceRun(const Stage& stage, Model model, long long first, long long last, const std::vector<long long>& frames,
                   TracerOptions options) {
    SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, model, first, last, options);
    TracedRun run;
    for (long long k : frames) {
        const TracedFrame f = tracer.traceFrame(k, 160, 90);
        if (run.images.empty()) run.worlds = tracer.worldCount();
        run.images.push_back(f.image);
        run.objects.push_back(f.object);
    }
    run.counts = tracer.slabCounts();
    return run;
}

long long coveredPixels(const std::vector<int32_t>& object) {
    return std::count_if(object.begin(), object.end(), [](int32_t o) { return o >= 0; });
}

}  // namespace

// An accelerated and a keyframed body traced over only the span their frames see
// (worlds.h pathSpanSeen) give the pictures of the padded span (buildWorld: light-crossing time
// over 1 - b), byte for byte, with far fewer slabs: the slabs lie on the motion's grid (extrude.h
// SlabGrid), so the seen span's slabs are the padded span's that the frames can reach, and a seen
// span too narrow would cut the picture (an open end of the history shows the background).
TEST(RaytraceSpan, SeenSpanTracesWhatThePaddedSpanTraces) {
    const std::string dir = ::testing::TempDir() + "span_seen_" + std::to_string(::getpid());
    struct Case {
        std::string scene;
        Model model;
        std::vector<long long> frames;
        size_t fewer;  // the padded span needs more than this many times the seen span's slabs
    };
    const std::vector<Case> cases = {
        {source("data/scenes/keyed.gltf"), Model::Relativistic, {40, 80, 120}, 2},
        {source("data/scenes/keyed.gltf"), Model::Finite, {60, 100}, 2},
        {source("data/scenes/keyed.gltf"), Model::Contracted, {100}, 1},
        {source("data/scenes/keyed.gltf"), Model::Instant, {100}, 1},
        {writeSmallRocketScene(dir), Model::Relativistic, {70, 110}, 1},
        {writeSmallRocketScene(dir), Model::Finite, {110}, 1},
        {writeSmallRocketScene(dir), Model::Contracted, {110}, 1},
    };
    for (const Case& c : cases) {
        Stage stage;
        std::string error;
        ASSERT_TRUE(loadQuietStage(c.scene, &stage, &error, {c.model})) << error;
        for (long long k : c.frames) {
            TracerOptions padded;
            padded.padded_span = true;
            const TracedRun wide = traceRun(stage, c.model, k, k, {k}, padded);
            const TracedRun seen = traceRun(stage, c.model, k, k, {k}, {});
            std::cout << "[seen span] " << c.scene.substr(c.scene.rfind('/') + 1) << " " << modelName(c.model) << " frame "
                      << k << ": " << seen.worlds << " slabs (padded " << wide.worlds << "), "
                      << coveredPixels(seen.objects[0]) << " pixels show it\n";
            EXPECT_GT(coveredPixels(seen.objects[0]), 100) << c.scene << " " << k;
            EXPECT_LT(c.fewer * seen.worlds, wide.worlds) << c.scene << " " << k;
            EXPECT_EQ(seen.objects[0], wide.objects[0]) << c.scene << " " << k;
            EXPECT_TRUE(seen.images[0].rgb == wide.images[0].rgb) << c.scene << " " << k;
        }
    }
    std::filesystem::remove_all(dir);
}

// A long frame range traced in windows of slabs (SceneTracer: at most window_slabs per
// object at once, rebuilt as the frames advance) gives each frame the picture of a short range
// traced in one window, byte for byte; the run below needs several windows.
TEST(RaytraceSpan, WindowsOfFramesTraceWhatOneWindowTraces) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/keyed.gltf"), &stage, &error, {Model::Relativistic})) << error;
    const std::vector<long long> frames{100, 101, 102, 103};
    const TracedRun one = traceRun(stage, Model::Relativistic, 100, 103, frames, {});
    TracerOptions narrow;
    narrow.window_slabs = 500;  // frame 80 alone needs 412
    const TracedRun windows = traceRun(stage, Model::Relativistic, 90, 130, frames, narrow);
    std::cout << "[windows] keyed.gltf frames 100..103: one window of " << one.counts.most << " slabs; in a run over 90..130 "
              << windows.counts.windows << " windows, at most " << windows.counts.most << " slabs at once\n";
    EXPECT_EQ(one.counts.windows, 1u);
    EXPECT_GE(windows.counts.windows, 2u);
    EXPECT_LE(windows.counts.most, 500u);
    for (size_t i = 0; i < frames.size(); ++i) {
        EXPECT_GT(coveredPixels(one.objects[i]), 100) << frames[i];
        EXPECT_EQ(one.objects[i], windows.objects[i]) << frames[i];
        EXPECT_TRUE(one.images[i].rgb == windows.images[i].rgb) << frames[i];
    }
}

// A window keeps the slabs it shares with the last one (SceneTracer TraceChunk): frames
// traced one window after another extrude each slab of their range once, exactly the slabs one
// window over the range extrudes, and give its pictures byte for byte. Backwards the same, but
// for the first window (the constructor's, at the range's start), whose slabs the window of the
// last frame drops.
TEST(RaytraceSpan, AWindowExtrudesOnlyTheSlabsTheLastOneDidNotHold) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/keyed.gltf"), &stage, &error, {Model::Relativistic})) << error;
    const std::vector<long long> frames{100, 102, 104, 106, 108, 110};
    const TracedRun one = traceRun(stage, Model::Relativistic, 100, 110, frames, {});
    TracerOptions narrow;
    narrow.window_slabs = 420;  // frames 100..110 need 492: windows of a few frames
    const size_t first_window = SceneTracer(stage.scene, stage.objects, stage.mirrors, Model::Relativistic, 100, 110, narrow)
                                    .slabCounts()
                                    .built;
    for (bool backwards : {false, true}) {
        std::vector<long long> order = frames;
        if (backwards) std::reverse(order.begin(), order.end());
        const TracedRun windows = traceRun(stage, Model::Relativistic, 100, 110, order, narrow);
        std::cout << "[window reuse] keyed.gltf frames 100..110" << (backwards ? " backwards" : "") << ": "
                  << windows.counts.windows << " windows extruded " << windows.counts.built << " slabs; one window "
                  << one.counts.built << "\n";
        EXPECT_GE(windows.counts.windows, 3u);
        EXPECT_LE(windows.counts.most, 420u);
        if (backwards) {  // without reuse: a window of 400 slabs or more per frame
            EXPECT_GE(windows.counts.built, one.counts.built);
            EXPECT_LE(windows.counts.built, one.counts.built + first_window);
        } else {
            EXPECT_EQ(windows.counts.built, one.counts.built);
        }
        for (size_t i = 0; i < order.size(); ++i) {
            const size_t j = size_t(order[i] - 100) / 2;
            EXPECT_GT(coveredPixels(windows.objects[i]), 100) << order[i];
            EXPECT_EQ(one.objects[j], windows.objects[i]) << order[i];
            EXPECT_TRUE(one.images[j].rgb == windows.images[i].rgb) << order[i];
        }
    }
}

// Only a frame that alone needs more slabs than one window may hold is refused, with one
// line naming the field, the count and the frame (exit 2): the rolling wheel at 0.99c (w R = |v|).
TEST(RaytraceSpan, AFrameThatAloneNeedsTooManySlabsIsRefused) {
    const std::string dir = ::testing::TempDir() + "span_fast_wheel_" + std::to_string(::getpid());
    std::filesystem::create_directories(dir);
    std::filesystem::copy_file(source("data/meshes/wheel.obj"), dir + "/wheel.obj",
                               std::filesystem::copy_options::overwrite_existing);
    std::ofstream(dir + "/wheel.json") << R"({ "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 70},
  "frames": {"start": 0, "end": 16, "fps": 10}, "model": "relativistic",
  "objects": [{"mesh": "wheel.obj", "position": [-4.5, 0, 0], "t0": 0, "velocity": [0.99, 0, 0],
               "angular_velocity": [0, 0, -0.99]}] })";
    const CommandRun r = run({"raytrace", dir + "/wheel.json", "--out", dir + "/out", "--frames", "100:101", "--size", "8x4"});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("wheel.json: objects[0].angular_velocity: the raytracer would need more than 4096 time slabs of 792 "
                         "prisms for frame 100 alone"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out/relativistic/frame_00100.png"));
    std::filesystem::remove_all(dir);
}
