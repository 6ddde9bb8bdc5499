// The vertex clip (cut/slice.cpp: FrameBuilder::classifyVertices, clipWhole, addTriangle): each
// vertex's side of the real caps and the clip of a convex polygon to the span between them, which
// the rest clip (cut/rest_clip.cpp) and the refinement's leaves (refine/first_pass.cpp) use too.
// The frame's state it works in is FrameBuilder's (mesh4d/cut/frame_builder.h).
#pragma once

#include <cstdint>

namespace mesh4d {
namespace slicing {

// Where a vertex's worldline crossing falls relative to the extruded span.
enum class Side : uint8_t { NotYet, Inside, Gone };

// Sutherland-Hodgman over the span between the caps, for a convex polygon of n corners whose
// sides are s[i]: the corners inside the span, and on each side i -> i + 1 whose ends lie on
// different sides of a cap, that cap's crossing (both caps' crossings, in order along the side,
// when it runs from before existing to after). corner(i) and crossing(i, j, cap) give output ids.
// Writes at most 2 n ids to `out` and returns their count (a triangle gives at most 5).
template <class Corner, class Crossing>
int clipToSpan(int n, const Side* s, Corner corner, Crossing crossing, uint32_t* out) {
    int k = 0;
    for (int i = 0; i < n; ++i) {
        const int j = (i + 1) % n;
        const Side si = s[i], sj = s[j];
        if (si == Side::Inside) out[k++] = corner(i);
        if (si == sj) continue;
        const bool cross_a = si == Side::NotYet || sj == Side::NotYet;
        const bool cross_b = si == Side::Gone || sj == Side::Gone;
        const bool a_first = si == Side::NotYet || sj == Side::Gone;
        if (cross_a && cross_b) {
            out[k++] = crossing(i, j, a_first ? 0 : 1);
            out[k++] = crossing(i, j, a_first ? 1 : 0);
        } else {
            out[k++] = crossing(i, j, cross_a ? 0 : 1);
        }
    }
    return k;
}

// Why the steps of cut/slice.cpp hold:
//   - No real cap, nothing culled, every vertex used, the refinement's batch cut made: output vertex
//     i is the image of vertex i, copied in bulk (the same points vertexPoint emits).
//   - Visible vertices first, in input order: when nothing is clipped or refined, output vertex i is
//     the image of input vertex i (unreferenced input vertices aside).
//   - The camera among the events: h <= t_c - t there; the light has not left any of them yet, or so
//     little time ago that whatever shows is narrower than the limit.
//   - The 4D-box cull of one run of triangles (SliceSettings::cull): true when some event of the run
//     may be visible. On the cone, h = (t_c - t) - |x - C| is at most (t_c - t_lo) - dist(C, box)
//     and at least (t_c - t_hi) - maxdist(C, box) over a box; on the hyperplane only the t terms
//     remain, and on the tilted one (lightcone.h) the least and greatest (x - C).k over the box take
//     the distances' place. The margin covers the rounding of these bounds (a few ulps of the largest term).
//   - Model only what the cut requires: on a hyperplane, or at rest, the map from the rest surface
//     to the apparent one is affine, so straight edges are exact and nothing is refined (at rest
//     under a shear it is not: chord_error.h displacedChordError).
//   - At rest on the past cone with a real cap, the caps' clip curves are circles: those alone are
//     refined (FrameBuilder::restPlan). A motion that is not uniform (worldline.h) is otherwise cut
//     in vertex mode: exact points on the true worldlines (lightcone.h sends each cut to
//     crossWorldline).
//   - A motion that is not uniform, with a tolerance: worldline_refine.h (no real cap; the callers
//     refuse a tolerance for such an object that begins or ends existing, and a moving camera).
//   - Step: the fast path of vertex mode when nothing is clipped: output vertex i is the image of
//     input vertex i and the triangles are the input's (the same result as below, made in one pass).
//   - Step: the Galilean map into the output frame, origin and local parts apart (each local point
//     moves by -shear times its local time, a term of the object's size).

}  // namespace slicing
}  // namespace mesh4d
