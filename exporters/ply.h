// Per-frame PLY for MeshLab: binary little-endian, written by OpenMesh, vertex x y z (float, as
// OpenMesh writes them) plus a per-vertex double property `quality` holding the emission time,
// so MeshLab's "Colorize by vertex quality" shows when each point emitted its light.
#pragma once

#include <string>

#include "exporters/frame_mesh.h"

namespace apparent {

// Writes `frame` to `path` through a temporary file. Returns false with a message on failure.
bool writePly(const std::string& path, const ExportFrame& frame, std::string* error);

}  // namespace apparent
