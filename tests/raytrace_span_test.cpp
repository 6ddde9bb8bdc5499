// The span of an accelerated body's time that the raytracer extrudes (pipeline/stage/worlds.h
// pathSpanSeen, mesh4d/motion/latest_crossing.h), checked against crossings found independently: the
// rocket of data/scenes/rocket.json (a Born-rigid box 2 ls long at 0.5 ls/s^2, whose frames
// see interior points of its faces emit after every vertex) and a turned torus, boosted and
// accelerated obliquely.
// Crossings come from mesh4d/refine/measure.h crossingBySearch (its own bisection on the true worldline),
// their object time s from the test's inverse of the motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "mesh4d/box.h"
#include "mesh4d/motion/latest_crossing.h"
#include "mesh4d/motion/seen.h"
#include "mesh4d/refine/measure.h"
#include "mesh4d/slice.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"
#include "pipeline/trace/raytrace.h"
#include "mesh_caster.h"
#include "quiet_stage.h"
#include "test_meshes.h"

using namespace apparent;
using mesh4d::SeenSpan;
using mesh4d::Vec3;

namespace {

std::string source(const std::string& rel) { return std::string(APPARENT_SOURCE_DIR) + "/" + rel; }

// The object time s of rest point q's crossing with `view`: the event by crossingBySearch, then
// the test's inverse of the motion (worldline.h): the start-frame time T of the event (the inverse
// boost with `velocity` about (t0, X0)), s = T before t0, and after it T = xi sinh(|a| s) with
// xi = 1/|a| + q.k, so s = asinh(|a| T / (1 + a.q)) / |a|.
double crossingTime(const mesh4d::ViewSurface& view, const mesh4d::Motion& m, const Vec3& q) {
    bool ok = false;
    const mesh4d::Event e = mesh4d::measure::crossingBySearch(view, m, q, &ok);
    EXPECT_TRUE(ok);
    const double g = 1 / std::sqrt(1 - mesh4d::dot(m.velocity, m.velocity));
    const double T = g * ((e.t - m.t0) - mesh4d::dot(m.velocity, e.x - m.origin));
    const double a = mesh4d::norm(m.acceleration);
    if (T <= 0 || a == 0) return T;
    return std::asinh(a * T / (1 + mesh4d::dot(m.acceleration, q))) / a;
}

// Points of every triangle of `mesh`: barycentric (i, j, n - i - j) / n.
std::vector<Vec3> trianglePoints(const mesh4d::RestMesh& mesh, int n) {
    std::vector<Vec3> out;
    for (const auto& t : mesh.triangles)
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                const double u = double(i) / n, v = double(j) / n;
                out.push_back(u * mesh.positions[t[0]] + v * mesh.positions[t[1]] + (1 - u - v) * mesh.positions[t[2]]);
            }
    return out;
}

// The rocket as the raytracer sees it: its rest mesh and motion in the frame of the cut.
struct Body {
    mesh4d::RestMesh rest;
    mesh4d::Motion motion;
};
Body rocketBody(const Stage& stage) {
    const mesh4d::MotionInCameraFrame in_cut = cutMotionOf(stage.objects[0].spec, Model::Relativistic, stage.scene);
    mesh4d::RestMesh rotated;
    return {restInCameraFrame(stage.objects[0].rest, in_cut, &rotated), in_cut.motion};
}

// A torus (R 0.6, r 0.25) turned about two axes, boosted and accelerated obliquely: a body
// whose start frame is not the lab's and whose acceleration is along no axis.
Body turnedTorus() {
    Body b;
    b.rest = testmesh::torus(16, 8, 0.6, 0.25);
    const double c1 = std::cos(0.7), s1 = std::sin(0.7), c2 = std::cos(-0.4), s2 = std::sin(-0.4);
    for (Vec3& p : b.rest.positions) {
        p = {c1 * p.x - s1 * p.y, s1 * p.x + c1 * p.y, p.z};
        p = {c2 * p.x + s2 * p.z, p.y, -s2 * p.x + c2 * p.z};
    }
    b.motion = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 1.0, {-2, 0.5, -1}, {0.5, -0.2, 0.1});
    b.motion.acceleration = {0.6, 0.5, -0.3};  // |a| = 0.84: the horizon 1.19 behind the origin, beyond the torus
    return b;
}

mesh4d::ViewSurface coneAt(double t_c, const Vec3& apex) {
    mesh4d::ViewSurface v;
    v.kind = mesh4d::ViewKind::PastCone;
    v.t_c = t_c;
    v.apex = apex;
    return v;
}

}  // namespace

