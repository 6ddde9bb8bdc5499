// Sinks that write one file per frame, DIR/frame_NNNNN.EXT (global frame numbers), holding every
// object of the frame in one mesh: the base of the PLY and OBJ sinks. begin() creates DIR; each
// frame's file is serialized in memory and committed through AtomicOutput, so it is complete when
// add() returns, and counts to the output budget at once.
// Frames across processes (pipeline/distribute.h): when the ranks share the output folder (their
// frame spills are installed, exporters/frame_spill.h) a rank writes its frame's file itself, in
// frame order just before sending the frame (beforeSending), to DIR/.frame_NNNNN.tmp-TOKEN.EXT
// (TOKEN: the run's random token; created exclusively, never through a link, synced), and sends
// only its size and inode, or the write's error. Rank 0 checks the budget as for its own frames and
// renames the file into place in frame order (addEncoded: the same bytes, messages and order as one
// process). Nothing is left behind: rank 0 registers for its interrupt cleanup the name of each
// rank's frame under way (expectEncoded: the next frame of a rank, from the receipt of its previous
// one; a rank writes one frame at a time) and of each one received and not yet renamed, and
// removes every such name of the sequence when the run fails (dropEncoded). A rank killed by
// SIGKILL while rank 0 lives leaves its frame under way to rank 0's cleanup when mpirun ends rank 0
// with SIGTERM. Rank 0 registers at most 16 such names per sink at once (the cleanup has 64 slots,
// shared with its own temporaries): from about 14 ranks on, a killed rank's frame under way may
// stay, as AtomicOutput's temporary does after SIGKILL (a hidden .tmp- name, never a final file).
// Without shared spills the bytes travel to rank 0, which commits them (addEncoded).
#pragma once

#include <map>
#include <string>

#include "exporters/frame_sink.h"

namespace apparent {

// Writes `frame` to `path` (through a temporary name); false with a message naming the file.
using FrameWriter = bool (*)(const std::string& path, const ExportFrame& frame, std::string* error);
// The file's bytes for `frame` (what FrameWriter writes): the frame as another process sends it.
using FrameSerializer = void (*)(const ExportFrame& frame, std::string* bytes);

class FrameFileSink final : public FrameSink {
public:
    FrameFileSink(std::string dir, std::string extension, FrameWriter write, FrameSerializer serialize);
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
    void expectEncoded(long long index) override;
    void dropEncoded(long long first, long long last_excl) override;
    ~FrameFileSink() override;

private:
    std::string path(long long k) const;
    std::string temporaryPath(long long k) const;  // a rank's file for frame k (shared spills only)
    int sent_slot_ = -1;                            // a rank: its last frame's name, for its interrupt cleanup
    std::map<long long, int> expected_;             // rank 0: frames of other ranks under way -> their slots
    std::string dir_, extension_;
    FrameWriter write_;
    FrameSerializer serialize_;
};

}  // namespace apparent
