// One frame cut into memory at any camera time, without sinks or files (the Python module,
// python/_apparent.cpp; issue 34). The frame loop (pipeline/run/frame_loop.h) cuts its frames with the
// same function, cutFrameAt, so a frame cut here at frameTime(k) holds the arrays the command's
// frame k holds, value for value.
#pragma once

#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "exporters/frame_mesh.h"
#include "pipeline/stage/mirror.h"
#include "pipeline/stage/stage.h"

namespace apparent {

// Triangles one frame may hold (objects and reflections together) unless --max-triangles says
// otherwise: 4 x the scene's input triangles (objects x (1 + mirrors); vertex mode's frame holds at
// most the input plus the pieces of clipped triangles, which this covers), and never less than
// kMinFrameTriangleBudget, so that refinement has room. The budget bounds memory: the frame loop
// holds at most threads + 1 frames, and a refined frame costs a few hundred bytes per
// output triangle at its peak (measured: `/usr/bin/time -f %M` on a budget-stopped run,
// docs/HOSTILE_INPUT.md), so a run the default budget stops on a small input stays under 500 MB on the
// 2-core machine those figures come from.
constexpr long long kMinFrameTriangleBudget = 500'000;
long long defaultFrameTriangleBudget(const Stage& stage);

// Freed memory the process keeps for its next allocations, bytes: a frame's buffers (tens of MB
// at 1M triangles) are reused in place frame after frame instead of unmapped and faulted in again
// zero-filled (glibc's defaults map a block that large on its own and trim a heap whose free top
// passes 128 kB; docs/PERFORMANCE.md, issue 37). More than this is given back, so one huge frame
// does not hold its memory for the program's life (the budget of the cut's RefineScratch).
constexpr int kFreedMemoryKeep = 256 << 20;
// Sets that policy for the whole process (glibc's mallopt; elsewhere nothing): the apparent command
// and the Python module call it once at start.
void keepFreedMemory();

// What the sinks are told about the sequence of `model`: objects (then the reflections, see
// MirrorReflections::describe), camera, fps, tolerance, scene file.
SequenceInfo sequenceInfo(const Stage& stage, Model model);

// The frame loop's per-frame step: every world cut with `view` (objects in parallel, each with its
// own tolerance from stage.tolerances; an object outside the camera's view left empty when
// `cull_view`), the light factors added when `light_factors`, then the mirrors' reflections
// appended. `frame->objects` is replaced; t_c and index are the caller's.
void cutFrameAt(const Stage& stage, const std::vector<mesh4d::World4D>& worlds, const MirrorReflections& reflections,
                const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings, bool cull_view,
                bool light_factors, ExportFrame* frame);

// The 4D worlds of one model built once over the stage's frame range [first, last_excl) (as the
// frame loop builds them), then cut at any finite camera time. A time outside that range's first
// and last frame times is cut from histories built for it alone, as the frame loop builds them for
// a scene whose frames are one frame at that time ({start: t, fps: the scene's}: frame 0 at t), after
// the checks loadStage applies to such a range (checkViewedTime, checkObjectMotion for the model;
// their lines name that frame 0); the last kSpansKept of those are kept, keyed by the time.
// cut() is const and may be called from several threads at once.
class FrameCutter {
public:
    static constexpr size_t kSpansKept = 8;

    // `stage` must outlive the cutter. Builds the worlds and the mirrors' reflections.
    FrameCutter(const Stage& stage, Model model);
    ~FrameCutter();

    // The frame at camera time t_c (seconds), with light factors, the per-frame triangle budget of
    // the frame loop (defaultFrameTriangleBudget unless max_frame_triangles > 0). False with one
    // line when t_c is not finite, when the histories for a time outside the range fail the
    // command's checks, or when the frame passes the budget.
    bool cut(double t_c, long long max_frame_triangles, ExportFrame* frame, std::string* error) const;

    // Names (objects, then the reflections) and colours, as the sinks are told.
    const SequenceInfo& info() const { return info_; }
    double firstTime() const { return t_first_; }
    double lastTime() const { return t_last_; }

private:
    struct Histories;  // the worlds and reflections over one span of camera times
    // The histories that cover t_c: the frame range's, or those built (or kept) for t_c alone.
    std::shared_ptr<const Histories> historiesFor(double t_c, std::string* error) const;

    const Stage& stage_;
    Model model_;
    std::shared_ptr<const Histories> range_;
    SequenceInfo info_;
    double t_first_ = 0, t_last_ = 0;
    mutable std::mutex mutex_;
    mutable std::deque<std::pair<double, std::shared_ptr<const Histories>>> spans_;  // newest last
};

}  // namespace apparent