// latest_crossing.h: the largest distance of a triangle's points to its nearest vertex, against
// closed forms: the circumradius 1/sqrt(3) of the unit equilateral triangle, half the hypotenuse
// of the 3-4-5 right triangle, half the longest edge of an obtuse and of a degenerate triangle.
TEST(LatestCrossing, NearestVertexReachOfClosedFormTriangles) {
    EXPECT_NEAR(mesh4d::nearestVertexReach({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(0.75), 0}), 1 / std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(mesh4d::nearestVertexReach({0, 0, 0}, {3, 0, 0}, {0, 4, 0}), 2.5, 1e-11);
    EXPECT_NEAR(mesh4d::nearestVertexReach({0, 0, 0}, {4, 0, 0}, {2, 0.5, 0}), 2, 1e-11);
    EXPECT_NEAR(mesh4d::nearestVertexReach({0, 0, 0}, {1, 1, 1}, {3, 3, 3}), 0.5 * std::sqrt(27.0), 1e-11);
    // Sampled: no point of a skewed triangle is farther than that from its nearest vertex.
    const Vec3 a{0.1, -0.3, 0.2}, b{1.7, 0.4, -0.5}, c{0.6, 1.1, 0.9};
    double farthest = 0;
    for (int i = 0; i <= 200; ++i)
        for (int j = 0; i + j <= 200; ++j) {
            const Vec3 p = (i / 200.0) * a + (j / 200.0) * b + (1 - (i + j) / 200.0) * c;
            farthest = std::max(farthest, std::min({mesh4d::norm(p - a), mesh4d::norm(p - b), mesh4d::norm(p - c)}));
        }
    EXPECT_LE(farthest, mesh4d::nearestVertexReach(a, b, c));
    EXPECT_GT(farthest, 0.99 * mesh4d::nearestVertexReach(a, b, c));
}

// The bound the span rests on (latest_crossing.h, Rindler optics): two points of a Born-rigid
// body cross a past cone within |p - q| / min(1, |a| xi_min) of each other in the body's time,
// for random pairs of the rocket's and the torus's surface at several camera times, crossings
// from crossingBySearch. The largest ratio is printed; it comes near 1 (the bound is not loose
// by a factor) for the rocket, whose points along its length see each other by light along k.
TEST(LatestCrossing, CrossingsOfTwoPointsDifferByAtMostTheirLightTime) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/rocket.json"), &stage, &error)) << error;
    const Body rocket = rocketBody(stage), torus = turnedTorus();
    std::mt19937 rng(18);
    for (const Body* body : {&rocket, &torus}) {
        const std::vector<Vec3> points = trianglePoints(body->rest, 6);
        std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
        const double a = mesh4d::norm(body->motion.acceleration);
        double worst = 0;
        for (double t_c : {0.0, 4.0, 8.0, 12.0, 16.0}) {
            const mesh4d::ViewSurface view = coneAt(t_c, {0, 0, 6});
            for (int k = 0; k < 300; ++k) {
                const Vec3 p = points[pick(rng)], q = points[pick(rng)];
                if (mesh4d::norm(p - q) < 1e-3) continue;
                const double c = std::min({1.0, a * mesh4d::horizonDistance(body->motion, p),
                                           a * mesh4d::horizonDistance(body->motion, q)});
                const double ratio = std::fabs(crossingTime(view, body->motion, p) - crossingTime(view, body->motion, q)) * c /
                                     mesh4d::norm(p - q);
                EXPECT_LE(ratio, 1 + 1e-9) << "t_c " << t_c << " pair " << k;
                worst = std::max(worst, ratio);
            }
        }
        std::cout << "[light time] " << (body == &rocket ? "rocket" : "torus") << ": largest |s(p) - s(q)| c_min / |p - q| "
                  << worst << "\n";
        if (body == &rocket) {
            EXPECT_GT(worst, 0.9);
        }
    }
}

