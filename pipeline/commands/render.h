// `apparent render`: options in, the stage (pipeline/stage/stage.h), for each model the frame loop
// (pipeline/run/frame_loop.h) into one sink per output format (exporters/frame_sink.h), then the
// summary. Exit codes: 0 success, 2 bad input or usage, 3 output could not be written.
// Under mpirun (frameGroup() of more than one rank) the ranks share the frames and rank 0 writes
// (pipeline/run/distribute.h); with --shard I/N it renders one job-array shard (pipeline/run/shards.h).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "exporters/gltf.h"
#include "pipeline/run/distribute.h"
#include "pipeline/run/frame_loop.h"
#include "pipeline/stage/stage.h"

namespace apparent {

// The default output budget: 2 GiB on disk.
constexpr long long kDefaultMaxOutputBytes = 2LL << 30;

struct RenderSettings {
    StageOptions stage;                // scene, --model, --tolerance, --frames, limits
    std::string out_dir = "out";
    std::vector<std::string> formats = {"glb"};  // --format: names from outputFormats()
    GlbOptions glb;                    // --draco, --draco-bits
    int threads = 0;                   // --threads; 0: all cores
    bool cull_view = false;            // --cull-view: leave objects outside the camera's view empty
    bool quiet = false;
    bool verbose = false;
    // --max-output-bytes: all files of the run together (0: no limit); checked first against an
    // estimate from the first frames, before anything is written.
    long long max_output_bytes = kDefaultMaxOutputBytes;
    long long max_frame_triangles = 0;  // --max-triangles: per frame; 0: defaultFrameTriangleBudget
    // --shard I/N: render part I of N of the frames into DIR/shards (pipeline/run/shards.h).
    bool sharded = false;
    FrameSplit shard;
};

// The names --format accepts, in the order their sinks take each frame: "ply", "obj", "glb".
const std::vector<std::string>& outputFormats();

int render(const RenderSettings& settings, std::ostream& log, std::ostream& err);

}  // namespace apparent
