// Frames across processes: how the frames of a sequence are split between processes, and how a
// frame cut on one process reaches the process that writes the files. Two users:
// - job-array shards (`render --shard I/N`, pipeline/run/shards.h): N independent processes, each
//   renders its part of the frames; `apparent merge` assembles the .glb afterwards;
// - MPI (`mpirun -n N apparent render ...`, pipeline/run/mpi_group.cpp): rank r cuts and encodes its
//   part, rank 0 writes every output in frame order (the .glb's frame data by reference when the
//   ranks share the output folder: shareFrameSpills below).
// The split is interleaved: frame k (of frames [first, last)) belongs to part (k - first) mod N.
// Neighbouring frames cost about the same (the scene changes smoothly), so every part gets an
// even share of the work whatever the cost profile along the sequence, and rank 0 receives frames
// in the order the ranks make them (no part runs far ahead of the writer).
//
// The MPI protocol (FrameGroup below, one exchange per model's frame loop), rank r > 0:
//   for each of its frames, in order: FRAME (the EncodedFrame as parts: its header, then each
//   sink's bytes; a synchronous send, so a rank holds at most its frame loop's tokens of frames:
//   bounded memory; up to 1 MiB in all, as frames by reference and files written by their ranks
//   are, one message, larger ones their parts' sizes and then each part), or, when it fails, ERROR (exit code and
//   the one-line message) instead, and no more frames; before each frame it checks for END from
//   rank 0 and stops sending when it came; then DONE; then it waits for END(code).
// Rank 0 receives the frames in frame order from their ranks (one at a time: bounded memory) and
// writes them; at the end (the files committed), or as soon as it fails or receives an ERROR, it
// sends END(code) to every rank and then drains each rank's messages up to its DONE (which
// unblocks a rank stuck in a send). Each part of a frame is received straight into the string
// that keeps it (a sink's bytes are moved, never copied, into the EncodedFrame).
// PLY and OBJ frames with shareFrameSpills: the rank writes the frame's file under a temporary name
// just before sending it, the FRAME holds its size (exporters/frame_files.h), rank 0 renames it.
// Frames by reference (shareFrameSpills below, the .glb): a FRAME then holds the frame's
// description, its data being in the sending rank's frame spill; when rank 0 assembles the .glb it
// sends each rank concerned PLACE (the temporary file's name and where each of the rank's ranges
// goes), which the rank, between its DONE and END, answers with PLACED (its status) after copying
// them in.
// Every rank then leaves the loop with rank 0's code; rank 0 alone prints the message, after its
// sinks removed their temporary files. A rank that dies (a signal, the OOM killer) is mpirun's to
// handle: it ends the job; files are committed by rename only, so none is left truncated.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "exporters/frame_sink.h"
#include "exporters/frame_spill.h"

namespace apparent {

// Part `part` of `parts` (0 <= part < parts) of the frames.
struct FrameSplit {
    int part = 0;
    int parts = 1;
    // Whether frame k of a sequence starting at `first` is this part's.
    bool owns(long long k, long long first) const { return (k - first) % parts == part; }
    // The part frame k belongs to.
    int partOf(long long k, long long first) const { return int((k - first) % parts); }
    // How many of frames [first, last_excl) are this part's.
    long long count(long long first, long long last_excl) const {
        const long long n = last_excl - first;
        return n / parts + (part < n % parts ? 1 : 0);
    }
};

// One frame as it travels: its number, what the frame loop's checks need (triangle counts, the
// per-frame budget) and each sink's encoding (FrameSink::encode), in the loop's sink order.
struct EncodedFrame {
    long long index = 0;
    uint64_t triangles = 0;          // ExportFrame::triangleCount()
    uint64_t limited_triangles = 0;  // summed over objects
    bool over_budget = false;                  // past --max-triangles: no sink data
    std::vector<EncodedOutput> sinks;
};

// The frame as the parts of one message: part 0 its header (number, triangle counts, budget flag,
// each sink's least and estimate and the size of its bytes), then each sink's bytes, viewed.
std::string frameHeader(const EncodedFrame& frame);
std::vector<std::string_view> frameParts(const EncodedFrame& frame, const std::string& header);
// And back: the sinks' bytes moved out of `parts` (false when they are not such parts: a message then).
bool frameFromParts(std::vector<std::string>* parts, EncodedFrame* frame, std::string* error);

// The processes of one run and the messages between them (MPI). The single-process group is
// the default; main() installs the MPI group when the program runs under mpirun or srun.
class FrameGroup {
public:
    virtual ~FrameGroup() = default;
    virtual int rank() const { return 0; }
    virtual int size() const { return 1; }
    // Every rank calls it with its own status (code 0: fine): returns the code of the lowest rank
    // that failed, and on rank 0 its message in `error` (the failing rank's own line), else 0.
    virtual int agree(int code, std::string* error) { (void)error; return code; }
    // Every rank calls it: rank 0's `text`, on every rank.
    virtual std::string broadcast(const std::string& text) { return text; }

