#include "mesh4d/motion/latest_crossing.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

namespace mesh4d {

namespace {

// A piece of a triangle: its corners in rest space, their crossings and the piece's bound.
struct Piece {
    Vec3 q[3];
    double s[3];
    double bound = 0;
    bool operator<(const Piece& o) const { return bound < o.bound; }  // the largest bound on top
};

}  // namespace

double nearestVertexReach(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a, bc = c - b, ca = a - c;
    double l2[3] = {dot(bc, bc), dot(ca, ca), dot(ab, ab)};  // opposite a, b, c
    std::sort(l2, l2 + 3);
    const double longest = std::sqrt(l2[2]);
    // Obtuse (the circumcentre outside) or degenerate: half the longest edge.
    const double twice_area = norm(cross(ab, ca));
    if (l2[2] > l2[0] + l2[1] || !(twice_area > 0)) return 0.5 * longest * (1 + 1e-12);
    // The circumradius |ab| |bc| |ca| / (4 area), at most the longest edge / sqrt(3).
    const double r = std::sqrt(l2[0]) * std::sqrt(l2[1]) * longest / (2 * twice_area);
    return std::min(r, longest) * (1 + 1e-12);
}

LatestCrossing latestCrossing(const RestMesh& mesh, const Motion& motion, const ViewSurface& view, double tolerance,
                              size_t max_splits) {
    LatestCrossing out;
    const double a = norm(motion.acceleration);
    // c(q) = min(1, a xi(q)) = min(1, 1 + a q.k): the coordinate speed of light at q (header).
    auto lightSpeed = [&](const Vec3& q) { return a > 0 ? std::min(1.0, a * horizonDistance(motion, q)) : 1.0; };
    auto crossing = [&](const Vec3& q) {
        const WorldlineCrossing c = crossWorldline(view, motion, q);
        if (!c.ok || !std::isfinite(c.s)) out.ok = false;
        out.found = std::max(out.found, c.s);
        return c.s;
    };
    auto bounded = [&](Piece p) {
        const double c = std::min({lightSpeed(p.q[0]), lightSpeed(p.q[1]), lightSpeed(p.q[2])});
        p.bound = std::max({p.s[0], p.s[1], p.s[2]}) + nearestVertexReach(p.q[0], p.q[1], p.q[2]) / c;
        return p;
    };
    // Step: each vertex's crossing once, then every triangle as one piece.
    std::vector<double> s(mesh.positions.size(), NAN);
    std::vector<bool> used(mesh.positions.size(), false);
    for (const auto& t : mesh.triangles)
        for (uint32_t v : t) used[v] = true;
    for (size_t v = 0; v < s.size(); ++v)
        if (used[v]) s[v] = crossing(mesh.positions[v]);
    std::priority_queue<Piece> pieces;
    for (const auto& t : mesh.triangles) {
        Piece p;
        for (int i = 0; i < 3; ++i) {
            p.q[i] = mesh.positions[t[i]];
            p.s[i] = s[t[i]];
        }
        pieces.push(bounded(p));
    }
    if (pieces.empty() || !out.ok) {
        out.bound = pieces.empty() ? -INFINITY : NAN;
        return out;
    }
    // Step: split the piece with the largest bound into four at its edge midpoints until that
    // bound is within the tolerance of the latest crossing computed.
    while (out.splits < max_splits && pieces.top().bound - out.found > tolerance) {
        const Piece p = pieces.top();
        pieces.pop();
        ++out.splits;
        Vec3 m[3];
        double ms[3];
        for (int i = 0; i < 3; ++i) {
            m[i] = 0.5 * (p.q[i] + p.q[(i + 1) % 3]);  // midpoint of edge i, i + 1
            ms[i] = crossing(m[i]);
        }
        if (!out.ok) {
            out.bound = NAN;
            return out;
        }
        pieces.push(bounded({{p.q[0], m[0], m[2]}, {p.s[0], ms[0], ms[2]}}));
        pieces.push(bounded({{m[0], p.q[1], m[1]}, {ms[0], p.s[1], ms[1]}}));
        pieces.push(bounded({{m[2], m[1], p.q[2]}, {ms[2], ms[1], p.s[2]}}));
        pieces.push(bounded({{m[0], m[1], m[2]}, {ms[0], ms[1], ms[2]}}));
    }
    out.bound = pieces.top().bound;
    return out;
}

}  // namespace mesh4d
