// Triangulation of a refined triangle's parameter domain.
//
// The domain is the right triangle (0,0), (M,0), (0,M) of an integer lattice (M < 2^53, so every
// coordinate is exact in double and points on the hypotenuse satisfy x + y = M exactly). The
// boundary points, in counter-clockwise order starting at (0,0), are joined by constraints; the
// interior points are free. CGAL's constrained Delaunay triangulation with exact predicates does
// the work (the only CGAL translation unit of mesh4d). Triangles come out counter-clockwise, so
// they keep the orientation of the input triangle whose parameter domain this is.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace mesh4d {

// Returns triangles as indices into boundary (first) followed by interior points. Preconditions:
// boundary has at least 3 points, all on the domain's edges, in order; interior points strictly inside.
std::vector<std::array<uint32_t, 3>> triangulateDomain(const std::vector<std::array<double, 2>>& boundary,
                                                       const std::vector<std::array<double, 2>>& interior);

}  // namespace mesh4d
