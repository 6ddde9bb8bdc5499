// The frame loop: for one model, the stage's 4D histories (pipeline/stage/worlds.h) and mirror
// reflections are built once, then frames [first, last_excl) are cut in parallel batches (TBB;
// objects of a frame in parallel too) and delivered to the sinks in frame order, so outputs are
// byte-identical for any thread count. Each sink gets begin(), then every frame, then finish()
// (exporters/frame_sink.h). Before each write the output budget (--max-output-bytes) is checked
// against the sink's least size, and after it against the real size of every completed file.
// Before the first write, the sinks' estimate of the first batch of frames, scaled to every frame
// and every model left, is checked against the budget too: a run that would pass it stops with
// nothing written. Progress (frames done, rate, time left) is shown on a terminal. The light
// factors (mesh4d/light_factors.h) are computed only when some sink reads them
// (FrameSink::readsLightFactors); otherwise every object's doppler and proper_time stay empty.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "exporters/frame_sink.h"
#include "pipeline/run/distribute.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

// Bytes written by a run, against --max-output-bytes: files already written stay complete,
// nothing is written past the limit. A limit of 0 is none.
class OutputBudget {
public:
    explicit OutputBudget(long long limit) : limit_(limit) {}
    // Before anything is written: false, with the one line that names the ways out (--tolerance,
    // --frames, --compress, --max-output-bytes), when `estimate` bytes for the whole run would pass
    // the limit. `measured` of `total` frames gave the estimate.
    bool fitsEstimate(double estimate, long long measured, long long total, std::string* error) const;
    // False, with the message, when `more` bytes beyond those written would pass the limit
    // (more = 0: the total already has).
    bool fits(long long more, const std::string& what, std::string* error) const;
    // Counts the size of the written file `path`; false (with the message) once over the limit.
    bool count(const std::string& path, std::string* error);
    long long written() const { return written_; }

private:
    long long limit_;
    long long written_ = 0;
};

struct FrameLoopSettings {
    int threads = 0;         // worker threads; 0: all cores
    // Triangles per frame: each object's refinement stops at this many
    // (mesh4d::SliceSettings::max_triangles) and a frame that reaches it, or holds more in all,
    // ends the loop with a message naming --tolerance and --max-triangles (bad input: exit 2).
    long long max_frame_triangles = kMinFrameTriangleBudget;
    bool cull_view = false;  // --cull-view: objects outside the camera's view stay empty (worlds.h)
    bool progress = true;    // on a terminal only
    // Models still to run with the same budget, this one included: the estimate made from the
    // first frames before writing (OutputBudget::fitsEstimate) counts them all.
    long long models_left = 1;
    // This process's part of the frames (pipeline/run/distribute.h): a job-array shard renders only
    // its part, and the output budget's estimate scales to the part's frames.
    FrameSplit split;
    // MPI: the frames of every rank of frameGroup() (`split` is then the rank's): rank r > 0 cuts
    // and encodes its part and sends it; rank 0 writes every frame in order into the sinks.
    bool distributed = false;
};

struct FrameLoopResult {
    size_t max_triangles = 0;            // the largest frame's triangle count
    size_t limited_triangles = 0;        // triangle-frames that reached the refinement limit
    size_t max_segments = 0;             // that limit
    std::vector<SinkSummary> summaries;  // per sink, in the order given
    bool over_budget = false;            // stopped at max_frame_triangles: the error is bad input
    // MPI: the exit code the group agreed on when the loop failed (rank r > 0 has no message then:
    // rank 0 prints it); 0 otherwise.
    int group_code = 0;
    // Where the time went (wall clock, seconds): cutting, converting and encoding the frames this
    // process cut, summed over its threads; writing (the sinks' add and finish, in order, one
    // thread; with MPI also rank 0 receiving and unpacking each frame of another rank once it has
    // come); with MPI, rank 0 waiting for frames of other ranks to come. render --verbose prints them.
    double cut_seconds = 0, write_seconds = 0, wait_seconds = 0, loop_seconds = 0;
    // The same as the CPU time of the threads that did it (not slowed by other processes sharing
    // the cores; a nested parallel loop's work stolen by another thread is not counted).
    double cut_cpu_seconds = 0, write_cpu_seconds = 0;
    // Of the writing, the sinks' finish (the .glb's assembly), wall clock and CPU.
    double finish_seconds = 0, finish_cpu_seconds = 0;
    // Of the writing, with MPI: rank 0's work on the frames of other ranks (receiving, unpacking,
    // the budget's checks, the sinks' addEncoded), wall clock and CPU, and how many such frames:
    // what rank 0 spends per frame it did not cut, the figure that bounds how many ranks help.
    double received_seconds = 0, received_cpu_seconds = 0;
    long long frames_cut = 0, frames_written = 0, frames_received = 0;
};

// Runs frames [stage.first, stage.last_excl) of `model` into `sinks` (in that order per frame).
// Returns false with one line (naming the file) when an output cannot be written or the budget is
// exhausted: the command's exit code 3; or when a frame passes max_frame_triangles
// (result->over_budget: exit code 2). Progress goes to `progress_out`.
bool runFrameLoop(const Stage& stage, Model model, const FrameLoopSettings& settings,
                  const std::vector<FrameSink*>& sinks, OutputBudget* budget, std::ostream& progress_out,
                  FrameLoopResult* result, std::string* error);

// runFrameLoop for the last model run from `stage`: when no mirror needs them, the objects' rest
// meshes are handed to the 4D worlds instead of copied (pipeline/stage/worlds.h takeWorlds; every
// stage->objects[i].rest is then left empty), so a large mesh is held once. Same outputs.
bool runLastFrameLoop(Stage* stage, Model model, const FrameLoopSettings& settings,
                      const std::vector<FrameSink*>& sinks, OutputBudget* budget, std::ostream& progress_out,
                      FrameLoopResult* result, std::string* error);

}  // namespace apparent
