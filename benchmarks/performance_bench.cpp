// What the pipeline costs at scale (issue: model only what a scene requires). Google Benchmark;
// scripts/performance_report.sh runs it and writes docs/PERFORMANCE.md. Timings are compared as
// ratios within one run; none of this is a test.
//
//   BM_MemoryCopy          the machine's limit: bytes/s of a 256 MiB copy (one core)
//   BM_CutVertexMode/N     1. and 2.: the cone cut alone, vertex mode, on a torus of N triangles,
//                          one core: vertex-frames per second, time per frame against N
//   BM_ClosedFormOnly/N    the closed form alone (no output mesh bookkeeping), one core
//   BM_CutTolerance/N      the same at tolerance 1e-3 x the object's size
//   BM_ExportFrame/F       1.: one frame of the 1M-triangle torus cut and written: F = 0 .glb, 1 PLY
//                          (the cut runs on one thread, it has no parallel step; the export on
//                          TBB's default pool, every core)
//   BM_ExportFrameOneThread/F  the same with TBB held to one thread: cut and export on one core,
//                          as BM_CutVertexMode
//   BM_GlbPrepare          the lone .glb frame's in-memory part alone (GlbSequenceWriter::prepare:
//                          bounds, crease split, float32 conversion) on the frame cut once
//   BM_PlySerialize        the PLY frame's bytes alone (serializePly), likewise
//   BM_GlbSequenceFrame    2.: one more frame of a .glb sequence of the 1M-triangle torus, cut and
//                          exported (the writer's buffers reused); finish_ms_per_frame: the file's
//                          assembly at the end, per frame
//   process_cpu_ms         (the cuts and the exports above) CPU time of the whole process per
//                          iteration, every thread: the work done, fair also on a shared machine
//   BM_Frames/N            3.: `apparent render` end to end, N frames of a 20k-triangle torus (.glb)
//   BM_Culling/C           4.: 100 objects, most not existing or out of view in a frame;
//                          C = 1 with the 4D-box cull and --cull-view, 0 with both off
//   BM_Threads/T           5.: `apparent render`, 40 frames of a 200k-triangle torus, T threads
//   BM_Million100/T        the target: 1M triangles, 100 frames, tolerance 1e-3 x size, cut on
//                          2 threads (T = 2), no export
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/resource.h>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "exporters/gltf.h"
#include "exporters/ply.h"
#include "pipeline/commands/cli.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"
#include "test_meshes.h"
#include "quiet_stage.h"

namespace {

namespace fs = std::filesystem;
using mesh4d::Vec3;

// A torus of about n triangles (2 nu nv), ring radius 2, tube 0.5: size (diameter) 5.
mesh4d::RestMesh torusOf(long n) {
    const int nv = std::max(4, int(std::sqrt(double(n) / 8.0)));
    const int nu = std::max(4, int(n / (2 * nv)));
    return testmesh::torus(nu, nv, 2.0, 0.5);
}
constexpr double kTorusSize = 5.0;

// The torus passing 10 ls in front of the camera at 0.9c, seen as it crosses the view axis.
struct Passing {
    mesh4d::World4D world;
    mesh4d::ViewSurface view{mesh4d::ViewKind::PastCone, 0.0, {0, 0, 0}};
};
const Passing& passing(long n) {
    static std::map<long, Passing> cache;
    auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    Passing p;
    const mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -10}, {0.9, 0, 0});
    p.world = mesh4d::extrude(torusOf(n), m, -100, 100, false, false);
    return cache.emplace(n, std::move(p)).first->second;
}

// CPU seconds of the whole process (every thread, user + system) so far: the work a benchmark
// does, whatever else shares the machine (wall times are only fair on an idle one).
double processCpuSeconds() {
    struct rusage u {};
    ::getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Sets the counter process_cpu_ms: process CPU per iteration since `start` (processCpuSeconds()).
void setProcessCpu(benchmark::State& state, double start) {
    state.counters["process_cpu_ms"] =
        state.iterations() > 0 ? 1e3 * (processCpuSeconds() - start) / double(state.iterations()) : 0.0;
}

void BM_MemoryCopy(benchmark::State& state) {
    const size_t n = size_t(256) << 20;
    std::vector<char> a(n, 1), b(n, 2);
    for (auto _ : state) {
        std::memcpy(b.data(), a.data(), n);
        benchmark::DoNotOptimize(b.data());
        benchmark::ClobberMemory();
    }
    // Read + write.
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(2 * n));
}

