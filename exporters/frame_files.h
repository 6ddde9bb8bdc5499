// Sinks that write one file per frame, DIR/frame_NNNNN.EXT (global frame numbers), holding every
// object of the frame, each object's vertices and faces together in scene order (the PLY's
// per-vertex `object` index, the OBJ's `o` groups): the base of the PLY and OBJ sinks. begin() creates DIR; each
// frame's file is serialized in memory and committed through AtomicOutput, so it is complete when
// add() returns, and counts to the output budget at once.
// Frames across processes (pipeline/run/distribute.h): when the ranks share the output folder (their
// frame spills are installed, exporters/frame_spill.h) a rank writes its frame's file itself, in
// frame order just before sending the frame (beforeSending), to DIR/.frame_NNNNN.tmp-TOKEN.EXT
// (TOKEN: the run's random token; created exclusively, never through a link, synced), and sends
// only its size and inode, or the write's error. Rank 0 checks the budget as for its own frames and
// renames the file into place in frame order (addEncoded: the same bytes, messages and order as one
// process). Nothing is left behind: every rank registers every model's frame folder before any
// rank writes a file there (removeFrameTemporariesOnInterrupt, from pipeline/run/distribute.cpp's
// shareFrameSpills): on SIGINT, SIGTERM or SIGHUP a rank removes every temporary of the run there
// by its name's pattern, whichever rank made it and however many ranks there are. A rank killed by
// SIGKILL (the OOM killer) leaves its frame under way to the others, which mpirun then ends with
// SIGTERM (also the first frame of the next model, `--model all`, made before rank 0 is done with
// the model before). When the run fails, rank 0 removes every such name of the sequence after the
// other ranks stopped sending (dropEncoded). Bounds: Open MPI 4.1's mpirun sent its SIGKILL 3 ms
// after its SIGTERM here (strace; odls_base_sigkill_timeout 1 s notwithstanding), so the removal
// needs one rank, any, to run its handler in that time (24 runs of 3 and of 20 ranks on 2 cores
// left no temporary; tests/mpi/mpi_test.sh; with rank 0 alone removing, 20 ranks left some in 5
// runs of 6); a launcher that waits (Slurm's KillWait, 30 s by default) leaves time enough. Every rank killed at once by SIGKILL can
// leave the temporaries of frames under way, as AtomicOutput leaves its own (hidden .tmp- names,
// never a final file).
// Without shared spills the bytes travel to rank 0, which commits them (addEncoded).
#pragma once

#include <string>
#include <map>
#include <memory>
#include <vector>

#include "exporters/frame_sink.h"

