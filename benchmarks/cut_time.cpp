// The native cut of frames timed as benchmarks/wasm_cut.mjs times the WebAssembly module's
// (benchmarks/wasm_cut.sh): cut_time SCENE TOLERANCE N prints "native MEDIAN_MS MIN_MS TRIANGLES":
// N cuts at the scene's frame times (spread over its range, after one cut to build the histories),
// each timed alone, on one thread.
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/stage.h"

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: cut_time SCENE TOLERANCE N   (TOLERANCE '' : the scene's)\n");
        return 2;
    }
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    apparent::keepFreedMemory();  // as the apparent command (the WebAssembly module never gives memory back)
    apparent::StageOptions options;
    options.scene_path = argv[1];
    options.quiet = true;
    options.limits.allow_outside = true;
    const std::string tolerance = argv[2];
    if (!tolerance.empty()) {
        if (!apparent::parseTolerance(tolerance, &options.tolerance, &options.tolerance_relative)) return 2;
        options.has_tolerance = true;
    }
    apparent::Stage stage;
    std::ostringstream log;
    std::string error;
    if (!apparent::loadStage(options, &stage, log, &error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 2;
    }
    apparent::FrameCutter cutter(stage, stage.models.front());
    const long long n = std::atoll(argv[3]), frames = apparent::frameCount(stage.scene.frames);
    std::vector<double> ms;
    size_t triangles = 0;
    for (long long i = -1; i < n; ++i) {
        const long long k = i < 0 ? 0 : (i * frames) / n;
        apparent::ExportFrame frame;
        const auto start = std::chrono::steady_clock::now();
        if (!cutter.cut(apparent::frameTime(stage.scene.frames, k), 0, &frame, &error)) {
            std::fprintf(stderr, "%s\n", error.c_str());
            return 2;
        }
        const double elapsed = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (i >= 0) ms.push_back(elapsed);
        triangles = 0;
        for (const auto& o : frame.objects)
            for (const auto& t : o.triangles) triangles += t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    }
    std::sort(ms.begin(), ms.end());
    std::printf("native %.3f %.3f %zu\n", ms[ms.size() / 2], ms[0], triangles);
    return 0;
}
