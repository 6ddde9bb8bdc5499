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
//
// Why the steps of first_pass.cpp hold (its step headings, in order):
//   - Step: the corners' bound (chordErrorFromCorners) passes most triangles that need no
//     refinement; the others get the a-priori bound (chordErrorOfBubbles).
//   - The corners' spread (chord_error.h cornerSpread: the largest |u|_M^2 of a triangle's sides)
//     from each mesh edge's |u|_M^2, made once per edge instead of once per side of each triangle:
//     |u|_M^2 is even in u (negating u negates its terms exactly), and the largest of three does not
//     depend on their order, so each triangle's spread is cornerSpread's bit for bit. (With a cull,
//     per triangle: most edges may be culled.)
//   - Every triangle passes when the whole mesh does: its largest spread D with the least |x|_M of
//     all its vertices X (passesFromSpread(D, {X, X, X})). Each triangle's d2 is at most D (both the
//     same std::max chain from 0 over the same spreads, which skips a NaN) and its xmin at least X
//     (no xm is NaN), and passesFromSpread is monotone in both as rounded (chord_error.h): fl(4 d2),
//     fl(xmin xmin) and fl(beta d2) grow with their operand, and fl(3 (1 - beta^2) T) >= 0 is one
//     factor of xmin. So the verdict is the triangles' own (no candidates), without the pass over
//     the triangles (with real caps that pass also counts the clipped triangles: it is made then).
//   - The least |x|_M of all vertices, and their sum: NaN when one is (an infinity of each sign
//     makes NaN too, and the pass below is only skipped then). (Its own loop: the terms' loop above
//     stays vectorised.)
//   - (The arrays and the tolerance read through locals: the compiler cannot tell that
//     `candidates`'s stores leave them alone, and would load them again per triangle.)
//   - The terms are the corners' own (shapeOfEvent, normMOfEvent): the corners' bound is
//     chordErrorFromCorners' bit for bit, from the one spread both tests use.
//   - Each mesh edge's bound made once and kept for the splits (edgeOf makes the same bits: ends in
//     id order), when the candidates are enough to pay for the edge records' reset (a large mesh
//     with a few candidates computes their edges per triangle instead).
//   - The corners' terms in place (the drain's pointsBound on the same record: the same bits); the
//     sides' |u|_M^2 are the edges' spreads when made (normM2 of the side either way round: the same
//     bits, chord_error.h chordErrorOfSides).
//   - Room for the pieces and points the refinement is expected to make (growth would copy them). At
//     most a million: reserving is only a saving, never a bound (max_triangles is).
//   - Still as the mesh has it (only a split changes a record's corners, and it deepens it; a
//     neighbour's split may have made the record): the first pass's verdict stands, from the same
//     terms and edge records (edgeOf: the same bits).
//   - Step: templates only where they make most of the output: else the few coarse pieces are
//     bisected on like the rest (the templates' pass over every leaf would cost more than it saves).
//   - The records still coarse, in id order (as a pass over all records would meet them), from the
//     list of those marked: no pass over every record.
//   - Step (no real cap): the output's points, once the splits are done: the visible vertices
//     (classifyVertices, in input order), then the points the splits (and the templates) made, in
//     room for all of them made once. Without templates the room is exact: each output array is
//     allocated once per frame and its points copied once. Templates fill the leaves when the splits
//     left coarse pieces (no real cap: r_templates).
//   - Step (no real cap): the leaves filled by their templates. (Without a coarse piece every leaf
//     is its own output triangle: emitted below as they are.)
//   - Step: the leaves in record order: the mesh's triangles (or the piece each keeps), then the
//     pieces the splits appended.
//   - Nothing clipped: every point a split made is a corner of some leaf, so the points follow the
//     mesh's visible vertices in id order, copied in bulk.
#pragma once
