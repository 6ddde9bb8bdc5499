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

// The same split as a map, without copying the mesh's points: split vertex k is input vertex
// source[k] with unit normal normals[k]; triangles index split vertices. Fills `out` reusing its
// capacity and `work`'s (scratch kept between calls, so a sequence of frames does not allocate
// again). Faces and vertices are processed in parallel (TBB); the result does not depend on the
// thread count, and creaseSplit gives the same vertices, normals and triangles bit for bit.
// Called again with the same `out` and `work` on a mesh with the same triangles (a vertex-mode
// sequence), it reuses the vertex-face adjacency, and when no vertex is split then or now, also
// `out`'s numbering: only the normals are computed again.
struct CreaseMap {
    std::vector<uint32_t> source;
    std::vector<Vec3> normals;
    std::vector<std::array<uint32_t, 3>> triangles;
};
struct CreaseWork {
    std::vector<Vec3> area;  // per face: edge cross product (twice the area vector)
    std::vector<Vec3> vertex_normal;
    std::vector<uint32_t> start, faces, fill, first_copy, next_copy;
    std::vector<unsigned char> uniform;
    std::vector<std::array<uint32_t, 3>> triangles;  // the last call's triangles (adjacency reuse)
    size_t vertices = 0;                              // the last call's vertex count
    bool unsplit = false;                             // the last call split no vertex
};
void creaseSplitMap(const ApparentMesh& mesh, double crease_deg, CreaseMap* out, CreaseWork* work);

}  // namespace mesh4d
