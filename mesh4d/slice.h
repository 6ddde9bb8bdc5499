// One frame of the apparent shape: the static 4D history of an object cut by a view surface.
//
// For a subluminal object every rest point's worldline meets the view surface exactly once, so
// the cut of a prism is a graph over its triangle (docs/DESIGN.md section 6): the three tetrahedra of
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
// nearness (docs/DESIGN.md section 6). With a tolerance T > 0 the cut is refined where the exact
// surface departs from the output, and only there ("Refinement" in slice.cpp):
//   - each triangle is accepted when the bound of chord_error.h on |F - L| (the exact image
//     against the linear interpolant of its exact corners) is <= T: first, for the mesh's
//     triangles, a bound from the corners alone; else the a-priori bound: per edge an upper bound
//     c of its midpoint bubble from the Hessian of the delay at the edge's middle, with a
//     fourth-order remainder (edgeBubble: one square root for that middle, no cut), and per
//     triangle the largest value of the quadratic form those c give plus a third-order term
//     (chordErrorOfBubbles). A triangle whose bubbles pass but whose third-order term does
//     not is passed by its whole-piece form (chord_error.h pieceForm, tighter near the camera)
//     when that is within T. The bound is on the whole triangle, so the measured error of a
//     refined mesh is 0.5 to 1 times T (docs/ACCURACY.md);
//   - a triangle that fails is halved by longest-edge bisection (Rivara) in the map's own metric
//     (edge lengths from the same Hessian: chord_error.h EdgeBubble::length), so pieces are short
//     across the direction the map bends and long along it, and only where it bends;
//   - an edge is always halved in every triangle that has it (the cycle of slots around it,
//     World4D::slot_next): no T-junctions, a watertight input stays watertight, genus is kept;
//   - no decision needs an exact cut: the points the splits make are cut once each, in one batch
//     after the last split (cutRestLocalBatch); the mesh's vertices were cut in one batch before;
//   - a piece wholly before or after existing is not refined; a piece a real cap cuts is clipped
//     at the exact crossings of its sides (keyed by the side's two vertices, so neighbours share
//     them); the clip chords are measured by the tests, not bounded;
//   - a piece is halved at most 2 log2(max_segments) times (counted in limited_triangles); splits
//     that keep a neighbour conforming are never refused;
//   - without a real cap, a piece that needs a level n >= 2 of even splitting, whose whole-piece
//     bound (chord_error.h pieceForm: one quadratic form over the whole piece) is close to the
//     map's at its centroid and whose shape in that form is not far from equilateral, is not
//     bisected further but filled by a template (tessellate.h): the regular grid of level n
//     (each triangle within T by the form), stitched along its sides to the equal segments its
//     neighbours share (each edge cut into the largest level of the pieces around it; every
//     stitched triangle checked against the form). A template is kept whole: a neighbour whose
//     split would halve it is filled by its own template instead, unless that one would make
//     more than twice the triangles the neighbour's bisection is expected to (then the split
//     is made and the template's halves are judged again). When such pieces would make less
//     than half of the output, they are bisected like the rest (slice.cpp, "Templates");
//   - a piece the grid would fill with stretched triangles (its shape in the form's metric far
//     from equilateral) whose form asks for at most 16 times T is filled instead by longest-edge
//     bisection in the form's metric on local arrays (form_bisect.h): each triangle accepted by
//     the form on its three edges (the form bounds the Hessian over the whole piece, so that is
//     the bound of every triangle inside it), its sides cut at the counts agreed with the
//     neighbours before any piece is filled (each edge the largest count around it), no edge or
//     triangle bound and no split record per sub-piece; a fill that would make slivers falls
//     back to the grid.
// |F - L| bounds both one-sided distances between the output and the exact surface, so the
// two-sided distance stays <= T. The output is deterministic (no dependence on threads) and, when
// no triangle needs refining, identical to vertex mode's. Output order: the visible input
// vertices in input order, then the splits' points (in the order they were made when nothing is
// clipped, else with the clip points in the order the leaves first use them), then the templates'
// points (per edge, then per piece, in the order the pieces are filled: a bisected piece's in the
// order its splits made them); the triangles in record
// order (each input triangle, or the piece of it that kept its record, then the pieces the splits
// appended; a templated piece gives its template's triangles in its place).
// Cost: per output triangle of the bisection about two edge bounds, one and a fifth triangle
// bounds, half a split (its point's square root and the slot bookkeeping) and the output; a
// templated piece one form and its grid besides its share of the batched cut; a piece filled by
// the bisection in its form's metric in between (figures: docs/PERFORMANCE.md, "The refinement's
// costs").
// The working arrays (a few hundred bytes per output triangle) are kept by each thread from frame to
// frame, so a frame reuses the memory of the one before; a thread frees them after a frame that
// grew them past 256 MiB.
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
#include <cmath>
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
    // Per apparent point, when the frame loop asked for them (light_factors.h, else empty): the
    // Doppler factor of the light that reaches the camera, and the object's clock at emission.
    std::vector<double> doppler;
    std::vector<double> proper_time;
    std::vector<std::array<uint32_t, 3>> triangles;  // orientation of the input triangles kept
    std::vector<uint32_t> source_triangles;  // the input triangle each output triangle lies on
    size_t clipped_triangles = 0;         // input triangles cut by a real cap in this frame
    size_t refined_triangles = 0;         // input triangles split by the tolerance
    size_t limited_triangles = 0;         // input triangles whose refinement reached max_segments first
    size_t culled_triangles = 0;          // input triangles skipped by the 4D-box cull (SliceSettings::cull)
    bool over_budget = false;             // the refinement stopped at SliceSettings::max_triangles

    Vec3 absolutePosition(size_t i) const { return origin + positions[i]; }
    double absoluteTime(size_t i) const { return time_origin + emission_times[i]; }
};

