// Per-vertex normals of an apparent mesh, for shading in viewers.
//
// creaseSplit: each corner of a triangle gets the normalised sum of the edge cross products (the
// area-weighted average of the face normals) of the faces around its vertex whose normals are
// within `crease_deg` of the corner's own face, with the
// vertex duplicated where corners disagree, so that sharp folds (the flange's 90-degree edge)
// shade flat on each side while curved apparent surfaces stay smooth. The apparent surface is
// oriented like the input (the cut keeps triangle orientation). A vertex whose triangles all have
// zero area gets +z rather than NaN: glTF requires unit normals.
#pragma once

#include <vector>

#include "slice.h"

namespace mesh4d {

struct CreasedMesh {
    ApparentMesh mesh;             // positions and emission times copied per split vertex
    std::vector<Vec3> normals;     // one unit normal per vertex of `mesh`
};

// Splits vertices along edges sharper than crease_deg (0 < crease_deg <= 180).
CreasedMesh creaseSplit(const ApparentMesh& mesh, double crease_deg);

}  // namespace mesh4d
