// The anisotropic fill of one piece of the adaptive refinement (slice.h): conforming longest-edge
// bisection in the metric of the piece's whole-piece form, on small local arrays, with the sides
// cut at points agreed with the neighbours beforehand. The alternative to tessellate.h's regular
// grid for pieces that are stretched in the form's metric (a grid of level n makes n^2 triangles
// of the piece's own stretched shape; the bisection halves the long sides only).
//
// Conventions (as tessellate.h). The piece has corners P0, P1, P2 (local points 0, 1, 2) and is
// parametrised by the barycentrics (l1, l2) of P1 and P2. Side k runs from P_k to P_{k+1} and is
// cut into n[k] >= 1 equal segments; its inner points i = 1 .. n[k] - 1 (from P_k) are local points
// sideFirst(k) + i - 1, sideFirst(0) = 3, sideFirst(k + 1) = sideFirst(k) + n[k] - 1. The points the
// bisection makes inside the piece follow: local points innerFirst() + j, at params()[j].
// The fill. Start from the piece; a triangle is split while its bound exceeds the limit or one of
// its edges on a side still spans more than one of that side's segments. The edge split is the
// longest in the form's metric, c(d) = d^T A d / 2 (TessForm), among those that may be split (a
// side's edge spanning one segment may not); ties go to the lower local point ids, so the order
// is total and a new point never wins a tie. An inner edge is halved in both triangles that have it, after the neighbour's own
// longest edge, when it is another (Rivara's path: lengths grow strictly along it, so it ends);
// a side's edge spanning segments i0 .. i1 is cut at the side's point (i0 + i1) / 2, the one its
// neighbour piece has too. So the pieces meet point for point (no T-junctions), and the output
// depends on the inputs alone (deterministic).
// The bound, term by term. The caller's form bounds the delay's Hessian over the whole piece
// (chord_error.h PieceForm), so every triangle S inside the piece has
//     |F - L| <= speed bubbleMax(c(S's edges))
// (chord_error.h, "The whole-piece bound"); each output triangle is accepted only when its
// bubbleMax is within the limit (the caller's T / speed): nothing else is added, the form being
// valid on every sub-triangle (no third-order or cap term: the form is not a Taylor expansion at
// the sub-triangle, and the fill is used only without a real cap).
// Bounds: at most max_triangles triangles, and no triangle flatter in the form's metric than
// the piece by more than a factor (a side held to its agreed points can make a fan of slivers
// towards it): false otherwise, and the caller fills the piece with tessellate.h's template;
// a side's edge spanning one segment whose bound alone, c / 4, exceeds the limit can never pass,
// so the caller cuts each side into at least sideSegments(c(side), limit) segments.
// Cost: per output triangle about one split (one form evaluation for the new inner edge, a
// quarter for the halves, bubbleMax and the choice of edge for the triangles it touches, the
// neighbour links), no square root, no cut: the new points are cut by the caller in its batch.
// Between the global bisection and a grid template per output triangle, so the caller uses it
// for small needs only (refine/templates.cpp, kAnisoMaxNeed; docs/PERFORMANCE.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tessellate.h"

namespace mesh4d {

class FormBisection {
public:
    // Fills `out` (cleared first) with the triangles of local point indices, with the piece's
    // orientation. False when more than max_triangles would be needed (then `out` is incomplete).
    bool fill(const TessForm& form, const int n[3], size_t max_triangles, std::vector<std::array<uint32_t, 3>>& out);
    uint32_t sideFirst(int k) const { return side_first_[k]; }
    uint32_t innerFirst() const { return inner_first_; }
    // The params (l1, l2) of the inner points made by the last fill.
    const std::vector<std::array<double, 2>>& params() const { return inner_; }

    // The least count of equal segments of a side whose form coefficient is c such that each
    // segment's c is within 3 limit (a triangle whose three edges are within 3 limit passes:
    // bubbleMax <= max c / 3); at most cap, at least 1.
    static int sideSegments(double c, double limit, int cap);

private:
    struct Tri {
        uint32_t v[3];
        int32_t nb[3];  // across edge v[e] -> v[e + 1]: a triangle, or -(k + 1) on side k
        double c[3];    // the form on edge e (the same bits in both triangles of an inner edge)
        int8_t chosen;  // the edge to split (-1: none may be split)
        bool need;      // whether the triangle must be split
    };
    struct Point {
        double l1, l2;
        int32_t side;  // side k it lies on (its inner points; corners: -1, interior: -1)
        int32_t index; // its index along that side, from P_k
    };
    TessForm form_;
    int n_[3] = {1, 1, 1};
    uint32_t side_first_[3] = {3, 3, 3};
    uint32_t inner_first_ = 3;
    std::vector<Tri> tris_;
    std::vector<Point> pts_;
    std::vector<std::array<double, 2>> inner_;
    std::vector<uint32_t> stack_;
    size_t max_triangles_ = 0;
    mutable bool over_ = false;  // past max_triangles, or a sliver made
    double min_shape_ = 0;  // the least shape a triangle may have (kShapeLoss times the piece's)
    // Longest-edge bisection keeps the angles within a fixed factor of the piece's (shape falls
    // by a bounded factor); a side's edge that may not be split can make a fan that flattens
    // towards the side. A triangle whose shape falls below the piece's times this stops the fill.
    static constexpr double kShapeLoss = 1.0 / 64;
    static double shape(const Tri& t);

    double edgeC(uint32_t a, uint32_t b) const;
    int sideIndex(uint32_t p, int k) const;
    bool splittable(const Tri& t, int e) const;
    void judge(Tri& t) const;
    uint32_t sidePoint(int k, int i) const;
    void split(uint32_t t);
};

}  // namespace mesh4d
