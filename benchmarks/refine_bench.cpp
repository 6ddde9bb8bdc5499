// Cost per output triangle of the tolerance mode's refinement against vertex mode (issue 13: per
// output triangle at most 3x vertex mode's cost per triangle, at every T).
//
// For each scene and tolerance T = 10^-k x size (k = range(1)), one frame is cut with the
// tolerance, and the uniform subdivision of the input whose triangle count is nearest the refined
// output's (12 4^j for the box, 320 4^j for the sphere) is cut in vertex mode. Both are timed in
// the same loop, alternately, by the thread's CPU clock (time the thread waits for a core on a
// shared machine is not counted: a long cut would otherwise be preempted more often than a short
// one) around blocks of cuts of about 2 ms each, and each keeps its best time per cut over the
// iterations. Counters:
//   tol_ns_per_tri     best time of the tolerance cut / its output triangles
//   vertex_ns_per_tri  best time of the vertex cut of the uniform mesh / its triangles
//   ratio              tol_ns_per_tri / vertex_ns_per_tri (the target: <= 3)
//   triangles, uniform_triangles: the two output sizes.
//
//   box:      the unit box passing 2 ls from the camera at 0.9c, seen at closest approach
//             (docs/ACCURACY.md), size = its diagonal sqrt 3.
//   sphere:   the 320-face icosphere of radius 1 passing 4 ls away at 0.9c, size = its diameter 2.
//   plate:    a flange-like plate (2 x 4 ls, 4 triangles about its centre) 18.675 ls away at 0.866c,
//             seen at closest approach, size = its diagonal sqrt 20: pieces far from the camera,
//             which the refinement fills with templates (mesh4d/refine/tessellate.h).
//
// Instruction counts (repeatable on a shared machine, unlike times): `refine_bench --count SCENE K`
// (SCENE: 0 or box, 1 or sphere320, 2 or plate)
// makes one tolerance cut and one vertex cut of the matching uniform mesh, each in its own function
// (countTolerance, countVertex), and prints both output sizes; run it under
//   valgrind --tool=callgrind --toggle-collect='*countTolerance*' build/benchmarks/refine_bench --count 0 4
// (or '*countVertex*') and divide the instructions by the triangles printed. It also prints an
// FNV-1a hash of the tolerance cut's whole output (tolerance_output_fnv), to show that a change
// meant to be a pure speed-up leaves every output byte as it was.
//
// `refine_bench --count-warm SCENE K` does the same after one uncounted cut of each kind first
// (outside countTolerance and countVertex): the counted cuts are then a frame as a render's later
// frames pay it (the refinement's per-thread scratch already allocated, the library calls already
// bound, the first calls' set-up done), which is the fixed cost per frame of a many-frame render
// on a tiny mesh. The first-frame costs that --count includes are the difference of the two.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "mesh4d/slice.h"
#include "mesh4d/refine/subdivide.h"
#include "test_meshes.h"

namespace {

struct Scene {
    mesh4d::RestMesh mesh;
    mesh4d::Motion motion;
    mesh4d::ViewSurface view;
    double size;
};

Scene boxNear() {
    mesh4d::RestMesh box;
    for (int i = 0; i < 8; ++i) box.positions.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
    const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        box.triangles.push_back({q[0], q[1], q[2]});
        box.triangles.push_back({q[0], q[2], q[3]});
    }
    return {box, mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -2}, {0.9, 0, 0}),
            {mesh4d::ViewKind::PastCone, 2.0, {0, 0, 0}}, std::sqrt(3.0)};
}

Scene sphereMid() {
    return {testmesh::icosphere(2, 1.0), mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -4}, {0.9, 0, 0}),
            {mesh4d::ViewKind::PastCone, 4.0, {0, 0, 0}}, 2.0};
}

Scene plateFar() {
    mesh4d::RestMesh plate;
    plate.positions = {{-1, -2, 0}, {1, -2, 0}, {1, 2, 0}, {-1, 2, 0}, {0, 0, 0}};
    plate.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    return {plate, mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -18.675}, {0.866, 0, 0}),
            {mesh4d::ViewKind::PastCone, 18.675, {0, 0, 0}}, std::sqrt(20.0)};
}

Scene sceneOf(long i) { return i == 0 ? boxNear() : i == 1 ? sphereMid() : plateFar(); }

double threadSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// CPU seconds of one cut (the output's release included, as a caller pays it), averaged over
// `repeats` cuts: the thread's CPU clock is read around a block long enough to be above its grain.
double seconds(const mesh4d::World4D& w, const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& s, size_t* tris,
               int repeats) {
    const double t0 = threadSeconds();
    for (int r = 0; r < repeats; ++r) {
        const mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, view, s);
        benchmark::DoNotOptimize(m.positions.data());
        *tris = m.triangles.size();
    }
    return (threadSeconds() - t0) / repeats;
}

// Cuts per block so that a block takes about 2 ms of CPU.
int repeatsFor(const mesh4d::World4D& w, const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& s) {
    size_t tris = 0;
    const double one = seconds(w, view, s, &tris, 1);
    const double more = seconds(w, view, s, &tris, std::max(1, int(2e-3 / std::max(one, 1e-7))));
    return std::max(1, std::min(100000, int(2e-3 / std::max(more, 1e-9))));
}

