// Loading a mesh against Debian's gltfpack on the same file, and the cut and PLY/OBJ export of a
// frame, for tori of 1e3..1e6 triangles (issue 16). Google Benchmark; scripts/load_report.py turns
// its JSON into the "Loading and per-frame export" section of docs/PERFORMANCE.md. Ratios within one run.
//
//   BM_LoadVsGltfpack/F/N  one process loads a torus of N triangles as `apparent` does before its
//                          first frame (scene, mesh file, transform, the 4D history of one model:
//                          pipeline/stage/stage.h, pipeline/stage/worlds.h takeWorlds); another runs
//                          `gltfpack -i FILE -o out.glb` on the same file (F = 0 OBJ, 2 .glb).
//                          F = 1 loads the binary PLY of the same torus, compared with gltfpack on
//                          its OBJ (gltfpack reads no PLY). Both are child processes measured alike
//                          (wall time, ru_maxrss from wait4): counters load_s, gltfpack_s,
//                          time_ratio, load_peak_MiB, gltfpack_peak_MiB, peak_ratio.
//   BM_Cut/N               the vertex-mode cone cut of one frame, one core
//   BM_WritePly/N          that frame written to PLY (the sink's writer: temporary file, fsync, rename)
//   BM_SerializePly/N      the same frame's PLY bytes in memory only (no file)
//   BM_WriteObj/N          the same to OBJ
#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "exporters/obj.h"
#include "exporters/ply.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"
#include "test_meshes.h"
#include "quiet_stage.h"

namespace {

namespace fs = std::filesystem;

// A torus of about n triangles (2 nu nv), ring radius 2, tube 0.5 (as performance_bench.cpp).
mesh4d::RestMesh torusOf(long n) {
    const int nv = std::max(4, int(std::sqrt(double(n) / 8.0)));
    const int nu = std::max(4, int(n / (2 * nv)));
    return testmesh::torus(nu, nv, 2.0, 0.5);
}

std::string self_path;  // this program, for the child processes

fs::path benchDir(long n) { return fs::temp_directory_path() / ("apparent_load_bench_" + std::to_string(n)); }

// The torus of n triangles as OBJ ("%.17g"), binary PLY (double x y z) and .glb (gltfpack's
// conversion of the OBJ, positions unquantized), and a scene with the torus passing at 0.9c.
void writeInputs(long n) {
    const fs::path dir = benchDir(n);
    if (fs::exists(dir / "torus.glb")) return;
    fs::create_directories(dir);
    const mesh4d::RestMesh m = torusOf(n);
    {
        std::ofstream obj(dir / "torus.obj");
        obj.precision(17);
        for (const auto& v : m.positions) obj << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
        for (const auto& t : m.triangles) obj << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }
    {
        std::ofstream ply(dir / "torus.ply", std::ios::binary);
        ply << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.positions.size()
            << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << m.triangles.size()
            << "\nproperty list uchar int vertex_indices\nend_header\n";
        for (const auto& v : m.positions) ply.write(reinterpret_cast<const char*>(&v.x), 24);
        for (const auto& t : m.triangles) {
            ply.put(char(3));
            ply.write(reinterpret_cast<const char*>(t.data()), 12);
        }
    }
    const std::string cmd = "gltfpack -noq -i '" + (dir / "torus.obj").string() + "' -o '" + (dir / "torus.glb").string() + "' >/dev/null";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gltfpack could not write %s\n", (dir / "torus.glb").c_str());
    for (const char* ext : {"obj", "ply", "glb"})
        std::ofstream(dir / (std::string("scene_") + ext + ".json"))
            << R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "frames": {"start": 0, "end": 1, "fps": 10},)"
            << R"( "model": "relativistic", "tolerance": "vertex", "objects": [{"mesh": "torus.)" << ext
            << R"(", "position": [-4, 0, -10], "velocity": [0.9, 0, 0]}]})";
}

struct ChildRun {
    double seconds = 0;
    double peak_mib = 0;
    bool ok = false;
};

// Runs argv as a child process: wall time and peak resident memory (ru_maxrss of wait4).
ChildRun runChild(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
        const int null = ::open("/dev/null", O_WRONLY);
        if (null >= 0) ::dup2(null, 1);
        ::execvp(argv[0], argv.data());
        _exit(127);
    }
    int status = 0;
    struct rusage usage {};
    ::wait4(pid, &status, 0, &usage);
    ChildRun r;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.peak_mib = double(usage.ru_maxrss) / 1024.0;
    r.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    return r;
}

