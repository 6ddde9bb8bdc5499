// The speed-accuracy trade of the tolerance (issue: accuracy on a dial). For each scene and each
// tolerance T (vertex mode first, then T = 1e-1 ... 1e-6 times the object size) it times the cut
// of one frame and reports, as counters, the output triangles and the measured maximum error in
// both directions (mesh4d/refine/measure.h: output -> exact surface and exact surface -> output).
//
//   flanges: data/scenes/flanges.json, relativistic, frame 100 (the flanges crossing the
//            centreline); size = the flange's diagonal, sqrt(2^2 + 4^2 + 2^2) light-seconds.
//   sphere:  an icosphere (320 faces, radius 1) passing 4 light-seconds from the camera at 0.9c,
//            seen at closest approach, relativistic; size = its diameter 2.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "mesh4d/refine/measure.h"
#include "pipeline/commands/cli.h"
#include "pipeline/stage/prepared_object.h"
#include "pipeline/stage/worlds.h"
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
        out_err = std::max(out_err, mesh4d::measure::outputToExact(w, scene.view, m));
        in_err = std::max(in_err, mesh4d::measure::exactToOutput(w, scene.view, m, 8));
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

// An object at rest appearing (slice.cpp restPlan): the default scene's backdrop, a 30 x 8 ls quad
// of two triangles 23.675 ls from the camera, existing for lab time [-16, -10]. range(1) = 0: t_c =
// 9 s, a disc of radius 5.0 ls about the camera's foot is seen while every corner is still too far;
// 1: t_c = 12.5 s, the lower corners seen, the upper ones not. range(0) as in cutFrame, size = the
// quad's diagonal. Errors: *out* = largest distance of sampled output points (edge midpoints and
// centroids) from the seen region, *in* = largest distance of seen points of a 0.05 ls grid from
// the output (counter `missing` = 1 when nothing is output although a part is seen).
void BM_RestAppearing(benchmark::State& state) {
    mesh4d::RestMesh quad;
    quad.positions = {{-15, 0, 0}, {15, 0, 0}, {15, 8, 0}, {-15, 8, 0}};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    const mesh4d::Vec3 origin{0, -2.05, -23.675};
    const mesh4d::World4D w = mesh4d::extrude(
        quad, mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, origin, {0, 0, 0}), -16, -10, true, true);
    const double t_c = state.range(1) == 0 ? 9.0 : 12.5, p = 23.675, size = std::hypot(30.0, 8.0);
    const mesh4d::ViewSurface view{mesh4d::ViewKind::PastCone, t_c, {0, 0, 0}};
    mesh4d::SliceSettings settings;
    settings.max_segments = 4096;
    const int k = int(state.range(0));
    settings.tolerance = k == 0 ? 0.0 : std::pow(10.0, -k) * size;
    size_t triangles = 0;
    for (auto _ : state) {
        const mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, view, settings);
        triangles = m.triangles.size();
        benchmark::DoNotOptimize(m.positions.data());
    }
    mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, view, settings);
    for (auto& x : m.positions) x = x + m.origin;
    const double r_out = std::sqrt((t_c + 16 - p) * (t_c + 16 + p));  // the seen region in the plane:
    const double r_in = t_c + 10 > p ? std::sqrt((t_c + 10 - p) * (t_c + 10 + p)) : 0.0;  // r_in <= rho <= r_out
    auto rho = [&](const mesh4d::Vec3& x) { return std::hypot(x.x, x.y); };
    double out_err = 0;
    for (const auto& t : m.triangles) {
        const mesh4d::Vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
        for (const mesh4d::Vec3& x : {(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5, (a + b + c) / 3.0})
            out_err = std::max({out_err, rho(x) - r_out, r_in - rho(x)});
    }
    // Seen grid points against the output, in the plane: inside some output triangle, else the
    // distance to the nearest output edge.
    double in_err = 0;
    bool missing = false;
    for (int i = 0; i <= 600; ++i)
        for (int j = 0; j <= 160; ++j) {
            const mesh4d::Vec3 x = origin + mesh4d::Vec3{-15 + 0.05 * i, 0.05 * j, 0};
            if (rho(x) > r_out || rho(x) < r_in) continue;
            if (m.triangles.empty()) { missing = true; continue; }
            double best = INFINITY;
            for (const auto& t : m.triangles) {
                const mesh4d::Vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
                auto side = [&](const mesh4d::Vec3& u, const mesh4d::Vec3& v) {
                    return (v.x - u.x) * (x.y - u.y) - (v.y - u.y) * (x.x - u.x);
                };
                const double s0 = side(a, b), s1 = side(b, c), s2 = side(c, a);
                if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) { best = 0; break; }
                auto seg = [&](const mesh4d::Vec3& u, const mesh4d::Vec3& v) {
                    const mesh4d::Vec3 d = v - u;
                    const double s = std::clamp(mesh4d::dot(x - u, d) / mesh4d::dot(d, d), 0.0, 1.0);
                    return mesh4d::norm(x - (u + d * s));
                };
                best = std::min({best, seg(a, b), seg(b, c), seg(c, a)});
            }
            in_err = std::max(in_err, best);
        }
    state.counters["tolerance_rel"] = k == 0 ? 0.0 : std::pow(10.0, -k);
    state.counters["triangles"] = double(triangles);
    state.counters["err_out_rel"] = out_err / size;
    state.counters["err_in_rel"] = missing ? 0.0 : in_err / size;
    state.counters["missing"] = missing ? 1.0 : 0.0;
}

}  // namespace

BENCHMARK(BM_Flanges)->DenseRange(0, 6)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Sphere)->DenseRange(0, 6)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RenderFlanges)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RestAppearing)->ArgsProduct({{0, 1, 2, 3, 4}, {0, 1}})->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
