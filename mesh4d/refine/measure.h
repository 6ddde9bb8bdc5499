// Measured distance between an apparent mesh and the exact apparent surface, both directions,
// shared by the tests, the accuracy benchmark and `apparent trade`. The exact surface is evaluated
// point by point, independently of how the mesh was refined: for uniform motion by the direct
// closed form (not the anchored form that made the mesh's points); for the motions beyond uniform
// (worldline.h: spin, rolling, acceleration, keyframed paths) by a root search of this file's own
// (crossingBySearch: bracketing and plain bisection on the true worldline, worldlineEvent), not
// by crossWorldline's Newton search nor by the refinement's grid points.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <utility>
#include <vector>

#include "mesh4d/motion/worldline.h"
#include "mesh4d/slice.h"

namespace mesh4d::measure {

// The crossing of rest point q's worldline with the view surface, by a bracketing search. h(s) =
// (t_c - t(s)) - |x(s) - C| (cone) or t_c - t(s) (hyperplane), (t, x) = worldlineEvent(m, s, q),
// decreases strictly along a timelike worldline (worldline.h), so its one root is bracketed by
// steps that double from the guess s0 = t_c - t0 - |X0 + q - C| (1, 2, 4, ... up to 2^200 either
// way). The bracket [lo, hi], h(lo) > 0 >= h(hi), then shrinks until its ends are adjacent doubles
// or h(hi) is exactly 0 (the guess s0 is the root itself for a point whose distance from the camera
// does not change, such as a wheel spinning about the line of sight): s to the last bit of a
// double, the event's rounding aside. Each step tries the secant point of the bracket's ends
// (regula falsi, with the Illinois rule: an end kept twice in a row has its h halved, so the other
// end moves too), and takes the midpoint instead when that point is not strictly inside or when
// the bracket did not halve over the last four steps: superlinear where h is smooth, and within a
// small factor of bisection's 60 evaluations where it is not. Only values of h are used (no
// derivative, nothing of crossWorldline's Newton search). Returns the lab event; ok = false when
// no bracket was found (NaN or infinite input).
inline Event crossingBySearch(const ViewSurface& view, const Motion& m, const Vec3& q, bool* ok = nullptr) {
    const bool cone = view.kind == ViewKind::PastCone;
    auto h = [&](double s) {
        const Event e = worldlineEvent(m, s, q);
        return (view.t_c - e.t) - (cone ? norm(e.x - view.apex) : 0.0);
    };
    const double s0 = view.t_c - m.t0 - (cone ? norm(m.origin + q - view.apex) : 0.0);
    double lo = s0, hi = s0;
    bool found = false;
    if (h(s0) > 0) {
        for (double step = 1; step < 1e60 && !found; step *= 2) {
            hi = s0 + step;
            if (h(hi) > 0) lo = hi;
            else found = true;
        }
    } else {
        for (double step = 1; step < 1e60 && !found; step *= 2) {
            lo = s0 - step;
            if (h(lo) <= 0) hi = lo;
            else found = true;
        }
    }
    if (ok) *ok = found;
    double h_lo = found ? h(lo) : 0, h_hi = found ? h(hi) : 0;  // h_lo > 0 >= h_hi
    double f_lo = h_lo, f_hi = h_hi;  // the values the secant uses (halved by the Illinois rule)
    int kept = 0;                     // +n: lo kept n steps in a row, -n: hi
    double width_before = hi - lo;    // the bracket four steps ago
    for (int i = 0; i < 4400 && found; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi || h_hi == 0) break;
        // Step: the secant point, or the midpoint when it is not inside or the bracket shrinks slowly.
        double s = lo + (hi - lo) * (f_lo / (f_lo - f_hi));
        if (i % 4 == 0) {
            if (hi - lo > 0.5 * width_before) s = mid;
            width_before = hi - lo;
        }
        if (!(s > lo && s < hi)) s = mid;
        const double v = h(s);
        if (v > 0) {
            lo = s, h_lo = f_lo = v;
            kept = kept < 0 ? kept - 1 : -1;
            if (kept <= -2) f_hi *= 0.5;
        } else {
            hi = s, h_hi = f_hi = v;
            kept = kept > 0 ? kept + 1 : 1;
            if (kept >= 2) f_lo *= 0.5;
        }
    }
    return worldlineEvent(m, std::fabs(h_lo) <= std::fabs(h_hi) ? lo : hi, q);
}


