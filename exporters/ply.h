// Per-frame PLY for MeshLab: binary little-endian, every object of the frame in one mesh with
// absolute lab positions. Vertex `x y z` are double (light-seconds, exact: an object far from the
// origin keeps its shape), followed by a double `quality` holding the emission time, so MeshLab's
// "Colorize by vertex quality" shows when each point emitted its light; faces are
// `list uchar int vertex_indices`. Triangles with a repeated corner are left out.
#pragma once

#include <memory>
#include <string>

#include "exporters/frame_sink.h"

namespace apparent {

// The file's bytes for `frame` into `bytes` (resized; its capacity is reused): serialized in
// parallel blocks (TBB), the same bytes whatever the thread count.
void serializePly(const ExportFrame& frame, std::string* bytes);

// Writes `frame` to `path` through a temporary file. Returns false with a message on failure.
bool writePly(const std::string& path, const ExportFrame& frame, std::string* error);

// The PLY sink: DIR/frame_NNNNN.ply per frame (exporters/frame_files.h).
std::unique_ptr<FrameSink> plySink(std::string dir);

}  // namespace apparent
