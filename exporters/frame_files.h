// Sinks that write one file per frame, DIR/frame_NNNNN.EXT (global frame numbers), holding every
// object of the frame in one mesh: the base of the PLY and OBJ sinks. begin() creates DIR; each
// frame's file is serialized in memory and committed through AtomicOutput, so it is complete when
// add() returns, and counts to the output budget at once.
#pragma once

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

private:
    std::string path(long long k) const;
    std::string dir_, extension_;
    FrameWriter write_;
    FrameSerializer serialize_;
};

}  // namespace apparent