void cut(benchmark::State& state, double tolerance) {
    const Passing& p = passing(state.range(0));
    mesh4d::SliceSettings s;
    s.tolerance = tolerance;
    size_t triangles = 0;
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) {
        const mesh4d::ApparentMesh m = mesh4d::sliceWorld(p.world, p.view, s);
        triangles = m.triangles.size();
        benchmark::DoNotOptimize(m.positions.data());
    }
    setProcessCpu(state, cpu0);
    const double vertices = double(p.world.mesh.positions.size());
    state.counters["input_triangles"] = double(p.world.mesh.triangles.size());
    state.counters["output_triangles"] = double(triangles);
    state.counters["vertex_frames_per_s"] = benchmark::Counter(vertices, benchmark::Counter::kIsIterationInvariantRate);
}
void BM_CutVertexMode(benchmark::State& state) { cut(state, 0.0); }

// The closed form alone (mesh4d::cutRestLocalBatch): positions and emission times of every vertex,
// without the output mesh's bookkeeping (triangles, rest points) that sliceWorld adds.
void BM_ClosedFormOnly(benchmark::State& state) {
    const Passing& p = passing(state.range(0));
    const mesh4d::ViewAnchor anchor = mesh4d::viewAnchor(p.view, p.world.motion);
    const size_t n = p.world.mesh.positions.size();
    std::vector<Vec3> positions(n);
    std::vector<double> times(n);
    for (auto _ : state) {
        mesh4d::cutRestLocalBatch(anchor, p.world.motion, p.world.mesh.positions.data(), n, positions.data(), times.data());
        benchmark::DoNotOptimize(positions.data());
        benchmark::ClobberMemory();
    }
    state.counters["vertex_frames_per_s"] = benchmark::Counter(double(n), benchmark::Counter::kIsIterationInvariantRate);
}
void BM_CutTolerance(benchmark::State& state) { cut(state, 1e-3 * kTorusSize); }

void BM_ExportFrame(benchmark::State& state) {
    const Passing& p = passing(1'000'000);
    const fs::path dir = fs::temp_directory_path() / "apparent_perf_export";
    fs::create_directories(dir);
    apparent::SequenceInfo info;
    info.model = "relativistic";
    info.fps = 10;
    info.objects.emplace_back().name = "torus";
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) {
        std::vector<apparent::ExportFrame> frames(1);  // the frame cut into place (a copy is no part of the export)
        frames[0].objects.push_back(mesh4d::sliceWorld(p.world, p.view, {}));
        std::string error;
        const bool ok = state.range(0) == 0
                            ? apparent::writeAnimatedGlb((dir / "f.glb").string(), frames, info, {}, nullptr, &error)
                            : apparent::writePly((dir / "f.ply").string(), frames[0], info, &error);
        if (!ok) state.SkipWithError(error.c_str());
    }
    setProcessCpu(state, cpu0);
    state.counters["vertex_frames_per_s"] =
        benchmark::Counter(double(p.world.mesh.positions.size()), benchmark::Counter::kIsIterationInvariantRate);
    fs::remove_all(dir);
}

void BM_ExportFrameOneThread(benchmark::State& state) {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    BM_ExportFrame(state);
}

// The frame of BM_ExportFrame, cut once.
const apparent::ExportFrame& exportFrame() {
    static const apparent::ExportFrame frame = [] {
        apparent::ExportFrame f;
        f.objects.push_back(mesh4d::sliceWorld(passing(1'000'000).world, passing(1'000'000).view, {}));
        return f;
    }();
    return frame;
}

void BM_GlbPrepare(benchmark::State& state) {
    const apparent::ExportFrame& frame = exportFrame();
    apparent::SequenceInfo info;
    info.model = "relativistic";
    info.fps = 10;
    info.objects.emplace_back().name = "torus";
    const fs::path dir = fs::temp_directory_path() / "apparent_perf_prepare";
    apparent::GlbSequenceWriter writer((dir / "f.glb").string(), info, {});  // nothing written: no add()
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) benchmark::DoNotOptimize(writer.prepare(frame).get());
    setProcessCpu(state, cpu0);
}

