// The 4D raytracer's cost per ray (issue 20): the bounding hierarchy over the prisms in co-moving
// coordinates (mesh4d/ray4d.h) against the linear scan over every prism that `raytrace` and
// `figure` used before, side by side in one run. Google Benchmark; docs/PERFORMANCE.md quotes the
// ratios. None of this is a test (tests/raytrace_test.cpp checks that both find the same hits).
//
//   BM_TraceRays/H/N   160x90 rays (24 degrees high) along the past cone from the camera when a torus of
//                      about N triangles, passing 10 ls ahead at 0.9c, is seen crossing the view
//                      axis; H = 1 hierarchy, 0 linear scan; one core; items = rays
//   BM_TraceFrame/H/S  one whole frame of a scene as `raytrace` traces it (SceneTracer, 480x270,
//                      one thread, mirror bounces included): S = 0 the paper's flanges at t = 10 s
//                      (relativistic), 1 the Penrose sphere at t = 5 s (relativistic)
#include <benchmark/benchmark.h>

#include <ostream>
#include <sstream>
#include <string>

#include <tbb/task_arena.h>

#include "pipeline/trace/raytrace.h"

#include <cmath>
#include <map>

#include "mesh4d/angles.h"
#include "mesh4d/ray4d.h"
#include "test_meshes.h"
#include "quiet_stage.h"

namespace {

const mesh4d::World4D& passingTorus(long n) {
    static std::map<long, mesh4d::World4D> cache;
    auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    const int nv = std::max(4, int(std::sqrt(double(n) / 8.0)));
    const int nu = std::max(4, int(n / (2 * nv)));
    const mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -10}, {0.9, 0, 0});
    return cache.emplace(n, mesh4d::extrude(testmesh::torus(nu, nv, 2.0, 0.5), m, -100, 100, false, false)).first->second;
}

void BM_TraceRays(benchmark::State& state) {
    const bool hierarchy = state.range(0) != 0;
    const mesh4d::World4D& world = passingTorus(state.range(1));
    const mesh4d::TraceWorld trace = mesh4d::prepareTrace(world, hierarchy);
    constexpr int kW = 160, kH = 90;
    const double half_h = std::tan(12 * mesh4d::kPi / 180), half_w = half_h * kW / kH;
    long hits = 0;
    for (auto _ : state) {
        for (int py = 0; py < kH; ++py)
            for (int px = 0; px < kW; ++px) {
                mesh4d::Ray4D ray;
                ray.origin = {10, {0, 0, 0}};
                const mesh4d::Vec3 d{(2 * (px + 0.5) / kW - 1) * half_w, (1 - 2 * (py + 0.5) / kH) * half_h, -1};
                ray.direction = d / mesh4d::norm(d);
                hits += mesh4d::intersectWorld(trace, ray, INFINITY).has_value();
            }
    }
    benchmark::DoNotOptimize(hits);
    state.SetItemsProcessed(state.iterations() * kW * kH);
    state.counters["triangles"] = double(world.mesh.triangles.size());
    state.counters["hit_share"] = double(hits) / double(state.iterations() * kW * kH);
}

void BM_TraceFrame(benchmark::State& state) {
    const bool hierarchy = state.range(0) != 0;
    const bool sphere = state.range(1) != 0;
    apparent::Stage stage;
    std::string error;
    if (!apparent::loadQuietStage(
            std::string(APPARENT_SOURCE_DIR) + (sphere ? "/data/scenes/penrose_sphere.json" : "/data/scenes/flanges.json"),
            &stage, &error, {apparent::Model::Relativistic})) {
        state.SkipWithError(error.c_str());
        return;
    }
    const long long k = sphere ? 48 : 100;  // t = 5 s (12 fps, start 1) and t = 10 s
    apparent::TracerOptions options;
    options.hierarchy = hierarchy;
    apparent::SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, apparent::Model::Relativistic, k, k, options);
    tbb::task_arena one(1);
    for (auto _ : state) {
        apparent::TracedFrame frame;
        one.execute([&] { frame = tracer.traceFrame(k, 480, 270); });
        benchmark::DoNotOptimize(frame.image.rgb.data());
    }
    state.SetItemsProcessed(state.iterations() * 480 * 270);
}

}  // namespace

BENCHMARK(BM_TraceFrame)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TraceRays)
    ->ArgsProduct({{0, 1}, {320, 2'000, 20'000}})
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