// The exact apparent point of rest point q relative to `origin`. Uniform motion: by the direct
// closed form of the cut from where the point is now (lightcone.h cutRestWorldline: one quadratic
// in the whole delay), not by the anchored form (delay of the origin plus a second quadratic) that
// the mesh is made with. Other motions: crossingBySearch (their outputs are never sheared: the
// callers refuse a moving camera for them).
inline Vec3 exactRelative(const World4D& w, const ViewSurface& view, const Vec3& q, const Vec3& origin) {
    if (!isUniform(w.motion)) return crossingBySearch(view, w.motion, q).x - origin;
    return cutRestWorldline(view, w.motion, nowBase(view, w.motion), q).x - origin;
}

// Barycentric sample points: vertices, edge midpoints, the centroid and interior points.
inline const double kSamples[12][3] = {{1, 0, 0},     {0, 1, 0},   {0, 0, 1},   {0.5, 0.5, 0},
                                       {0, 0.5, 0.5}, {0.5, 0, 0.5}, {1. / 3, 1. / 3, 1. / 3}, {0.6, 0.2, 0.2},
                                       {0.2, 0.6, 0.2}, {0.2, 0.2, 0.6}, {0.25, 0.75, 0}, {0.75, 0, 0.25}};

// Output -> exact: the largest |L(p) - F(p)| over samples of every output triangle, where L is the
// mesh (linear on each triangle) and F the exact image of the same rest point. Bounds the
// distance from every sampled output point to the exact surface.
inline double outputToExact(const World4D& w, const ViewSurface& view, const ApparentMesh& m) {
    double worst = 0;
    for (const auto& t : m.triangles)
        for (const auto& b : kSamples) {
            Vec3 rest{0, 0, 0}, out{0, 0, 0};
            for (int k = 0; k < 3; ++k) {
                rest += m.rest_points[t[k]] * b[k];
                out += m.positions[t[k]] * b[k];
            }
            worst = std::max(worst, norm(exactRelative(w, view, rest, m.origin) - out));
        }
    return worst;
}

// The output triangles that lie on each input triangle (source_triangles), by input triangle.
inline std::vector<std::vector<size_t>> outputBySource(const World4D& w, const ApparentMesh& m) {
    std::vector<std::vector<size_t>> by_source(w.mesh.triangles.size());
    for (size_t t = 0; t < m.triangles.size(); ++t) by_source[m.source_triangles[t]].push_back(t);
    return by_source;
}

// fn(q) for the points of the barycentric grid of input triangle f: (grid + 1)(grid + 2) / 2 rest
// points, row by row; n is the triangle's (unnormalised) normal, for sameRestPoint.
template <class Fn>
void forEachLatticePoint(const RestMesh& mesh, size_t f, int grid, Vec3* n, Fn fn) {
    const auto& it = mesh.triangles[f];
    const Vec3 a = mesh.positions[it[0]], b = mesh.positions[it[1]], c = mesh.positions[it[2]];
    *n = cross(b - a, c - a);
    for (int i = 0; i <= grid; ++i)
        for (int j = 0; i + j <= grid; ++j) {
            const double l1 = double(i) / grid, l2 = double(j) / grid;
            fn(a * (1 - l1 - l2) + b * l1 + c * l2);
        }
}