// The child's work: what `apparent render` does before its first frame.
int loadChild(const std::string& scene) {
    apparent::Stage stage;
    std::string error;
    if (!apparent::loadQuietStage(scene, &stage, &error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 2;
    }
    // As render's last (here only) model: the worlds take the stage's meshes (runLastFrameLoop).
    const std::vector<mesh4d::World4D> worlds =
        apparent::takeWorlds(&stage.objects, apparent::Model::Relativistic, stage.scene, stage.first, stage.last_excl - 1);
    return worlds.empty() || worlds[0].empty() ? 1 : 0;
}

void BM_LoadVsGltfpack(benchmark::State& state) {
    const long n = state.range(1);
    writeInputs(n);
    const fs::path dir = benchDir(n);
    static const char* kExt[] = {"obj", "ply", "glb"};
    const std::string ext = kExt[state.range(0)];
    const std::string peer_input = (dir / (ext == "ply" ? "torus.obj" : "torus." + ext)).string();
    ChildRun ours, peer;
    for (auto _ : state) {
        const ChildRun a = runChild({self_path, "--load-child", (dir / ("scene_" + ext + ".json")).string()});
        const ChildRun b = runChild({"gltfpack", "-i", peer_input, "-o", (dir / "peer_out.glb").string()});
        if (!a.ok || !b.ok) {
            state.SkipWithError(!a.ok ? "the load failed" : "gltfpack failed");
            return;
        }
        ours.seconds += a.seconds;
        peer.seconds += b.seconds;
        ours.peak_mib = std::max(ours.peak_mib, a.peak_mib);
        peer.peak_mib = std::max(peer.peak_mib, b.peak_mib);
    }
    const double k = double(state.iterations());
    state.counters["triangles"] = double(torusOf(n).triangles.size());
    state.counters["load_s"] = ours.seconds / k;
    state.counters["gltfpack_s"] = peer.seconds / k;
    state.counters["time_ratio"] = ours.seconds / peer.seconds;
    state.counters["load_peak_MiB"] = ours.peak_mib;
    state.counters["gltfpack_peak_MiB"] = peer.peak_mib;
    state.counters["peak_ratio"] = ours.peak_mib / peer.peak_mib;
}

// The torus of n triangles passing 10 ls in front of the camera at 0.9c, and its frame.
struct Passing {
    mesh4d::World4D world;
    mesh4d::ViewSurface view{mesh4d::ViewKind::PastCone, 0.0, {0, 0, 0}};
    apparent::ExportFrame frame;
};
const Passing& passing(long n) {
    static std::map<long, Passing> cache;
    auto it = cache.find(n);
    if (it != cache.end()) return it->second;
    Passing p;
    const mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0.0, {0, 0, -10}, {0.9, 0, 0});
    p.world = mesh4d::extrude(torusOf(n), m, -100, 100, false, false);
    p.frame.objects.push_back(mesh4d::sliceWorld(p.world, p.view, {}));
    return cache.emplace(n, std::move(p)).first->second;
}

void BM_Cut(benchmark::State& state) {
    const Passing& p = passing(state.range(0));
    for (auto _ : state) {
        const mesh4d::ApparentMesh m = mesh4d::sliceWorld(p.world, p.view, {});
        benchmark::DoNotOptimize(m.positions.data());
    }
    state.counters["triangles"] = double(p.world.mesh.triangles.size());
}

void write(benchmark::State& state, bool ply) {
    const Passing& p = passing(state.range(0));
    const fs::path dir = fs::temp_directory_path() / "apparent_load_bench_out";
    fs::create_directories(dir);
    for (auto _ : state) {
        std::string error;
        const bool ok = ply ? apparent::writePly((dir / "f.ply").string(), p.frame, apparent::SequenceInfo{}, &error)
                            : apparent::writeObj((dir / "f.obj").string(), p.frame, apparent::SequenceInfo{}, &error);
        if (!ok) state.SkipWithError(error.c_str());
    }
    state.counters["triangles"] = double(p.world.mesh.triangles.size());
    state.counters["bytes"] = double(fs::file_size(dir / (ply ? "f.ply" : "f.obj")));
    fs::remove_all(dir);
}
void BM_WritePly(benchmark::State& state) { write(state, true); }
// The PLY bytes alone, in memory (no file): what the writer costs before the kernel and the disk.
void BM_SerializePly(benchmark::State& state) {
    const Passing& p = passing(state.range(0));
    std::string bytes;
    for (auto _ : state) {
        apparent::serializePly(p.frame, apparent::SequenceInfo{}, &bytes);
        benchmark::DoNotOptimize(bytes.data());
    }
    state.counters["triangles"] = double(p.world.mesh.triangles.size());
}
void BM_WriteObj(benchmark::State& state) { write(state, false); }

}  // namespace

BENCHMARK(BM_LoadVsGltfpack)
    ->ArgsProduct({{0, 1, 2}, {1'000, 10'000, 100'000, 1'000'000}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK(BM_Cut)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WritePly)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SerializePly)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteObj)->Arg(1'000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
    self_path = fs::canonical("/proc/self/exe").string();
    if (argc == 3 && std::strcmp(argv[1], "--load-child") == 0) return loadChild(argv[2]);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