namespace apparent {

class AtomicOutput;

// The file's bytes for `frame` of the sequence `info` (the frame as another process sends it, too).
using FrameSerializer = void (*)(const ExportFrame& frame, const SequenceInfo& info, std::string* bytes);

// Writes `bytes` whole to `out`'s temporary file (writeWhole: past the page cache when large, else
// buffered after its blocks are reserved) and fsyncs it, every call checked; not committed. False
// with a message naming the final path.
bool writeUncommitted(AtomicOutput* out, const std::string& bytes, std::string* error);

// Writes `frame` to `path` through a temporary name: serialize, writeUncommitted, commit.
bool writeFrameFile(FrameSerializer serialize, const std::string& path, const ExportFrame& frame,
                    const SequenceInfo& info, std::string* error);

// The shortest decimal that reads back as `value`, in std::to_chars's plain form (fixed or
// scientific, whichever is shorter, fixed on a tie; "1e-05", "0.1", "100000"): std::to_chars where
// the standard library has it for doubles, else shortestDecimalByPrintf (the WebAssembly build's
// libc++), which gives the same text (tests/frame_files_test.cpp compares them).
std::string shortestDecimal(double value);
std::string shortestDecimalByPrintf(double value);

// What both frame files say of their frame, one line each without the line break, in this order:
// "units: U" (when the frame's units are not light-seconds), "model: M" and "scene: PATH" (when
// the sequence names them), "camera_time: T" (the frame's t_c in seconds, the shortest decimal that
// reads back as the same double), then "object I NAME" for every object I of the sequence
// (frameObjectCount) in scene order. The PLY writes each as `comment LINE`, the OBJ as `# LINE`.
// Control characters in the scene's path become '_' (one line each).
std::vector<std::string> frameFileComments(const ExportFrame& frame, const SequenceInfo& info);

// The objects of a sequence as the frame files count them: the sequence's (info.objects, mirror
// reflections included) or, when a frame holds more (a frame written without its sequence), the
// frame's. Every frame of a sequence has the same count.
size_t frameObjectCount(const ExportFrame& frame, const SequenceInfo& info);

// Object `i`'s name as the frame files write it: whitespace and control characters become '_'
// (an OBJ `o` name is one word); an empty or missing name becomes "object_I".
std::string frameObjectName(const SequenceInfo& info, size_t i);

class FrameFileSink final : public FrameSink {
public:
    // `light_factors`: whether `write` reads the frames' light factors (FrameSink::readsLightFactors).
    FrameFileSink(std::string dir, std::string extension, FrameSerializer serialize, bool light_factors = true);
    bool begin(const SequenceInfo& info, std::string* error) override;
    PendingOutput pending(const ExportFrame& frame) override;
    long long estimate(const ExportFrame& frame) const override { return leastFrameBytes(frame); }
    bool add(const ExportFrame& frame, const PreparedFrame* prepared, std::vector<std::string>* completed,
             std::string* error) override;
    bool finish(SinkSummary* summary, std::string* error) override;
    // Another process's frame: the file's bytes, committed here under the frame's name.
    EncodedOutput encode(const ExportFrame& frame, const PreparedFrame* prepared) const override;
    PendingOutput pendingEncoded(long long index, const EncodedOutput& frame) override;
    bool addEncoded(long long index, const EncodedOutput& frame, std::vector<std::string>* completed,
                    std::string* error) override;
    bool beginEncoding(const SequenceInfo& info, std::string* error) override;
    void beforeSending(long long index, EncodedOutput* frame) override;
    void dropEncoded(long long first, long long last_excl) override;
    bool readsLightFactors() const override { return light_factors_; }
    bool readsRestPoints() const override { return false; }  // PLY and OBJ write neither
    bool canHoldCommits() const override { return true; }
    void holdCommits(bool on) override;
    bool commitHeld(long long index, std::vector<std::string>* completed, std::string* error) override;
    ~FrameFileSink() override;

private:
    std::string path(long long k) const;
    std::string temporaryPath(long long k) const;  // a rank's file for frame k (shared spills only)
    int sent_slot_ = -1;                            // a rank: its last frame's name, for its interrupt cleanup
    std::string dir_, extension_;
    SequenceInfo info_;  // the sequence's, from begin() or beginEncoding()
    FrameSerializer serialize_;
    bool light_factors_;
    std::string bytes_;  // a frame file's bytes, kept between frames (no reallocation while they do not grow)
    bool holding_ = false;
    std::map<long long, std::unique_ptr<AtomicOutput>> held_;  // written, not yet committed
};

// Each rank of a run whose ranks write frame files (above): from now on an interrupt (SIGINT,
// SIGTERM, SIGHUP) removes, before exporters/atomic_file.h's cleanup runs, every file named
// ".frame_*.tmp-TOKEN.*" in each of `folders` (TOKEN: `token`, the run's frameRunToken()). To be
// called before any rank can write such a file; a later call replaces the folders. At most 8
// folders (one per model), each path under 4096 bytes: false, and nothing registered, beyond. The
// handlers run before the ones installed before (installInterruptCleanup's); a signal ignored
// stays ignored, one left to its default action takes it after the removal.
bool removeFrameTemporariesOnInterrupt(const std::string& token, const std::vector<std::string>& folders);

// Test hook of tests/mpi/mpi_test.sh: when the environment variable APPARENT_KILL_AFTER_WRITING
// names a frame file's final path, the rank that writes that frame (beforeSending) sends itself
// SIGKILL once the file's temporary is written and closed, before sending: a rank killed with its
// frame under way, at a frame the test chooses.
constexpr const char* kKillAfterWritingVariable = "APPARENT_KILL_AFTER_WRITING";

}  // namespace apparent