void BM_PlySerialize(benchmark::State& state) {
    const apparent::ExportFrame& frame = exportFrame();
    std::string bytes;
    const double cpu0 = processCpuSeconds();
    for (auto _ : state) {
        apparent::serializePly(frame, apparent::SequenceInfo{}, &bytes);
        benchmark::DoNotOptimize(bytes.data());
    }
    setProcessCpu(state, cpu0);
}

// A .glb sequence of the 1M-triangle torus, one frame per iteration (camera time advancing 0.05 s
// a frame), cut and added to one GlbSequenceWriter: crease split, normals, float32 conversion
// and the frame's data written out, with the buffers of earlier frames reused. The file's
// assembly by finish() (JSON, BIN chunk copied into place, fsync, rename) is timed apart and
// reported per frame.
void BM_GlbSequenceFrame(benchmark::State& state) {
    const Passing& p = passing(1'000'000);
    const fs::path dir = fs::temp_directory_path() / "apparent_perf_sequence";
    fs::create_directories(dir);
    apparent::SequenceInfo info;
    info.model = "relativistic";
    info.fps = 20;
    info.objects.emplace_back().name = "torus";
    long long k = 0;
    double finish_ms = 0, finish_cpu_ms = 0;
    const double cpu0 = processCpuSeconds();
    {
        apparent::GlbSequenceWriter writer((dir / "s.glb").string(), info, {});
        for (auto _ : state) {
            mesh4d::ViewSurface view = p.view;
            view.t_c = 0.05 * double(k);
            apparent::ExportFrame frame;
            frame.index = k++;
            frame.t_c = view.t_c;
            frame.objects.push_back(mesh4d::sliceWorld(p.world, view, {}));
            std::string error;
            if (!writer.add(frame, &error)) state.SkipWithError(error.c_str());
        }
        setProcessCpu(state, cpu0);
        const double cpu1 = processCpuSeconds();
        const auto t0 = std::chrono::steady_clock::now();
        std::string error;
        if (!writer.finish(nullptr, &error)) state.SkipWithError(error.c_str());
        finish_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        finish_cpu_ms = 1e3 * (processCpuSeconds() - cpu1);
    }
    state.counters["finish_cpu_ms_per_frame"] = k > 0 ? finish_cpu_ms / double(k) : 0.0;
    state.counters["finish_ms_per_frame"] = k > 0 ? finish_ms / double(k) : 0.0;
    state.counters["vertex_frames_per_s"] =
        benchmark::Counter(double(p.world.mesh.positions.size()), benchmark::Counter::kIsIterationInvariantRate);
    fs::remove_all(dir);
}

// A scene folder with an OBJ of the torus and `objects` JSON entries.
std::string writeScene(const std::string& name, long triangles, double seconds, double fps, const std::string& objects,
                       const std::string& model = "relativistic") {
    const fs::path dir = fs::temp_directory_path() / ("apparent_perf_" + name);
    fs::create_directories(dir);
    if (!fs::exists(dir / "torus.obj")) {
        const mesh4d::RestMesh m = torusOf(triangles);
        std::ofstream obj(dir / "torus.obj");
        obj.precision(17);
        for (const auto& v : m.positions) obj << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
        for (const auto& t : m.triangles) obj << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }
    std::ofstream(dir / "scene.json") << R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "frames": {"start": 0, "end": )"
                                      << seconds << R"(, "fps": )" << fps << R"(}, "model": ")" << model
                                      << R"(", "tolerance": "vertex", "objects": [)" << objects << "]}";
    return (dir / "scene.json").string();
}

