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
// decided by the exact sign of viewSide at the cap event (exact_side.h), once per vertex; zero
// counts as inside.
// Straight edges between exact vertices leave an error that grows with triangle size, speed and
// nearness (DESIGN.md section 6). With a tolerance T > 0 the cut is refined where the surface
// departs from the chord, and nowhere else (see "Refinement" in slice.cpp):
//   - each mesh edge is split, once per frame and keyed by its id, into the fewest equal
//     parameter segments whose exact midpoints lie within T/8 of the chord; both triangles of the
//     edge use the same points, so watertight input stays watertight (no T-junctions);
//   - a triangle whose edges need no split and whose exact centroid lies within T/4 of its plane is
//     kept whole; otherwise its parameter domain gets a regular interior grid of level N, zipped
//     to the edge points (tessellate.h), and N grows until every output edge's exact midpoint
//     lies within T/4 of the chord.
// Why that bounds the error: on an output triangle with exact corners, the difference e(p) between
// the exact map F and the linear interpolant L is, to second order, a quadratic vanishing at the
// corners, e = sum over edges c_ij l_i l_j; its edge-midpoint values are c_ij / 4 and
// |e| <= (|c_01| + |c_12| + |c_20|) / 4 <= 3 T / 4 everywhere on the triangle (each midpoint
// deviates at most T/4, T/8 on edge segments). |F(p) - L(p)| bounds
// both one-sided Hausdorff distances (each output point L(p) has the exact point F(p), and back),
// so the two-sided distance is <= 3T/4 plus third-order terms, which the remaining T/4 covers once
// the mesh resolves the curvature. The test suite measures the true error on samples of every
// output triangle. A refined triangle cut by a real cap is refined the same way, then each small
// triangle is clipped at the exact cap crossings of its edges (keyed by mesh edge and segment,
// so neighbours share them): the clip curve is a polyline whose vertices lie exactly on the
// tilted cap and on the cone; inside chords are checked as above, the clip chords themselves are
// measured by the tests, not bounded.
// An object at rest on the past cone is its input (an affine cut), except where a real cap clips
// it: the cap is one lab time, so the cone meets it in a sphere and the clip curves are circles.
// With T > 0 such a triangle is split in four, recursively, only where a cap's curve could hide in
// a piece (the side function is concave: its excess over the corners is bounded) or a chord
// through a piece lies more than T/4 from the curve (at most to 1/max_segments of the triangle),
// and the pieces, with their finer neighbours' corners on their sides, are clipped at exact
// crossings: a large triangle whose middle is seen before its corners shows that middle, and
// pieces meet edge to edge, also across mesh edges.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "extrude.h"
#include "lightcone.h"

namespace mesh4d {

struct ApparentMesh {
    // Apparent points (lab frame, light-seconds) relative to `origin`: first the images of the
    // visible input vertices in input order, then the clip points of this frame. The shape is
    // computed relative to the object's own origin (lightcone.h, ViewAnchor), so it keeps its
    // relative accuracy however far the object is from the camera; absolute = origin + local.
    std::vector<Vec3> positions;
    std::vector<double> emission_times;   // lab time each point emitted the light seen at t_c, minus time_origin
    Vec3 origin{0, 0, 0};                 // lab point the positions are relative to
    double time_origin = 0;               // lab time the emission times are relative to
    std::vector<Vec3> rest_points;        // the rest-frame point each apparent point is the image of
    std::vector<std::array<uint32_t, 3>> triangles;  // orientation of the input triangles kept
    std::vector<uint32_t> source_triangles;  // the input triangle each output triangle lies on
    size_t clipped_triangles = 0;         // input triangles cut by a real cap in this frame
    size_t refined_triangles = 0;         // input triangles split by the tolerance
    size_t limited_triangles = 0;         // input triangles and edges that reached max_segments first
    size_t culled_triangles = 0;          // input triangles skipped by the 4D-box cull (SliceSettings::cull)

    Vec3 absolutePosition(size_t i) const { return origin + positions[i]; }
    double absoluteTime(size_t i) const { return time_origin + emission_times[i]; }
};

struct SliceSettings {
    // Two-sided distance bound to the exact apparent surface, light-seconds; 0 is vertex mode
    // (exact vertices, straight edges: what real-time engines do). 0 is the safe default.
    double tolerance = 0;
    // Most segments per input edge, and most interior grid levels per input triangle (at least 3);
    // an edge or triangle that would need more is counted in ApparentMesh::limited_triangles and
    // keeps this level. Values below 1 count as 1.
    int max_segments = 256;
    // Skip runs of triangles (World4D::chunks) whose cap events all lie on one side of the view
    // surface: before a real cap a (not yet existing) or after a real cap b (gone), decided from
    // the runs' 4D boxes with a margin above rounding, so a skipped run never holds a visible
    // point. Off only to measure what it saves (benchmarks/performance_bench.cpp).
    bool cull = true;
};

// Cuts `world` with `view`. Precondition: world.motion.beta < 1 when view.kind == PastCone.
// The result is empty when no part of the history meets the view surface.
ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view, const SliceSettings& settings = {});

// A sphere that holds every apparent point of `world` in `view`: centred on the apparent position
// of the object's origin, radius R / (1 - b) on the cone (R = World4D::shape_radius: the shape
// offset never lengthens q; the light delay changes by at most |delta e| / (1 - b) between two
// points, so each point lies within |s| + b |s| / (1 - b) of the origin's image) and R on the
// hyperplane. For view culling (pipeline/render.cpp, --cull-view).
struct BoundingSphere {
    Vec3 center;
    double radius = 0;
};
BoundingSphere apparentBound(const World4D& world, const ViewSurface& view);

// The exact apparent point of rest point `q` (any point of the object's rest frame): the crossing of
// its worldline with the view surface. Used by tests and tools to measure the error of a mesh.
Event exactApparentPoint(const World4D& world, const ViewSurface& view, const Vec3& q);
// The same point in the local coordinates of sliceWorld's output for this world and view
// (relative to ApparentMesh::origin and time_origin), computed the same way.
Event exactLocalPoint(const World4D& world, const ViewSurface& view, const Vec3& q);

}  // namespace mesh4d
