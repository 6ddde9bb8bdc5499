// Where the frames of a sequence go: one sink per output format (.glb, PLY, OBJ; CONTRIBUTING.md "Adding a
// format"). The frame loop (pipeline/run/frame_loop.h) calls, for one model:
//   begin(info)                 once, before any frame;
//   prepare(frame)              on worker threads, several frames at once (optional conversion);
//   pending(frame), add(...)   on one thread, frames in order;
//   finish(...)                 once, after the last frame.
// Frames made by another process (pipeline/run/distribute.h: MPI ranks, job-array shards) reach the
// sink as bytes instead: beginEncoding(info) and encode(frame) where the frame was cut, then
// pendingEncoded(...) and addEncoded(...) in frame order where the file is written, with the same
// bytes in the file as add() would have written.
// Every method that writes returns false with one line naming the file on failure (the command
// exits with code 3). Sinks write through AtomicOutput (exporters/atomic_file.h): a file appears
// whole under its final name or not at all. The output budget (--max-output-bytes) is the loop's:
// a sink only states the least size of what it is about to write and names the files it completed.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "exporters/frame_mesh.h"

namespace apparent {

// A sink's conversion of one frame, made by prepare() on any thread (opaque to the loop).
struct PreparedFrame {
    virtual ~PreparedFrame() = default;
};

// What a sink reports when the sequence is done.
struct SinkSummary {
    std::vector<std::string> completed;  // files written by finish() (their sizes count to the budget)
    std::string text;                    // appended to the model's summary line, e.g. ", out/m.glb (1.2 MiB)"
    std::vector<std::string> warnings;   // one line each, without "warning: "
};

// The least size of what a sink holds unwritten, and the name the budget's message gives it.
struct PendingOutput {
    long long bytes = 0;
    std::string name;
};

// One frame as a sink's add() needs it, made where the frame was cut (FrameSink::encode): the
// bytes, the least size the frame adds (as pending() counts it) and the estimate() of the frame.
struct EncodedOutput {
    long long least = 0;
    long long estimate = 0;
    std::string bytes;
};

class FrameSink {
public:
    virtual ~FrameSink() = default;
    // Before the first frame: what the sequence is (objects, camera, model).
    virtual bool begin(const SequenceInfo& info, std::string* error) = 0;
    // The costly, order-independent part of taking `frame` (may run concurrently; const). The
    // default prepares nothing.
    virtual std::shared_ptr<const PreparedFrame> prepare(const ExportFrame& /*frame*/) const { return nullptr; }
    // What taking `frame` will add to the output before any of it is reported as completed: at
    // least `bytes` in all under `name` (called once per frame, just before add()).
    virtual PendingOutput pending(const ExportFrame& frame) = 0;
    // About how many bytes taking `frame` would add to the outputs, for the estimate the loop makes
    // from the first frames before anything is written (no side effects; 0: not known, the default).
    virtual long long estimate(const ExportFrame& /*frame*/) const { return 0; }
    // Takes `frame` (frames in order; `prepared` is prepare(frame), possibly null). Files it
    // completed are appended to `completed`.
    virtual bool add(const ExportFrame& frame, const PreparedFrame* prepared, std::vector<std::string>* completed,
                     std::string* error) = 0;
    // After the last frame.
    virtual bool finish(SinkSummary* summary, std::string* error) = 0;
    // Whether `bytes` more under `name` still fit the output limit (false with the message).
    using OutputCheck = std::function<bool(long long bytes, const std::string& name, std::string* error)>;
    // Set before finish(): a sink that writes a file there checks its whole size with `check`
    // before writing any of it (the default writes nothing in finish()).
    virtual void setFinishCheck(OutputCheck /*check*/) {}
    // Whether this sink reads the frames' light factors (ApparentMesh::doppler and proper_time,
    // mesh4d/light_factors.h): the loop computes them only when some sink does. The default: yes,
    // so a sink that does not say stays correct.
    virtual bool readsLightFactors() const { return true; }
    // Whether this sink reads the frames' rest points and source triangles (ApparentMesh::rest_points
    // and source_triangles) after prepare(): when none does, the loop releases them from a frame
    // once prepared, so the frames it holds at once (the first ones, for the output estimate) do
    // not keep them. The default: yes.
    virtual bool readsRestPoints() const { return true; }
    // Frames taken before the loop has estimated the output's size (the first few, for
    // --max-output-bytes: nothing may appear under a final name before the estimate fits). While
    // holdCommits(true), add() writes the files it would complete but leaves them under their
    // temporary names and reports none; commitHeld(index) renames frame `index`'s into place and
    // names them in `completed`; holdCommits(false) ends that and removes what was never committed.
    // Whether the sink can (a sink whose files appear only in finish() has nothing to hold); the
    // default: no, and the loop then keeps those frames whole in memory until the estimate.
    virtual bool canHoldCommits() const { return false; }
    virtual void holdCommits(bool /*on*/) {}
    virtual bool commitHeld(long long /*index*/, std::vector<std::string>* /*completed*/, std::string* /*error*/) {
        return true;
    }

    // Frames across processes. On the process that cuts frames without writing: what begin() sets
    // up for prepare() and encode(), nothing written (the default: nothing).
    virtual bool beginEncoding(const SequenceInfo& /*info*/, std::string* /*error*/) { return true; }
    // The frame as the writing process's addEncoded() needs it (const, any thread). The default
    // encodes nothing: a sink that cannot take frames from another process (addEncoded fails).
    virtual EncodedOutput encode(const ExportFrame& frame, const PreparedFrame* prepared) const;
    // Whether the encoding of frame k needs frame k - 1 (the .glb's morph targets by reference):
    // the loop then cuts frame k - 1 again where it cuts frame k (k > the sequence's first frame;
    // not when frame k - 1 is over the triangle budget) and calls encodeAfter() with it instead of
    // encode(). The default: no; encodeAfter() is then encode().
    virtual bool encodesAfterPrevious() const { return false; }
    virtual EncodedOutput encodeAfter(const ExportFrame& frame, const PreparedFrame* prepared,
                                      const ExportFrame* /*previous*/) const {
        return encode(frame, prepared);
    }
    // pending() and add() of a frame that arrives encoded: frame `index`, in order.
    virtual PendingOutput pendingEncoded(long long index, const EncodedOutput& frame);
    virtual bool addEncoded(long long index, const EncodedOutput& frame, std::vector<std::string>* completed,
                            std::string* error);
    // Files a process writes for the writing process (FrameFileSink under MPI). On the process that
    // cut frame `index`, in frame order just before the frame is sent: the sink may write it where
    // the writing process finds it, leaving a description in `frame` (the default: nothing).
    virtual void beforeSending(long long /*index*/, EncodedOutput* /*frame*/) {}
    // On the writing process when the loop ends without finishing, after every other process
    // stopped sending: whatever they wrote for frames [first, last_excl) and was not taken goes.
    virtual void dropEncoded(long long /*first*/, long long /*last_excl*/) {}
};

// The least size of a frame in any of the formats: 12 bytes per vertex and 12 per triangle
// (three float32 or uint32 each), the figure the budget checks before writing.
long long leastFrameBytes(const ExportFrame& frame);

}  // namespace apparent
