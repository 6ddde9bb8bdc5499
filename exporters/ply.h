// Per-frame PLY for MeshLab: binary little-endian, every object of the frame in one file with
// absolute lab positions, each object's vertices and faces together in scene order. Vertex
// `x y z` are double (light-seconds, exact: an object far from the origin keeps its shape),
// followed by a double `quality` holding the emission time, so MeshLab's "Colorize by vertex
// quality" shows when each point emitted its light, `doppler` and `proper_time` (double) when the
// frame has them, and `object`, the vertex's object index in scene order (mirror reflections after
// the scene's objects): uchar when the sequence has at most 256 objects, ushort up to 65536, else
// int, so every frame of a sequence has the same header. Faces are `list uchar int
// vertex_indices`. The header's comments (`comment LINE`) are frameFileComments
// (exporters/frame_files.h): units, model, scene, camera time and each object's name
// (`comment object I NAME`). Triangles with a repeated corner are left out.
#pragma once

#include <memory>
#include <string>

#include "exporters/frame_sink.h"

namespace apparent {

// The file's bytes for `frame` into `bytes` (resized; its capacity is reused): serialized in
// parallel blocks (TBB), the same bytes whatever the thread count.
void serializePly(const ExportFrame& frame, const SequenceInfo& info, std::string* bytes);

// Writes `frame` of the sequence `info` to `path` through a temporary file. Returns false with a
// message on failure.
bool writePly(const std::string& path, const ExportFrame& frame, const SequenceInfo& info, std::string* error);

// The PLY sink: DIR/frame_NNNNN.ply per frame (exporters/frame_files.h).
std::unique_ptr<FrameSink> plySink(std::string dir);

}  // namespace apparent