// latestCrossing against the crossings of dense points of every triangle (21 x 21 barycentric
// grid): never below any of them, within 0.01 s above the latest when refined, and sound with no
// refinement at all (one piece per triangle: the bound r / c_min of the header alone). At the
// rocket's late frames an interior point crosses after every vertex (the vertices' latest crossing
// is not a bound: the test fails for it).
TEST(LatestCrossing, BoundsTheCrossingOfEveryPointOfTheTriangles) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/rocket.json"), &stage, &error)) << error;
    const Body rocket = rocketBody(stage), torus = turnedTorus();
    struct Case {
        const Body* body;
        mesh4d::ViewSurface view;
        std::string name;
    };
    std::vector<Case> cases;
    for (long long k : {0LL, 40LL, 80LL, 120LL, 150LL, 153LL, 159LL})
        cases.push_back({&rocket, viewForFrame(stage.scene, Model::Relativistic, k), "rocket frame " + std::to_string(k)});
    for (double t_c : {2.0, 5.0, 9.0}) cases.push_back({&torus, coneAt(t_c, {0, 0, 6}), "torus t_c " + std::to_string(t_c)});
    int interior_later = 0;
    for (const Case& c : cases) {
        const std::vector<Vec3> points = trianglePoints(c.body->rest, c.body == &rocket ? 20 : 4);
        double latest = -INFINITY, vertex_latest = -INFINITY;
        for (const Vec3& p : points) latest = std::max(latest, crossingTime(c.view, c.body->motion, p));
        for (const Vec3& q : c.body->rest.positions) vertex_latest = std::max(vertex_latest, crossingTime(c.view, c.body->motion, q));
        const mesh4d::LatestCrossing refined = mesh4d::latestCrossing(c.body->rest, c.body->motion, c.view, 1e-3, 100000);
        const mesh4d::LatestCrossing coarse = mesh4d::latestCrossing(c.body->rest, c.body->motion, c.view, 0, 0);
        std::cout << "[latest crossing] " << c.name << ": sampled " << latest << " (vertices " << vertex_latest
                  << "), bound " << refined.bound << " after " << refined.splits << " splits, unrefined " << coarse.bound
                  << "\n";
        ASSERT_TRUE(refined.ok && coarse.ok) << c.name;
        const double rounding = 1e-12 * (1 + std::fabs(latest));
        EXPECT_LE(latest, refined.bound + rounding) << c.name;
        EXPECT_LE(latest, coarse.bound + rounding) << c.name;
        EXPECT_LE(refined.bound, latest + 0.01) << c.name;
        if (latest > vertex_latest + 1e-3) ++interior_later;
    }
    EXPECT_GE(interior_later, 3);
}

// pathSpanSeen as the raytracer calls it (the rocket in the frame of the cut, the slabs' offset
// 1e-3 of its diagonal) holds the object time of every sampled point's emission seen by the
// window's first and last frames, for one-frame and four-frame windows across the range and at
// the late frames 150..153; so does buildWorld's padded span.
TEST(RaytraceSpan, RocketSeenSpanHoldsEverySampledEmission) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/rocket.json"), &stage, &error)) << error;
    const Body rocket = rocketBody(stage);
    const std::vector<Vec3> points = trianglePoints(rocket.rest, 12);
    const double offset = 1e-3 * std::sqrt(2 * 2 + 0.5 * 0.5 + 0.5 * 0.5);
    for (const auto& [first, last] : std::vector<std::pair<long long, long long>>{
             {0, 0}, {30, 33}, {60, 60}, {100, 103}, {130, 130}, {150, 150}, {150, 153}, {153, 153}, {159, 159}}) {
        const mesh4d::ViewSurface view_first = viewForFrame(stage.scene, Model::Relativistic, first);
        const mesh4d::ViewSurface view_last = viewForFrame(stage.scene, Model::Relativistic, last);
        const SeenSpan seen = pathSpanSeen(rocket.rest, rocket.motion, view_first, view_last, offset);
        ASSERT_TRUE(seen.ok) << first;
        double lo = INFINITY, hi = -INFINITY;
        for (const Vec3& p : points) {
            lo = std::min(lo, crossingTime(view_first, rocket.motion, p));
            hi = std::max(hi, crossingTime(view_last, rocket.motion, p));
        }
        std::cout << "[rocket span] frames " << first << ".." << last << ": emissions " << lo << " .. " << hi << ", span "
                  << seen.span.lo << " .. " << seen.span.hi << "\n";
        EXPECT_LE(seen.span.lo, lo) << first;
        EXPECT_GE(seen.span.hi, hi) << last;
        EXPECT_LT(seen.span.hi - hi, 0.05) << last;  // tight: a slab or two at these times
        // buildWorld's padded span (render's, and the raytracer's fallback) holds them too.
        const mesh4d::World4D padded = buildWorld(stage.objects[0], Model::Relativistic, stage.scene, first, last);
        EXPECT_LE(padded.tau_a, lo) << first;
        EXPECT_GE(padded.tau_b, hi) << last;
    }
}

namespace {

// Frame k of the rocket traced at 240 x 135 with `options`, the camera turned to the rocket's
// origin as frame k sees it, with a field of view of 20 degrees (the rocket spans a third of the
// frame or more).
TracedFrame traceRocket(const Stage& stage, long long k, TracerOptions options, size_t* slabs = nullptr) {
    Scene scene = stage.scene;
    scene.camera.look_at = mesh4d::measure::crossingBySearch(viewForFrame(scene, Model::Relativistic, k),
                                                            rocketBody(stage).motion, {0, 0, 0}).x;
    scene.camera.fov_deg = 20;
    SceneTracer tracer(scene, stage.objects, stage.mirrors, Model::Relativistic, k, k, options);
    TracedFrame f = tracer.traceFrame(k, 240, 135);
    if (slabs) *slabs = tracer.worldCount();
    return f;
}

long long covered(const std::vector<int32_t>& object) {
    return std::count_if(object.begin(), object.end(), [](int32_t o) { return o >= 0; });
}

}  // namespace

