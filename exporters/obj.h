// Per-frame OBJ: every object of the frame in one file, absolute lab positions written with 17
// significant digits (a double survives the text round trip exactly). The file opens with
// `# V vertices, F faces` and the comments of frameFileComments (exporters/frame_files.h: units,
// model, scene, camera time, `# object I NAME` per object), then per object in scene order one
// `o NAME` group (frameObjectName: one word; every object of the sequence, also one with nothing
// in the frame) holding its vertices and then its triangles (1-based indices into the whole
// file). Positions only: OBJ has no per-vertex scalar; the emission time is in the PLY and glTF
// outputs. Triangles with a repeated corner are left out.
#pragma once

#include <memory>
#include <string>

#include "exporters/frame_sink.h"

namespace apparent {

// The file's bytes for `frame` into `bytes` (the same bytes whatever the thread count).
void serializeObj(const ExportFrame& frame, const SequenceInfo& info, std::string* bytes);

// Writes `frame` of the sequence `info` to `path` through a temporary file; false with a message.
bool writeObj(const std::string& path, const ExportFrame& frame, const SequenceInfo& info, std::string* error);

// The OBJ sink: DIR/frame_NNNNN.obj per frame (exporters/frame_files.h); it reads no light factors.
std::unique_ptr<FrameSink> objSink(std::string dir);

}  // namespace apparent
