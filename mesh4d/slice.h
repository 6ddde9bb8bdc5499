// One frame of the apparent shape: the static 4D history of an object cut by a view surface.
//
// For a subluminal object every rest point's worldline meets the view surface exactly once, so
// the cut of a prism is a graph over its triangle (DESIGN.md section 6): the three tetrahedra of
// the prism are bookkeeping and never show in the output. Vertex mode (this file) places exact
// vertices and joins them with straight edges:
//   - a rest vertex whose worldline crossing lies inside the extruded span gives its exact
//     retarded event (the closed form of lightcone.h), computed once per vertex;
//   - where the crossing leaves a real cap (the object has not begun, or has ended, existing),
//     the triangle is clipped: the clip points are the exact crossings of the cap edges (spacelike
//     segments of the 4D tetrahedra) with the view surface, computed once per (edge, cap) and
//     keyed by the edge's global id, so neighbouring triangles share them bit for bit.
// A closed 2-manifold that exists throughout therefore gives a closed 2-manifold of the same
// genus, with exactly one output vertex per input vertex. Which side of a cap a vertex falls on is
// decided by the sign of viewSide at the cap event, once per vertex; zero counts as inside.
// Straight edges between exact vertices leave an error that grows with triangle size, speed and
// nearness (DESIGN.md section 6); bounding it is the tessellation's job, not this file's.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "extrude.h"
#include "lightcone.h"

namespace mesh4d {

struct ApparentMesh {
    // Apparent points (lab frame, light-seconds): first the images of the visible input vertices
    // in input order, then the clip points of this frame.
    std::vector<Vec3> positions;
    std::vector<double> emission_times;   // lab time each point emitted the light seen at t_c
    std::vector<std::array<uint32_t, 3>> triangles;  // orientation of the input triangles kept
    size_t clipped_triangles = 0;         // input triangles cut by a real cap in this frame
};

// Cuts `world` with `view`. Precondition: world.motion.beta < 1 when view.kind == PastCone.
// The result is empty when no part of the history meets the view surface.
ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view);

}  // namespace mesh4d