// The rocket raytraced over its seen span gives the pictures of the seen span widened by 1 s of
// its time on both sides (span_margin: 20 or more slabs more at the late frames), byte for byte,
// across the range and at the late frames 150..153; narrowed by 0.2 s the pictures differ (an open
// end of the history shows the background), so the comparison can fail.
TEST(RaytraceSpan, RocketTracesWhatAWiderSpanTraces) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/rocket.json"), &stage, &error)) << error;
    int narrowed_differ = 0;
    for (long long k : {10LL, 60LL, 110LL, 150LL, 151LL, 152LL, 153LL, 159LL}) {
        size_t slabs = 0, wide_slabs = 0;
        const TracedFrame seen = traceRocket(stage, k, {}, &slabs);
        TracerOptions wide;
        wide.span_margin = 1;
        const TracedFrame widened = traceRocket(stage, k, wide, &wide_slabs);
        TracerOptions narrow;
        narrow.span_margin = -0.2;
        const TracedFrame narrowed = traceRocket(stage, k, narrow);
        std::cout << "[rocket traced] frame " << k << ": " << slabs << " slabs (widened " << wide_slabs << "), "
                  << covered(seen.object) << " pixels show it; narrowed, " << covered(narrowed.object) << "\n";
        EXPECT_GT(covered(seen.object), 1000) << k;
        if (k >= 110) {  // before t0 (the frames up to about 60) the grid has one slab
            EXPECT_GT(wide_slabs, slabs + 20) << k;
        }
        EXPECT_EQ(seen.object, widened.object) << k;
        EXPECT_TRUE(seen.image.rgb == widened.image.rgb) << k;
        narrowed_differ += narrowed.object != seen.object;
    }
    EXPECT_GE(narrowed_differ, 6);
}

// The rocket raytraced through its slabs over the seen span against the cut of the same frames
// (buildWorld's padded span, refined to T = 1e-3 of its diagonal), cast in 3D: every pixel where
// the two pictures of which pixels show the rocket differ has the other picture's value within one
// pixel (as RaytraceCrossCheck.RollingWheelThroughTimeSlabsMatchesTheRefinedCut). The span
// narrowed by 0.2 s fails that check at the late frames.
TEST(RaytraceSpan, RocketAtLateFramesMatchesTheRefinedCut) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(source("data/scenes/rocket.json"), &stage, &error)) << error;
    const int w = 240, h = 135;
    mesh4d::EventBox box;
    for (const Vec3& p : stage.objects[0].rest.positions) box.addPoint(p);
    for (long long k : {80LL, 150LL, 153LL}) {
        Scene scene = stage.scene;
        scene.camera.look_at = mesh4d::measure::crossingBySearch(viewForFrame(scene, Model::Relativistic, k),
                                                                rocketBody(stage).motion, {0, 0, 0}).x;
        scene.camera.fov_deg = 20;
        const mesh4d::World4D world = buildWorld(stage.objects[0], Model::Relativistic, scene, k, k);
        mesh4d::SliceSettings slice;
        slice.tolerance = 1e-3 * box.diagonal();
        const mesh4d::ApparentMesh cut = mesh4d::sliceWorld(world, viewForFrame(scene, Model::Relativistic, k), slice);
        const std::vector<int32_t> cast = testcast::castCut(scene.camera, w, h, cut);
        for (const double margin : {0.0, -0.2}) {
            TracerOptions options;
            options.span_margin = margin;
            SceneTracer tracer(scene, stage.objects, stage.mirrors, Model::Relativistic, k, k, options);
            const std::vector<int32_t> traced = tracer.traceFrame(k, w, h).object;
            const testcast::ImageDifference d = testcast::compareObjectImages(traced, cast, w, h);
            const long long shown = d.shown, differ = d.differ, far = d.far;
            std::cout << "[rocket cut] frame " << k << ", span margin " << margin << " s: " << shown << " pixels show it, "
                      << differ << " differ, " << far << " of them by more than a pixel\n";
            EXPECT_GT(shown, 1000) << k;
            if (margin == 0) {
                EXPECT_EQ(far, 0) << k;
            } else if (k >= 150) {
                EXPECT_GT(far, 20) << k;
            }
        }
    }
}
