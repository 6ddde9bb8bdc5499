// Triangulation of a refined triangle's parameter domain, with a given number of segments on
// each edge and a regular interior grid: the pattern GPU tessellators use (an inner regular
// lattice, and a ring joined to each edge's own points by a zipper), written for doubles.
//
// Domain: the triangle (0,0), (1,0), (0,1) in (u, v) = barycentrics of corners 1 and 2. Edge c runs
// from corner c to corner c + 1 and is split into n[c] equal segments. The interior holds the
// lattice points (i/N, j/N) with i, j >= 1 and i + j <= N - 1 (N >= 3). The ring between the
// boundary and that inner lattice is zipped side by side: both chains are monotone along the side
// and lie on two parallel lines (the edge and the first lattice row), so every zipper triangle
// has positive area. All triangles are counter-clockwise, like the domain: output keeps the
// orientation of the input triangle. Neighbouring triangles that agree on an edge's segment
// count agree on its points, so refined meshes have no T-junctions.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mesh4d {

struct DomainTriangulation {
    // Points in (u, v): first the boundary (corner 0, edge 0's inner points, corner 1, edge 1's,
    // corner 2, edge 2's), then the interior lattice.
    std::vector<std::array<double, 2>> points;
    size_t boundary_count = 0;
    std::vector<std::array<uint32_t, 3>> triangles;  // indices into points, counter-clockwise
};

// Preconditions: n[c] >= 1, level >= 3.
DomainTriangulation triangulateDomain(const uint32_t n[3], uint32_t level);

// Index in DomainTriangulation::points of point k (0 = corner c, n[c] = corner c + 1) of edge c.
uint32_t boundaryIndex(const uint32_t n[3], int c, uint32_t k);

}  // namespace mesh4d
