// The adaptive refinement of one frame's cut (mesh4d/slice.h SliceSettings::tolerance > 0): the
// manual of mesh4d/refine/ and of the cut it refines (mesh4d/cut/). The entry is sliceWorld
// (mesh4d/slice.h); one frame is one slicing::FrameBuilder (mesh4d/cut/frame_builder.h), whose
// state every stage below reads and writes, each stage in a file of its own.
//
// The stages, in the order a frame runs them, and what each decides:
//  1. cut/slice.cpp       sliceUnsheared, classifyVertices: the model (refine or not: on a hyperplane
//                         or at rest the map is affine and nothing is refined), the 4D-box cull per
//                         run of triangles, each vertex's side of the real caps and its exact image.
//  2. first_pass.cpp      refineFrame's first pass: per mesh triangle, whether its corners' bound
//                         (chord_error.h chordErrorFromCorners), then its a-priori bound
//                         (chordErrorOfPoints over edgeBubble), passes at the tolerance; the ones
//                         that fail go to the drain.
//  3. bisect.cpp          the drain: conforming longest-edge bisection in the map's metric of every
//                         piece whose bound fails (no T-junction: an edge is split in every piece
//                         that has it), until it passes, reaches the depth limit, or is coarse.
//  4. templates.cpp       the pieces the drain leaves coarse (no real cap): whether a template pays
//                         (its whole-piece form, chord_error.h pieceForm, is tight enough), the grid
//                         level or the form bisection (form_bisect.h) that fills it, the segment
//                         counts its sides share with their neighbours (tessellate.h).
//  5. first_pass.cpp      the batch cut of every new point, then the leaves' assembly in record
//                         order, clipped to the span between the caps (clipToSpan).
//  6. cut/slice.cpp       vertex mode (no refinement): each triangle whole or clipped to the span
//     cut/rest_clip.cpp   (clipWhole); objects at rest on the past cone with a real cap and a
//                         tolerance: restPlan refines only where a cap's curve crosses a triangle.
// What T bounds: the geometric distance (SliceSettings::tolerance). A piece whose face contains
// the velocity is judged on its rim alone (slide.cpp, bound in slide_bound.h: inside such a face
// the error is a slide within it), in the first pass and the drain, never filled by a template;
// every other piece by the parametric bound, which is also the geometric one up to the factors of
// geometric_bound.h (not used yet). SliceSettings::attribute_tolerance at T turns the rim rule off.
// Non-uniform motions refine per triangle on grids instead (worldline_refine.h, bound in
// worldline_bound.h; keyframed paths split at their keys first, key_split.h); measure.h measures
// any output against the exact surface; subdivide.h is the uniform subdivision the benchmarks
// compare with.
//
// Scalar and lanes: every bound with a two-lane form (lanes.h) has its readable scalar form beside
// it, named X and XLanes (chord_error.h "Scalar and lanes"); the CMake option APPARENT_NO_LANES
// builds the scalar forms only. Both give the same bytes because the mesh4d library is compiled
// without contraction (-ffp-contract=off, CMakeLists.txt): the one place that rule is stated.
#pragma once
