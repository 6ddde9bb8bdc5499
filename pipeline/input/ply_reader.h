// Stanford PLY meshes (ascii, binary little- and big-endian), read by our own single-pass scan
// into double positions and made into a mesh as OpenMesh's importer would
// (pipeline/input/polygon_input.h).
//
// A lenient reader trusts the header (sizing its arrays from the element counts) and drops faces
// with bad indices with a log line only. Our scan checks everything as it reads: the
// header (the `ply` magic, one `format` line, known property types, `element vertex` with scalar
// x, y and z, `element face` with a `vertex_indices` or `vertex_index` list), the element counts
// against the limits and against the file size (each row needs a minimum number of bytes, so a
// 200-byte file cannot ask for a billion vertices), then every row of the body (finite
// coordinates, face indices in range, faces of at least 3 vertices, no missing or trailing
// bytes in binary files). Errors are one line, "mesh.ply: field: problem", for example
// "mesh.ply: face[3].vertex_indices[2]: index 9 is out of range (8 vertices)". Faces with a
// repeated index are dropped and counted as degenerate, polygons triangulated (a fan) and counted.
// Other properties are skipped; an apparent PLY frame's per-vertex `object` index
// (exporters/ply.h) with a warning: the frame is read as one object.
#pragma once

#include <string>

#include "mesh4d/extrude.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/status.h"

namespace apparent {

// Reads a PLY file into a rest-frame triangle mesh (no transform applied).
Status readPly(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings);

}  // namespace apparent
