// Per-vertex normals of an apparent mesh, for shading in viewers.
//
// Each vertex gets the normalised sum of the cross products of its triangles' edges, which is
// the area-weighted average of the face normals (geometry-central's "area-weighted" vertex
// normal). The apparent surface is oriented like the input (the cut keeps triangle orientation).
// A vertex whose triangles all have zero area gets (0, 0, 1) rather than NaN: glTF requires unit normals.
#pragma once

#include <vector>

#include "slice.h"

namespace mesh4d {

// Returns one unit normal per position (or +z where undefined).
std::vector<Vec3> vertexNormals(const ApparentMesh& mesh);

}  // namespace mesh4d
