// Uniform subdivision of a rest mesh: what per-vertex engines do to make a moving mesh look
// curved (OpenRelativity's ObjectMeshDensity), and the peer the adaptive refinement is measured
// against (`apparent trade`, docs/ACCURACY.md).
//
// Each level splits every triangle 4-to-1 at its edge midpoints; a midpoint is made once per
// edge and shared by the edge's triangles, so a watertight mesh stays watertight. Level k has
// 4^k times the triangles. Midpoints are (a + b) / 2 of the rest points, in double.
#pragma once

#include "mesh4d/extrude.h"

namespace mesh4d {

RestMesh subdivideUniform(const RestMesh& mesh, int levels);

}  // namespace mesh4d
