// The template that fills one piece of the adaptive refinement (slice.h): a triangle cut into a
// structured pattern from the number of equal segments on each of its sides and an inner level,
// so that neighbouring pieces, which see the same count on the side they share, meet point for
// point (no T-junctions) with no record per output triangle.
//
// Conventions. The piece has corners P0, P1, P2 (local points 0, 1, 2) and is parametrised by the
// barycentrics (l1, l2) of P1 and P2. Side k runs from P_k to P_{k+1} and is cut into n[k] >= 1
// equal segments; its inner points i = 1 .. n[k] - 1 (from P_k) are local points
// sideFirst(k) + i - 1. The inner level N >= 1 is the level of the regular grid of the piece:
// points (i, j) at (l1, l2) = (i, j) / N, triangles the piece scaled by 1/N and its point
// reflection.
// The pattern, by case:
//   - every n[k] = N: that grid (N = 1: the piece itself). Grid points on side k are side k's points.
//   - N = 1, some side finer: the piece's boundary polygon, fanned from the corner opposite the one
//     finer side, or (several finer sides) from the centroid (one inner point).
//   - otherwise (N raised to 3 when it is 2): the grid points with all three grid coordinates
//     >= 1 (an inner grid of level N - 3; for N = 3 the centre alone) keep the grid's triangles,
//     and the ring between them and the sides is stitched: at a corner whose two sides both have
//     inner points and whose ear's chord passes between the corner and the inner grid
//     (n[k-1] + n[k] > N), the corner's ear (P_k's two neighbours on its sides); then the two
//     closed loops (side points, inner-grid boundary) are zipped: each step joins the next point
//     of one loop, by the shorter diagonal in the form's metric (a triangle that would turn over
//     is never taken), else by their places along the sides (an inner point's place: its
//     projection on its side in the form's metric).
// The bound. The caller gives a quadratic form c(d) on steps d = (dl1, dl2) in the parameter plane
// that bounds the error of the linear interpolant on any triangle inside the piece:
// error <= bubbleMax(c(e01), c(e12), c(e20)) (chord_error.h, PieceForm), and a limit. Grid
// triangles are the piece scaled by 1/N: their bound is bubbleMax of the piece's / N^2, which the
// caller's choice of N keeps within the limit. The stitched ring's triangles and the ears are not
// scaled copies: each is checked against the form here, and tessellate returns false if one
// exceeds the limit (the caller raises N: the ring's triangles shrink towards the side's segments).
// Without a form (N = 1 cases whose whole piece is within the limit) nothing is checked: the
// delay is convex, so the interpolant on any triangle inside the piece lies between the delay and
// the piece's own interpolant, and its error is at most the piece's.
// Output: triangles of local point indices, with the piece's orientation (P0, P1, P2 counter-
// clockwise in (l1, l2) gives counter-clockwise triangles).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace mesh4d {

struct TessForm {
    double cu = 0, cv = 0, cuv = 0;  // c(d) = dl1^2 cu + dl2^2 cv + 2 dl1 dl2 cuv
    double limit = 0;                // largest bubbleMax a stitched triangle may have
};

class TessLayout {
public:
    // n[k]: segments on side k (>= 1); N: inner level (>= 1). Raises N from 2 to 3 where the
    // pattern needs inner points (see above): read level() for the level used.
    TessLayout(int N, const int n[3]);
    int level() const { return N_; }
    bool grid() const { return grid_; }
    // Local points: 3 corners, then each side's inner points, then the inner points of the piece.
    uint32_t sideFirst(int k) const { return side_first_[k]; }
    uint32_t innerFirst() const { return inner_first_; }
    uint32_t innerCount() const { return count_ - inner_first_; }
    uint32_t count() const { return count_; }
    // The parameters (l1, l2) of local point p < count(): a corner, a side's point, an inner grid
    // point (i, j) / N, or the centroid of an N = 1 fan.
    std::array<double, 2> param(uint32_t p) const;
    // Fills `out` (cleared first) with the triangles; false when a checked triangle's bound
    // exceeds form->limit (then `out` is incomplete). form == nullptr: nothing is checked.
    bool tessellate(const TessForm* form, std::vector<std::array<uint32_t, 3>>& out) const;

private:
    int N_;
    int n_[3];
    bool grid_ = false;
    bool centroid_ = false;  // N = 1 with several finer sides: one inner point, the centroid
    uint32_t side_first_[3];
    uint32_t inner_first_ = 0, count_ = 0;

    uint32_t gridPoint(int i, int j) const;
};

}  // namespace mesh4d
