// The first step of tolerance mode for a keyframed path (worldline_refine.h): the rest mesh split
// along the curves where the emission time crosses a key, by longest-edge bisection, before the
// grid refinement of worldline_refine.h runs on the split mesh.
//
// Why. Across a key the apparent-point map has a kink (worldline_bound.h): a piece that straddles
// the curve Gamma_i = {q : sigma(q) = s_i} is bounded by a term linear in its width, so it passes
// only when about T / j wide. worldline_refine.h refines a mesh triangle as a whole (an n x n
// grid), which would cut the whole triangle that finely: O(1/T^2) pieces per triangle the curve
// crosses. Split here first, only where the kink term is large, the pieces cluster along the curve:
// O(1/T) triangles per unit length of it.
//
// The scheme. A triangle is split when its kink term (pieceBound's kink, from its
// corners' exact crossings) exceeds 8 T, or when its bound does not close (K infinite) while its
// corners' emission times straddle a key. worldline_refine.h's test then measures the error at a
// sub-grid of up to 16 x 16 exact points and bounds only the sub-pieces, whose kink terms are at
// most 8 T / 16 = T / 2; where that does not pass it refines the (now small) triangle as a whole.
// (8 T by measurement over the keyed cases of tests/motion_tolerance_test.cpp, T / 2 to 32 T
// tried: T / 2, whose straddling pieces must be about 16 times narrower, made up to 10 times more
// triangles; 32 T, which leaves wider triangles to the grids, up to 3.6 times more.) A split is Rivara's longest-edge bisection (LEPP): follow the longest-edge
// neighbours from the triangle until an edge that is the longest of every triangle around it (or
// lies on the boundary), bisect that edge at its midpoint in every triangle around it, repeat
// until the triangle itself is split. Every bisected edge is split in all its triangles at one
// point, so the mesh stays conforming: a closed mesh stays closed, no T-junctions; longest-edge
// bisection keeps the angles bounded below (Rivara 1984). Edges are ordered by (length^2, lower id,
// higher id), a strict order, so a path's edges grow strictly and every path ends.
// Triangles are visited in index order; a split keeps one half at the triangle's index and appends
// the other (visited later). A triangle already passed that a neighbour's bisection splits is not
// revisited: nothing here needs to hold for soundness, the refinement that follows tests every
// piece.
// Limits: no edge shorter than the input's longest edge over SliceSettings::max_segments (rounded
// up to a power of two, as worldline_refine.h): such a triangle is not split and its input triangle
// is counted as limited; the triangle count within SliceSettings::max_triangles (else over_budget,
// and the split stops).
// Output: the input's vertices in input order, then the midpoints in the order made; degenerate
// triangles (an index repeated) kept as they are. Deterministic; no threads. Each test costs one
// pieceBound; each vertex's exact crossing is computed once.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/lightcone.h"
#include "mesh4d/slice.h"

namespace mesh4d {

struct KeySplit {
    RestMesh mesh;                  // the split mesh
    std::vector<uint32_t> source;   // per triangle of `mesh`: the input triangle it lies in
    std::vector<uint8_t> limited;   // per input triangle: a split stopped at the finest edge
    bool over_budget = false;
};

// Preconditions: world.motion.keyed, settings.tolerance > 0.
KeySplit splitAlongKeys(const World4D& world, const ViewSurface& view, const SliceSettings& settings);

}  // namespace mesh4d