    // The frame protocol above. Rank r > 0:
    virtual bool stopRequested() { return false; }             // END has come
    virtual void sendParts(const std::vector<std::string_view>& /*parts*/) {}
    void sendFrame(const std::string& bytes) { sendParts({std::string_view(bytes)}); }  // one part
    virtual void sendError(int /*code*/, const std::string& /*message*/) {}
    virtual int finishSending() { return 0; }                   // DONE, then END's code
    // Rank 0: waits until rank `from`'s next message has come, without receiving it (the loop
    // tells its wait for a frame from its work on the frame, render --verbose).
    virtual void awaitFrame(int /*from*/) {}
    // Rank 0: the next frame from rank `from`: its parts, or false with the rank's code and message.
    virtual bool receiveParts(int /*from*/, std::vector<std::string>* /*parts*/, int* /*code*/, std::string* /*error*/) {
        return false;
    }
    // The same for a frame sent by sendFrame (one part).
    bool receiveFrame(int from, std::string* bytes, int* code, std::string* error);
    virtual void endFrames(int /*code*/) {}                     // END(code) to all, then up to every DONE
    // Rank 0, frames by reference (exporters/frame_spill.h): each rank copies the placements from
    // its own spill into the file at `path` (PLACE to every rank concerned, while it waits for END
    // after DONE; rank 0's own at the same time), and answers PLACED with its status. False with
    // the first failing rank's message.
    virtual bool placeOnRanks(const std::string& path, const std::vector<Placement>& placements, std::string* error) {
        return placeHere(path, placements, error);
    }
};

// Frames by reference (exporters/frame_spill.h), set up once per run before the frame loops: every
// rank creates its frame spill in `dir` (".apparent-frames-TOKEN.RANK", TOKEN random, broadcast by
// rank 0, then frameRunToken()), rank 0 opens every rank's file by name and then unlinks every
// name, so that nothing is left behind from here on whatever ends the job. True on every rank when every spill is in place:
// a rank's .glb frames then travel as descriptions, their data written by the rank that cut them
// and, when rank 0 assembles the file, copied into it by that rank (placeOnRanks, installed here
// as rank 0's frame placer); its PLY and OBJ files are written by the rank, renamed by rank 0.
// False on every rank, the reason in `why` on rank 0, when a rank cannot create its file or rank 0
// cannot see it (the folder is not on a file system every rank shares): the frames then travel
// whole, as to a writer without spills. `frame_folders`: every folder the ranks may write PLY or
// OBJ frames into (one per model), registered on every rank before any rank can (an interrupt of
// any rank removes every rank's frame under way: removeFrameTemporariesOnInterrupt,
// exporters/frame_files.h).
// Collective.
bool shareFrameSpills(const std::string& dir, const std::vector<std::string>& frame_folders, std::string* why);

// The group of this process (single until setFrameGroup installs another).
FrameGroup& frameGroup();
void setFrameGroup(std::unique_ptr<FrameGroup> group);

}  // namespace apparent
