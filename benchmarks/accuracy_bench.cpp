// The speed-accuracy trade of the tolerance (issue: accuracy on a dial). For each scene and each
// tolerance T (vertex mode first, then T = 1e-1 ... 1e-6 times the object size) it times the cut
// of one frame and reports, as counters, the output triangles and the measured maximum error in
// both directions (tests/error_measure.h: output -> exact surface and exact surface -> output).
//
//   flanges: data/scenes/flanges.json, relativistic, frame 100 (the flanges crossing the
//            centreline); size = the flange's diagonal, sqrt(2^2 + 4^2 + 2^2) light-seconds.
//   sphere:  an icosphere (320 faces, radius 1) passing 4 light-seconds from the camera at 0.9c,
//            seen at closest approach, relativistic; size = its diameter 2.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "error_measure.h"
#include "pipeline/cli.h"
#include "pipeline/render.h"
#include "test_meshes.h"

namespace {

struct BenchScene {
    std::vector<mesh4d::World4D> worlds;
    mesh4d::ViewSurface view;
    double size = 1;
};

const BenchScene& flanges() {
    static const BenchScene s = [] {
        BenchScene b;
        apparent::Scene scene;
        apparent::loadScene(std::string(APPARENT_SOURCE_DIR) + "/data/scenes/flanges.json", &scene);
        std::vector<apparent::PreparedObject> objects;
        std::ostringstream log;
        apparent::MeshLimits limits;
        limits.allow_outside = true;  // the shipped scene reads ../meshes, whatever the working folder
        apparent::prepareObjects(scene, limits, &objects, log, true);
        for (const auto& o : objects) b.worlds.push_back(apparent::buildWorld(o, apparent::Model::Relativistic, scene, 0, 199));
        b.view = apparent::viewForFrame(scene, apparent::Model::Relativistic, 100);
        b.size = std::sqrt(24.0);
        return b;
    }();
    return s;
}

const BenchScene& sphere() {
    static const BenchScene s = [] {
        BenchScene b;
        const mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -4}, {0.9, 0, 0});
        b.worlds.push_back(mesh4d::extrude(testmesh::icosphere(2, 1.0), m, -100, 100, false, false));
        b.view = {mesh4d::ViewKind::PastCone, 4.0, {0, 0, 0}};
        b.size = 2.0;
        return b;
    }();
    return s;
}

// range(0): 0 = vertex mode, k >= 1: T = 10^-k * size.
void cutFrame(benchmark::State& state, const BenchScene& scene) {
    mesh4d::SliceSettings settings;
    settings.max_segments = 4096;
    const int k = int(state.range(0));
    settings.tolerance = k == 0 ? 0.0 : std::pow(10.0, -k) * scene.size;
    size_t triangles = 0;
    for (auto _ : state) {
        triangles = 0;
        for (const auto& w : scene.worlds) {
            const mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, scene.view, settings);
            triangles += m.triangles.size();
            benchmark::DoNotOptimize(m.positions.data());
        }
    }
    // Measured error, outside the timed loop.
    double out_err = 0, in_err = 0;
    for (const auto& w : scene.worlds) {
        const mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, scene.view, settings);
        out_err = std::max(out_err, errmeasure::outputToExact(w, scene.view, m));
        in_err = std::max(in_err, errmeasure::exactToOutput(w, scene.view, m, 8));
    }
    state.counters["tolerance_rel"] = k == 0 ? 0.0 : std::pow(10.0, -k);
    state.counters["triangles"] = double(triangles);
    state.counters["err_out_rel"] = out_err / scene.size;
    state.counters["err_in_rel"] = in_err / scene.size;
}

void BM_Flanges(benchmark::State& state) { cutFrame(state, flanges()); }
void BM_Sphere(benchmark::State& state) { cutFrame(state, sphere()); }

// End to end: `apparent render flanges.json --frames 90:110` writing the animated .glb, in
// vertex mode (0) and at T = 1e-3 x the flange's size (3); the ratio of the two is what a user
// waits for.
void BM_RenderFlanges(benchmark::State& state) {
    const std::string out = (std::filesystem::temp_directory_path() / "apparent_bench_render").string();
    const std::string tol = state.range(0) == 0 ? "vertex" : std::to_string(1e-3 * std::sqrt(24.0));
    const std::string scene = std::string(APPARENT_SOURCE_DIR) + "/data/scenes/flanges.json";
    const char* argv[] = {"apparent", "render", scene.c_str(), "--out", out.c_str(), "--frames", "90:110",
                          "--model", "relativistic", "--tolerance", tol.c_str(), "--quiet"};
    std::ostringstream o, e;
    for (auto _ : state)
        if (apparent::runCommandLine(12, argv, o, e) != 0) state.SkipWithError("render failed");
    state.counters["frames"] = 20;
    std::filesystem::remove_all(out);
}

}  // namespace

BENCHMARK(BM_Flanges)->DenseRange(0, 6)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Sphere)->DenseRange(0, 6)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RenderFlanges)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