// range(0): 0 = box, 1 = sphere, 2 = plate; range(1): k, T = 10^-k x size.
void BM_PerTriangle(benchmark::State& state) {
    const Scene sc = sceneOf(state.range(0));
    const mesh4d::World4D w = mesh4d::extrude(sc.mesh, sc.motion, -100, 100, false, false);
    mesh4d::SliceSettings tol;
    tol.max_segments = 4096;
    tol.tolerance = std::pow(10.0, -double(state.range(1))) * sc.size;
    size_t tris = 0;
    const int tol_repeats = repeatsFor(w, sc.view, tol);
    seconds(w, sc.view, tol, &tris, 1);
    // The uniform level whose triangle count is nearest (in ratio) the refined output's.
    int level = 0;
    while (double(sc.mesh.triangles.size()) * std::pow(4.0, level + 0.5) < double(tris)) ++level;
    const mesh4d::World4D uw = mesh4d::extrude(mesh4d::subdivideUniform(sc.mesh, level), sc.motion, -100, 100, false, false);
    const mesh4d::SliceSettings vertex;
    const int vertex_repeats = repeatsFor(uw, sc.view, vertex);
    double best_tol = INFINITY, best_vertex = INFINITY;
    size_t utris = 0;
    for (auto _ : state) {
        const double a = seconds(w, sc.view, tol, &tris, tol_repeats);
        const double b = seconds(uw, sc.view, vertex, &utris, vertex_repeats);
        best_tol = std::min(best_tol, a);
        best_vertex = std::min(best_vertex, b);
        state.SetIterationTime(a * tol_repeats + b * vertex_repeats);
    }
    const double tol_ns = 1e9 * best_tol / double(std::max<size_t>(tris, 1));
    const double vertex_ns = 1e9 * best_vertex / double(std::max<size_t>(utris, 1));
    state.counters["tol_ns_per_tri"] = tol_ns;
    state.counters["vertex_ns_per_tri"] = vertex_ns;
    state.counters["ratio"] = tol_ns / vertex_ns;
    state.counters["triangles"] = double(tris);
    state.counters["uniform_triangles"] = double(utris);
}

}  // namespace

BENCHMARK(BM_PerTriangle)
    ->ArgsProduct({{0, 1, 2}, {2, 3, 4, 5}})
    ->ArgNames({"scene", "k"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

namespace {
[[gnu::noinline]] size_t countTolerance(const mesh4d::World4D& w, const mesh4d::ViewSurface& v, const mesh4d::SliceSettings& s) {
    return mesh4d::sliceWorld(w, v, s).triangles.size();
}
// FNV-1a of every output array and counter of one cut: a refactoring of the refinement must leave
// it unchanged (printed by --count, outside the counted functions).
uint64_t outputHash(const mesh4d::ApparentMesh& m) {
    uint64_t h = 1469598103934665603ull;
    auto mix = [&](const void* p, size_t n) {
        const unsigned char* b = static_cast<const unsigned char*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    };
    mix(m.positions.data(), m.positions.size() * sizeof(mesh4d::Vec3));
    mix(m.emission_times.data(), m.emission_times.size() * sizeof(double));
    mix(m.rest_points.data(), m.rest_points.size() * sizeof(mesh4d::Vec3));
    mix(m.triangles.data(), m.triangles.size() * sizeof(m.triangles[0]));
    mix(m.source_triangles.data(), m.source_triangles.size() * sizeof(uint32_t));
    const size_t counters[4] = {m.refined_triangles, m.limited_triangles, m.clipped_triangles, size_t(m.over_budget)};
    mix(counters, sizeof(counters));
    return h;
}
[[gnu::noinline]] size_t countVertex(const mesh4d::World4D& w, const mesh4d::ViewSurface& v) {
    return mesh4d::sliceWorld(w, v, mesh4d::SliceSettings{}).triangles.size();
}
}  // namespace

int main(int argc, char** argv) {
    const bool warm = argc == 4 && std::string(argv[1]) == "--count-warm";
    if (argc == 4 && (std::string(argv[1]) == "--count" || warm)) {
        // SCENE: 0 or box, 1 or sphere320, 2 or plate (anything else is refused: atoi would read
        // a name as 0, the box).
        const std::string name = argv[2];
        const long index = name == "0" || name == "box" ? 0 : name == "1" || name == "sphere320" ? 1 : name == "2" || name == "plate" ? 2 : -1;
        if (index < 0) {
            std::fprintf(stderr, "refine_bench: SCENE '%s': not a scene (0 or box, 1 or sphere320, 2 or plate)\n", argv[2]);
            return 2;
        }
        const Scene sc = sceneOf(index);
        const mesh4d::World4D w = mesh4d::extrude(sc.mesh, sc.motion, -100, 100, false, false);
        mesh4d::SliceSettings tol;
        tol.max_segments = 4096;
        tol.tolerance = std::pow(10.0, -double(std::atoi(argv[3]))) * sc.size;
        if (warm) mesh4d::sliceWorld(w, sc.view, tol);
        const size_t tris = countTolerance(w, sc.view, tol);
        int level = 0;
        while (double(sc.mesh.triangles.size()) * std::pow(4.0, level + 0.5) < double(tris)) ++level;
        const mesh4d::World4D uw =
            mesh4d::extrude(mesh4d::subdivideUniform(sc.mesh, level), sc.motion, -100, 100, false, false);
        if (warm) mesh4d::sliceWorld(uw, sc.view, mesh4d::SliceSettings{});
        const size_t utris = countVertex(uw, sc.view);
        std::printf("tolerance_triangles %zu\nvertex_triangles %zu\ntolerance_output_fnv %016llx\n", tris, utris,
                    (unsigned long long)outputHash(mesh4d::sliceWorld(w, sc.view, tol)));
        return 0;
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