struct SliceSettings {
    // Two-sided distance bound to the exact apparent surface, light-seconds; 0 is vertex mode
    // (exact vertices, straight edges: what real-time engines do). 0 is the safe default.
    double tolerance = 0;
    // Bound of the parametric error (each output point against the exact image of its own rest
    // point: where a texture or an attribute lands), light-seconds; infinite: only the distance
    // above is bounded. Where it is below `tolerance` the refinement bounds the parametric error
    // by it everywhere; else it limits only the faces whose interior error is a slide within the
    // face (mesh4d/refine/slide_bound.h), which the distance alone leaves coarse.
    double attribute_tolerance = INFINITY;
    // Finest refinement, as pieces along an input edge: a piece is halved at most
    // 2 ceil(log2(max_segments)) times; an input triangle whose pieces would need more is counted in
    // ApparentMesh::limited_triangles. The rest clip splits at most to 1/max_segments of a triangle.
    // Values below 2 count as 2.
    int max_segments = 256;
    // Most output triangles the refinement may make for one object in one frame (0: no limit): a
    // refinement that would pass it stops splitting and sets ApparentMesh::over_budget, so that a
    // tolerance far too fine for the scene ends with a message instead of exhausting memory.
    size_t max_triangles = 0;
    // Skip runs of triangles (World4D::chunks) whose cap events all lie on one side of the view
    // surface: before a real cap a (not yet existing) or after a real cap b (gone), decided from
    // the runs' 4D boxes with a margin above rounding, so a skipped run never holds a visible
    // point. Off only to measure what it saves (benchmarks/performance_bench.cpp).
    bool cull = true;
    // The speed the refinement's bound multiplies the light delay's error by (chord_error.h
    // displacedChordError), for a cut whose outputs are mapped afterwards by a linear map that
    // turns the object's displacement (1, u) into one of this spatial length (reflections seen by a
    // moving camera: pipeline/stage/mirror.h). Negative: |u - view.shear| (the outputs themselves).
    double displacement = -1;
};

// Cuts `world` with `view`. Precondition: world.motion.beta < 1 when view.kind == PastCone.
// The result is empty when no part of the history meets the view surface. A sheared view
// (lightcone.h ViewSurface::shear, the finite model with a moving camera) is cut in its own frame
// and every output event (t, x) returned as (t, x - shear t): origin and local parts apart, so
// the shape keeps its relative accuracy; the tolerance holds for these outputs (the refinement's
// bound displaces along u - shear, chord_error.h displacedChordError, objects at rest included).
// Limit: an object at rest under a shear (or SliceSettings::displacement) is refined as a moving
// one, so a real cap's clip curve wholly inside one triangle whose corners are all unseen (its
// middle seen first) is not found: the search for those (restPlan) serves unsheared views.
// A motion that is not uniform (worldline.h) is refined by worldline_refine.h when a tolerance is
// given and no real cap clips it (else cut in vertex mode).
ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view, const SliceSettings& settings = {});

// A sphere that holds every apparent point of `world` in `view`: centred on the apparent position
// of the object's origin, radius R / (1 - b) on the cone (R = World4D::shape_radius: the shape
// offset never lengthens q; the light delay changes by at most |delta e| / (1 - b) between two
// points, so each point lies within |s| + b |s| / (1 - b) of the origin's image) and R on the
// hyperplane. Under a shear (sliceWorld) the points are s - w delta, w = u - shear: radius
// R (1 + |w| / (1 - b)), centred on the origin's sheared image. For view culling
// (pipeline/commands/render.cpp, --cull-view). A motion that is not
// uniform (worldline.h) gets an infinite radius: it is never culled.
struct BoundingSphere {
    Vec3 center;
    double radius = 0;
};
BoundingSphere apparentBound(const World4D& world, const ViewSurface& view);

// The exact apparent point of rest point `q` (any point of the object's rest frame): the crossing of
// its worldline with the view surface (sheared as sliceWorld's outputs). Used by tests and tools to
// measure the error of a mesh.
Event exactApparentPoint(const World4D& world, const ViewSurface& view, const Vec3& q);
// The same point in the local coordinates of sliceWorld's output for this world and view
// (relative to ApparentMesh::origin and time_origin), computed the same way.
Event exactLocalPoint(const World4D& world, const ViewSurface& view, const Vec3& q);

}  // namespace mesh4d
