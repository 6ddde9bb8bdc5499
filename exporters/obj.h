// Per-frame OBJ, written by OpenMesh with 17 significant digits (positions only: OBJ has no
// per-vertex scalar; the emission time is in the PLY and glTF outputs).
#pragma once

#include <string>

#include "exporters/frame_mesh.h"

namespace apparent {

bool writeObj(const std::string& path, const ExportFrame& frame, std::string* error);

}  // namespace apparent