int renderScene(const std::string& scene, const std::vector<std::string>& extra) {
    const std::string out = (fs::path(scene).parent_path() / "out").string();
    std::vector<std::string> args = {"apparent", "render", scene, "--out", out, "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<const char*> argv;
    for (const auto& a : args) argv.push_back(a.c_str());
    std::ostringstream o, e;
    return apparent::runCommandLine(int(argv.size()), argv.data(), o, e);
}

void BM_Frames(benchmark::State& state) {
    const long n = state.range(0);
    const std::string scene =
        writeScene("frames", 20'000, double(n) / 10.0, 10.0, R"({"mesh": "torus.obj", "position": [-4, 0, -10], "velocity": [0.8, 0, 0]})");
    for (auto _ : state)
        if (renderScene(scene, {"--format", "glb"}) != 0) state.SkipWithError("render failed");
    state.counters["frames"] = double(n);
    state.counters["s_per_frame"] = benchmark::Counter(double(n), benchmark::Counter::kIsIterationInvariantRate |
                                                                      benchmark::Counter::kInvert);
}

// 100 tori of 2000 triangles on a 10 x 10 grid, half of them behind the camera, each existing for
// 1 s of a 20 s sequence at staggered times: in a frame about 1 in 40 shows.
void BM_Culling(benchmark::State& state) {
    std::ostringstream objects;
    for (int i = 0; i < 100; ++i) {
        const double x = (i % 10 - 4.5) * 6, z = (i / 10 % 5) * 6 + 20;
        const double side = i < 50 ? -1 : 1;  // ahead of the camera or behind it
        const double from = 0.2 * i;
        if (i) objects << ",";
        objects << R"({"mesh": "torus.obj", "position": [)" << x << ", 0, " << side * z
                << R"(], "velocity": [0.5, 0, 0], "exists": [)" << from << ", " << from + 1 << "]}";
    }
    const std::string scene = writeScene("culling", 2000, 20.0, 10.0, objects.str());
    const bool cull = state.range(0) == 1;
    apparent::Stage stage;
    std::string error;
    if (!apparent::loadQuietStage(scene, &stage, &error)) {
        state.SkipWithError(error.c_str());
        return;
    }
    const apparent::Scene& sc = stage.scene;
    const std::vector<mesh4d::World4D> worlds =
        apparent::buildWorlds(stage.objects, apparent::Model::Relativistic, sc, stage.first, stage.last_excl - 1);
    mesh4d::SliceSettings s;
    s.cull = cull;
    size_t shown = 0, cut = 0;
    for (auto _ : state) {
        shown = cut = 0;
        for (long long k = stage.first; k < stage.last_excl; ++k) {
            const mesh4d::ViewSurface view = apparent::viewForFrame(sc, apparent::Model::Relativistic, k);
            for (const auto& w : worlds) {
                if (cull && !apparent::inCameraView(sc.camera, mesh4d::apparentBound(w, view))) continue;
                const mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, view, s);
                ++cut;
                shown += !m.triangles.empty();
                benchmark::DoNotOptimize(m.positions.data());
            }
        }
    }
    state.counters["object_frames_shown"] = double(shown);
    state.counters["object_frames_cut"] = double(cut);
}

void BM_Threads(benchmark::State& state) {
    const std::string scene =
        writeScene("threads", 200'000, 4.0, 10.0, R"({"mesh": "torus.obj", "position": [-4, 0, -10], "velocity": [0.8, 0, 0]})");
    const std::string threads = std::to_string(state.range(0));
    for (auto _ : state)
        if (renderScene(scene, {"--format", "glb", "--threads", threads}) != 0) state.SkipWithError("render failed");
}

void BM_Million100(benchmark::State& state) {
    const Passing& p = passing(1'000'000);
    mesh4d::SliceSettings s;
    s.tolerance = 1e-3 * kTorusSize;
    tbb::task_arena arena(int(state.range(0)));
    size_t triangles = 0;
    for (auto _ : state) {
        std::vector<size_t> counts(100);
        arena.execute([&] {
            tbb::parallel_for(0, 100, [&](int k) {
                mesh4d::ViewSurface view = p.view;
                view.t_c = 0.1 * (k - 50);
                counts[size_t(k)] = mesh4d::sliceWorld(p.world, view, s).triangles.size();
            });
        });
        triangles = 0;
        for (size_t c : counts) triangles = std::max(triangles, c);
    }
    state.counters["max_output_triangles"] = double(triangles);
}

}  // namespace

BENCHMARK(BM_MemoryCopy)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CutVertexMode)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedFormOnly)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CutTolerance)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExportFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExportFrameOneThread)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GlbPrepare)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlySerialize)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GlbSequenceFrame)->Iterations(40)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Frames)->Arg(1)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_Culling)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Threads)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_Million100)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1);

BENCHMARK_MAIN();
