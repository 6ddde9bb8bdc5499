// Wavefront OBJ meshes, read by our own single-pass scanner (std::from_chars, no iostreams) into
// double positions, made into a mesh as OpenMesh's importer would (pipeline/input/polygon_input.h).
//
// Everything a lenient reader would drop unannounced becomes either a one-line error naming the
// line (bad numbers, indices out of range, faces of fewer than 3 vertices) or a counted warning
// (degenerate faces with a repeated index). Polygons are triangulated as a fan about their first
// corner, counted as a warning. Only `v` and `f` lines are read (the first three numbers of a
// `v`, the position index of each `f` corner: "i", "i/t", "i//n", "i/t/n", negatives counting
// back); material libraries are never opened (`mtllib` lines are counted as ignored), other
// keywords skipped. Coordinates must lie within float range (|x| <= 3e38), since every export
// is float32.
#pragma once

#include <string>
#include <vector>

#include "mesh4d/extrude.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/status.h"

namespace apparent {

// Reads an OBJ file into a rest-frame triangle mesh (no transform applied).
Status readObj(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings);

}  // namespace apparent
