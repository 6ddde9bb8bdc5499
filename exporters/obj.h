// Per-frame OBJ: every object of the frame in one mesh, absolute lab positions written with 17
// significant digits (a double survives the text round trip exactly), then the triangles
// (1-based). Positions only: OBJ has no per-vertex scalar; the emission time is in the PLY and
// glTF outputs. Triangles with a repeated corner are left out.
#pragma once

#include <memory>
#include <string>

#include "exporters/frame_sink.h"

namespace apparent {

// The file's bytes for `frame` into `bytes` (the same bytes whatever the thread count).
void serializeObj(const ExportFrame& frame, std::string* bytes);

bool writeObj(const std::string& path, const ExportFrame& frame, std::string* error);

// The OBJ sink: DIR/frame_NNNNN.obj per frame (exporters/frame_files.h); it reads no light factors.
std::unique_ptr<FrameSink> objSink(std::string dir);

}  // namespace apparent