// The distance from x, the exact image of rest point q on an input triangle of normal n, to the
// output point of the same rest point: the least over the output triangles `on` that input
// triangle whose rest triangle contains q; INFINITY when none does.
inline double sameRestPoint(const ApparentMesh& m, const std::vector<size_t>& on, const Vec3& n, const Vec3& q,
                            const Vec3& x) {
    double best = INFINITY;
    for (size_t t : on) {
        const auto& ot = m.triangles[t];
        const Vec3 p0 = m.rest_points[ot[0]], p1 = m.rest_points[ot[1]], p2 = m.rest_points[ot[2]];
        const double area = dot(cross(p1 - p0, p2 - p0), n);
        if (area == 0) continue;
        const double l[3] = {dot(cross(p1 - q, p2 - q), n) / area, dot(cross(p2 - q, p0 - q), n) / area,
                             dot(cross(p0 - q, p1 - q), n) / area};
        if (std::min({l[0], l[1], l[2]}) < -1e-9) continue;
        const Vec3 out = m.positions[ot[0]] * l[0] + m.positions[ot[1]] * l[1] + m.positions[ot[2]] * l[2];
        best = std::min(best, norm(x - out));
    }
    return best;
}

// Exact -> output: for points on a barycentric grid of every input triangle, the distance from
// the exact point to the output point at the same rest point (found in the output triangles that
// lie on that input triangle). Bounds the distance from every sampled exact point to the mesh.
inline double exactToOutput(const World4D& w, const ViewSurface& view, const ApparentMesh& m,
                            int grid) {
    const std::vector<std::vector<size_t>> by_source = outputBySource(w, m);
    double worst = 0;
    for (size_t f = 0; f < w.mesh.triangles.size(); ++f) {
        Vec3 n;
        forEachLatticePoint(w.mesh, f, grid, &n, [&](const Vec3& q) {
            worst = std::max(worst, sameRestPoint(m, by_source[f], n, q, exactRelative(w, view, q, m.origin)));
        });
    }
    return worst;
}


// The two-sided PARAMETRIC distance as the tests measure it: the larger of both directions (grid 8
// on each input triangle for exact -> output). An upper bound of the geometric one below
// (geometricTwoSided), which is what --tolerance promises.
inline double twoSided(const World4D& w, const ViewSurface& view, const ApparentMesh& m, int grid = 8) {
    if (m.triangles.empty()) return 0;
    return std::max(outputToExact(w, view, m), exactToOutput(w, view, m, grid));
}

// ---- The geometric distance: to the nearest point, not to the image of the same rest point ----
// twoSided above is the PARAMETRIC error: each output point L(q) against the exact image F(q) of
// its own rest point q. `--tolerance` promises a GEOMETRIC one, the two-sided distance between the
// output surface and the exact apparent surface as sets, which the functions below measure:
//   output -> exact: for the same sample points of every output triangle as outputToExact, the
//     distance from L(q) to the NEAREST point of the exact surface (any rest point of any input
//     triangle);
//   exact -> output: for the exact images F(q) of those samples' rest points and of the same
//     lattice of every input triangle as exactToOutput, the distance to the nearest point of the
//     output mesh (every output triangle, not only those on the same rest point).
// Each is a minimum over a set that contains the parametric pair (q itself), so per sample the
// geometric distance is at most the parametric one, which also bounds the search: the nearest
// point lies within the parametric distance of the sample.
// How. Exact -> output is exact geometry: the closest point of each output triangle within that
// radius (a tree of the triangles' boxes finds them), no iteration. Output -> exact needs the
// exact surface, which exists only point by point (exactRelative: the closed form for uniform
// motion, the bisection crossingBySearch otherwise; never the refinement's code). It is taken
// over each input triangle's rest domain q = q0 + a e1 + b e2 (a, b >= 0, a + b <= 1): minimise
// |F(q) - p|^2 by Gauss-Newton in (a, b) (Jacobian by forward differences of exactRelative, step
// 1e-6 of the triangle's parameters), started from the rest point of the sample when the triangle
// is the sample's own, else from the nearest point of a lattice of 4 x 4 exact points of the
// triangle; when the unconstrained minimiser leaves the triangle, the distance is minimised on
// the edges whose side it lies beyond (Newton in one parameter, clamped to the edge; F is smooth
// and the squared distance nearly a convex quadratic at these scales, so the constrained minimum
// is on one of those edges then). Input triangles are candidates when their exact lattice's box, widened by
// 4 times the lattice's largest chord error at its sub-triangles' centroids (a quadratic's largest
// error over a triangle is at most 9/4 of its centroid's), comes within the radius; nearer boxes
// first, and a box farther than the best distance so far is skipped.
// Only the largest distance is kept, and no sample's geometric distance exceeds its parametric
// one, so the samples are visited by decreasing parametric distance (per output triangle, its
// largest) and the search stops where that falls to the largest geometric distance found: the
// same maximum as visiting all of them.
// Why this and not a dense reference mesh: every distance returned is |F(q*) - p| for an actual
// rest point q* of the input mesh, so it is never below the true distance (to rounding: a few
// ulps of the object's size); it can only be above it where the search missed the minimiser, and
// the tests bound that from below (a brute-force lattice of exact points, a closed form). A
// reference mesh would carry its own chord error, which would have to be far below the
// distances measured (the geometric error of a fine output is many orders below its parametric
// one on faces containing v), so a mesh fine enough would be larger than any output.
struct GeometricError {
    double output_to_exact = 0;  // largest distance from an output sample to the exact surface
    double exact_to_output = 0;  // largest distance from an exact sample to the output mesh
    double twoSided() const { return std::max(output_to_exact, exact_to_output); }
};

