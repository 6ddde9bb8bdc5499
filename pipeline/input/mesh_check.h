// Mesh checks backed by CGAL's exact predicates and polygon-mesh processing: degenerate triangles
// and the topology of input and output meshes (closed, manifold, genus). CGAL is confined to
// mesh_check.cpp because it is slow to compile.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesh4d/event.h"
#include "mesh4d/extrude.h"

namespace apparent {

// Removes triangles whose three corners are exactly collinear (CGAL::collinear, exact predicate)
// and returns how many were removed; `per_triangle` (one value per triangle), when given, follows.
size_t dropDegenerateTriangles(mesh4d::RestMesh* mesh, std::vector<int>* per_triangle = nullptr);

struct Topology {
    bool manifold = false;       // the triangles form an oriented 2-manifold (with or without boundary)
    bool closed = false;         // manifold and without boundary
    size_t vertices = 0;         // vertices referenced by the triangles
    size_t edges = 0;
    size_t faces = 0;
    size_t components = 0;
    size_t boundary_loops = 0;
    long euler = 0;              // V - E + F
    long genus = -1;             // for closed manifolds: (2 components - euler) / 2, else -1
};

// Topology of an indexed triangle mesh (indices into `positions`).
Topology analyzeTopology(const std::vector<mesh4d::Vec3>& positions,
                         const std::vector<std::array<uint32_t, 3>>& triangles);

}  // namespace apparent
