// Tolerance mode for motions that are not uniform (worldline.h: spinning, rolling, Born-rigid
// accelerated bodies, keyframed paths): the cut of slice.h refined until the straight output lies
// within T of the exact apparent surface, both ways.
//
// The scheme. Each mesh triangle gets a level n, a power of two (1 = the triangle itself): it is
// cut into the n x n grid of its barycentric coordinates (n^2 pieces), every grid point the exact
// crossing of its worldline (crossWorldline). A piece passes when
//     B = K d^2 / 6 + J <= T    (K and J the bounds of worldline_bound.h pieceBound over the
//                       piece: the map's second derivative, and the kink term where a keyframed
//                       path's emission time crosses a key, J = 0 for the other motions; d the
//                       piece's longest rest side: no further cut), or, for the first m in
//                       2, 4, 8, 16 where it holds,
//     eps + max_k B_k <= T,
// eps the largest measured |F - L| at the points of the piece's m x m sub-grid (exact crossings
// against the piece's linear interpolant L), B_k the bound over sub-piece k (side d / m) from its
// own exact corners. Sound: e = F - L has the second derivative and the kinks of F, so on sub-piece k, e lies
// within B_k of its linear interpolant there, whose largest value is at the sub-grid points
// (worldline_bound.h gives the Taylor argument, kinks included); so |F - L| <= eps + max_k B_k
// on the whole piece. A piece with eps > T fails at once (that is a measured error). The measured term is
// what makes the bound tight (K takes the worst angles separately; eps does not), and the sub-pieces'
// own K (their Doppler term carried over a short distance only) what keeps K finite.
// A triangle's level doubles until all its pieces pass, at most to SliceSettings::max_segments
// pieces along an edge (then counted in limited_triangles) and while the output stays within
// SliceSettings::max_triangles (else over_budget).
// Conforming: a mesh edge is cut into n_e = the largest level of the triangles around it, and
// every edge point is computed from the edge alone (its lower vertex id first, at the exact
// fraction k / n_e), so neighbours share them bit for bit and the output keeps the input's
// topology: a closed mesh stays closed (no T-junctions). A piece with finer points on one of its
// sides is fanned from its opposite corner; with finer points on two sides, from its centroid (one
// more exact point). Each fan triangle is tested as a piece (above); when one fails, its mesh
// triangle's level doubles and the edge levels are taken again, until nothing changes (levels only
// grow, so this ends).
// A keyframed path's rest mesh is first split along the curves where the emission time crosses a
// key (key_split.h); the grids run on the split mesh, and its output triangles name the input
// triangle they lie in (source_triangles; refined_triangles and limited_triangles count input
// triangles).
// Preconditions (slice.cpp's hook): not isUniform(world.motion), tolerance > 0, no real cap (an
// object that begins or ends existing is refused a tolerance by the callers, pipeline/stage/physics.cpp:
// the cap's clip curve is not bounded here), world not empty.
// The output is as sliceWorld's (ApparentMesh, local coordinates about the origin's crossing):
// first the used input vertices in input order (when every level is 1, exactly vertex mode's
// output), then the edge points (by edge, from the lower vertex), then each triangle's interior
// and centroid points in the order its pieces first use them; triangles in input order, each
// triangle's pieces row by row. Deterministic; no threads.
// Cost: up to (m + 1)(m + 2) / 2 exact crossings per tested piece for each m tried (a safeguarded
// Newton search each) plus one per output point; levels are tried from 1 up.
#pragma once

#include "mesh4d/extrude.h"
#include "mesh4d/slice.h"

namespace mesh4d {

ApparentMesh refineWorldlines(const World4D& world, const ViewSurface& view, const SliceSettings& settings);

}  // namespace mesh4d