// A bounding-volume tree of boxes: the boxes within a distance of a point, nearest first.
class BoxTree {
public:
    void build(std::vector<Vec3> lo, std::vector<Vec3> hi);
    // The indices of the boxes within `radius` of p, with their distances, nearest first.
    void within(const Vec3& p, double radius, std::vector<std::pair<double, uint32_t>>* out) const;

private:
    struct Node {
        Vec3 lo, hi;
        uint32_t first = 0, count = 0;  // leaf: order_[first, first + count); inner: count 0, children first, first + 1
    };
    std::vector<Node> nodes_;
    std::vector<uint32_t> order_;
    std::vector<Vec3> leaf_lo_, leaf_hi_;  // the boxes, by index
};

// The exact surface of a world in one view, as nearest-point queries.
class ExactSurface {
public:
    ExactSurface(const World4D& w, const ViewSurface& view, const Vec3& origin);
    // The distance from p (relative to origin) to the nearest exact point within `radius` of it;
    // `radius` when none is nearer. hint: an input triangle and a rest point on it to start from.
    double distance(const Vec3& p, double radius, uint32_t hint_triangle = UINT32_MAX,
                    const Vec3* hint_rest = nullptr) const;
    // exactRelative(w, view, q, origin), the view's nowBase made once.
    Vec3 exact(const Vec3& q) const {
        if (!uniform_) return crossingBySearch(view_, w_.motion, q).x - origin_;
        return cutRestWorldline(view_, w_.motion, now_base_, q).x - origin_;
    }

private:
    double onTriangle(uint32_t f, const Vec3& p, double a, double b) const;
    double onEdge(const Vec3& q0, const Vec3& q1, const Vec3& p) const;
    const World4D& w_;
    ViewSurface view_;
    Vec3 origin_;
    bool uniform_ = true;
    Vec3 now_base_{0, 0, 0};
    static constexpr int kLattice = 4;
    std::vector<Vec3> lattice_;         // per input triangle, (kLattice + 1)(kLattice + 2) / 2 exact points
    BoxTree tree_;                      // per input triangle, the widened box of its lattice
};

// Both geometric directions (above) of mesh m; grid: the input-triangle lattice of exactToOutput.
GeometricError geometricError(const World4D& w, const ViewSurface& view, const ApparentMesh& m, int grid = 8);
// The two-sided geometric distance: the larger of both directions.
inline double geometricTwoSided(const World4D& w, const ViewSurface& view, const ApparentMesh& m, int grid = 8) {
    return m.triangles.empty() ? 0.0 : geometricError(w, view, m, grid).twoSided();
}

// The distance from p to the triangle (a, b, c), exact geometry (the closest point by region).
double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace mesh4d::measure
