// Wavefront OBJ meshes, read with OpenMesh and converted to our types.
//
// OpenMesh's reader is lenient: it silently skips faces with out-of-range or repeated indices and
// vertices with unparsable coordinates. So the file is first scanned line by line, and anything
// OpenMesh would drop unannounced becomes either a one-line error naming the line (bad numbers,
// indices out of range, faces of fewer than 3 vertices) or a counted warning (degenerate faces
// with a repeated index). Polygons are triangulated by OpenMesh (a fan), counted as a warning.
// Limit: OpenMesh's OBJ reader parses coordinates as float, so rest-frame positions carry a
// relative rounding of about 6e-8 of their magnitude; everything after the read is double.
#pragma once

#include <string>
#include <vector>

#include "mesh4d/extrude.h"
#include "pipeline/mesh_input.h"
#include "pipeline/status.h"

namespace apparent {

// Reads an OBJ file into a rest-frame triangle mesh (no transform applied).
Status readObj(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings);

}  // namespace apparent
