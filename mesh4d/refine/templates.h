// The templates (refine/templates.cpp, FrameBuilder::coarseForm, templateLeaves, fillLeaf): the
// pieces the bisection leaves, each filled at once by a grid (tessellate.h) or by the bisection
// in its form's metric (form_bisect.h). When a template pays, how its level is chosen and why
// its output is within T, with the constants that decide it; the frame's state it works in is
// FrameBuilder's (mesh4d/cut/frame_builder.h).
#pragma once

#include <cstdint>

namespace mesh4d {
namespace slicing {

// The bisection (refine/bisect.cpp) stops at a piece whose bound passes (kPassed) or that a
// template fills better (kCoarse, coarseForm): its whole-piece form (chord_error.h pieceForm: one
// quadratic form A >= the delay's Hessian all over the piece) asks for a level n >= kMinLevel,
//     n = the least integer with speed bubbleMax(A's sides) / n^2 <= T,
// the piece is not much worse shaped in A's metric than an equilateral triangle (area over
// bound at least kShapeShare of the equilateral's: the template's triangles have the piece's
// shape), and A is nearly the form at its centroid (within kCoarseSlack) or the n^2
// triangles of the template are fewer than the two halves are expected to need (each half
// asks for half the centroid's need, its excess of A over the centroid's form shrunk by
// sqrt 2, its level rounded up by kRounding on average). With the form of chord_error.h
// (second-order slack along the line of sight) this holds near the camera too. For a mesh
// triangle (depth 0) whose A is within kNearlyUniform of its centroid's form, each half's
// need is taken from the centroid's form on that half's own sides instead (halvesEstimate):
// a well-shaped piece's halves keep about 3/4 of its need each, not 1/2, so the halves were
// expected to be cheaper than they are, and a mesh triangle far from the camera (the plate
// of docs/ACCURACY.md) was halved, its halves' grids rounding up to more triangles than its
// own, or halved on down to pieces below kMinLevel and bisected to the end (the templates
// then too small a share of the frame's leaves). Its level is now decided at once. On the
// pieces the bisection made (near the camera, where the halves gain by adapting to the
// varying form) the first estimate is kept: the new one on every piece made the box's
// closest frame more triangles (Refine.FewerTrianglesThanUniformSubdivisionAtEqualError;
// docs/PERFORMANCE.md, "The refinement's costs").
// A split that would halve a piece marked kCoarse at a level of kKeptLevel or more (the
// longest-edge path of a neighbour reaching it) is not made: the neighbour is filled by its
// own template instead (splitLongestPath's guard), so a template, once chosen, stays whole
// (near the camera the bisection would otherwise cut every template its neighbours reach,
// and each piece cut so pays the bisection's records instead of the template's). The neighbour's forced template rounds its level up, and the
// neighbour may be stretched in the form's metric (no shape rule): where that template
// would make more than kForceRatio times the triangles its bisection is expected to make
// (its bubbles' bound over T, about the pieces halving down to T leaves), the split is made
// after all and the template's halves are judged again (forcedTemplatePays). Guarding every
// level without that rule templated the box's closest frame at T = 1e-3 x size into more
// triangles than uniform subdivision's; guarding level 8 and more only left the box at
// T = 1e-4 x size mostly bisected (docs/ACCURACY.md, "Templates").
// The grid triangles of a piece at level n (the piece scaled by 1/n) are within T
// (chord_error.h PieceForm). Each edge record gets the largest level of the pieces around
// it, and both sides cut it into that many equal segments: no T-junctions, and the counts
// depend on the pieces alone (deterministic). The template (tessellate.h) fills the piece:
// grid triangles inside, a stitched ring along sides cut more finely than its level, every
// ring triangle checked against A (the piece's level is raised until they pass: in the limit
// the ring's triangles shrink to the sides' segments, each shorter than a grid edge of the
// piece's first level). A piece that passed as a whole (and the mesh's triangles that needed
// nothing) keeps level 1: its sides' extra points are fanned and, the delay being convex,
// every triangle inside it is within its own bound.
// A piece whose shape fails that rule and whose need is at most kAnisoMaxNeed is filled by
// bisection in its form's metric instead (form_bisect.h: the grid would round its stretched
// triangles up; the global bisection would pay its bounds and records per piece); its sides
// get the counts FormBisection::sideSegments gives (each segment within 3 T / speed by the
// form), in the same largest-count-around-each-edge rule, so its neighbours conform. Larger
// needs are bisected on: their halves soon get grids, far cheaper per triangle (the limit's
// choice: docs/PERFORMANCE.md, "The refinement's costs").
// The template makes no record per output triangle; where it is not used (a level below
// kMinLevel, or more triangles than the halves') the bisection goes on to pieces that
// pass, which adapts more finely (docs/ACCURACY.md: the constants keep every trade ratio
// within the targets).
constexpr double kMinLevel = 2;
constexpr double kShapeShare = 0.3;
constexpr double kEquilateral = 2.598076211353316;  // 3 sqrt(3) / 2: area / bubbleMax of an equilateral triangle
constexpr double kCoarseSlack = 1.1;
constexpr double kRounding = 0.3;
constexpr double kTemplateShare = 0.5;  // least share of the leaves the templates' triangles must make (refineFrame)
constexpr uint32_t kKeptLevel = 2;      // least level of a template the guard keeps whole
constexpr double kForceRatio = 2;       // a forced template's triangles over its bisection's expected count, at most
constexpr double kAnisoCost = 2;        // FormBisection's triangles over the form's need (bubbleMax speed / T), about
constexpr double kAnisoMaxNeed = 16;    // the largest need (bubbleMax speed / T) FormBisection fills
constexpr uint32_t kNoCap = 1u << 20;   // formLevel without the max_segments cap
constexpr double kNearlyUniform = 1.2;  // a mesh triangle's A within this of its centroid's form: halvesEstimate

// Why the steps of refine/templates.cpp hold:
//   - Its shape in the form's metric: area over bound, against the equilateral's (the template's
//     triangles are the piece's shape, scaled).
//   - A fill's local points 0..2 are the corners, then each side's n[k] - 1 shared points from
//     side_first(k): both mapped to the frame's point ids (the sides' points in edge order).
//   - A piece stretched in its form's metric: the bisection in that metric (form_bisect.h), unless
//     that fails (past cap^2 triangles, or a fan of slivers along a side held to its points): then
//     the grid below, on the same side counts.
//   - Step: each record's level, and each edge's count (the largest level around it). The estimate
//     bounds the output: a leaf makes at most N^2 + 2 + the extra segments of its sides
//     (tessellate.h), an edge is on about two leaves.
//   - A form asking for more than max_segments segments gets that many: the tolerance is not met
//     there, counted as the depth limit is.

}  // namespace slicing
}  // namespace mesh4d
