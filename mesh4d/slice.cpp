#include "slice.h"

#include <algorithm>
#include <cmath>

#include "robust.h"
#include "tessellate.h"

namespace mesh4d {

namespace {

// Where a vertex's worldline crossing falls relative to the extruded span.
enum class Side : uint8_t { NotYet, Inside, Gone };

constexpr uint32_t kUnset = 0xffffffffu;

// Refinement (see slice.h): each inner output chord's exact midpoint must lie within this
// fraction of the tolerance, and each segment of a split mesh edge within half of it. A triangle
// of the ring next to an edge spans a whole edge segment, so its inner chords are about as long
// as that segment: the stricter edge limit leaves them room to pass at the inner limit instead of
// forcing an ever finer interior grid. Any output triangle's three midpoints then sum to at most
// 3/4 of the tolerance (at most 5/8 next to an edge).
constexpr double kMidpointShare = 0.25;
constexpr double kEdgeMidpointShare = 0.125;

struct FrameBuilder {
    const World4D& world;
    const ViewSurface& view;
    const SliceSettings& settings;
    const double one_minus_b2;
    ApparentMesh out;
    std::vector<Side> side;
    std::vector<uint32_t> vertex_out;     // rest vertex -> output vertex
    std::vector<uint32_t> crossing_out;   // 2 * edge + cap -> output vertex
    // Refinement of each edge: its segment count (0 = not yet decided) and the output ids of its
    // interior points from lo to hi, at edge_first[e] .. edge_first[e] + segments - 2.
    std::vector<uint32_t> edge_segments, edge_first, edge_points;

    FrameBuilder(const World4D& w, const ViewSurface& v, const SliceSettings& s)
        : world(w), view(v), settings(s), one_minus_b2(oneMinusSquare(w.motion.beta)) {}

    void addOutput(size_t f, const std::array<uint32_t, 3>& t) {
        out.triangles.push_back(t);
        out.source_triangles.push_back(uint32_t(f));
    }

    uint32_t emit(const Event& e, const Vec3& rest) {
        out.positions.push_back(e.x);
        out.emission_times.push_back(e.t);
        out.rest_points.push_back(rest);
        return uint32_t(out.positions.size() - 1);
    }

    // The cap whose events anchor worldlines near vertex i: the one nearer in time to the frame,
    // so that the extrapolation v (t_c - t_anchor) and its absolute rounding stay small.
    int anchorCap(uint32_t i) const {
        return std::fabs(view.t_c - world.events[2 * i].t) <= std::fabs(view.t_c - world.events[2 * i + 1].t) ? 0 : 1;
    }

    // The exact cut of the worldline of the rest point with barycentrics `l` on vertices `v`.
    Event surfaceAt(const uint32_t v[3], const double l[3], int cap) const {
        Event anchor{0, {0, 0, 0}};
        for (int k = 0; k < 3; ++k) {
            const Event& e = world.events[2 * v[k] + cap];
            anchor.t += l[k] * e.t;
            anchor.x += e.x * l[k];
        }
        return cutWorldline(view, anchor, world.motion.velocity, one_minus_b2).event;
    }

    Vec3 restAt(const uint32_t v[3], const double l[3]) const {
        return world.mesh.positions[v[0]] * l[0] + world.mesh.positions[v[1]] * l[1] + world.mesh.positions[v[2]] * l[2];
    }

    // Step: classify every vertex against the real caps, and cut the worldlines of the rest.
    void classifyVertices() {
        const size_t nv = world.mesh.positions.size();
        side.assign(nv, Side::Inside);
        vertex_out.assign(nv, kUnset);
        for (size_t i = 0; i < nv; ++i) {
            if (world.cap_a_real && viewSide(view, world.events[2 * i]) < 0) side[i] = Side::NotYet;
            else if (world.cap_b_real && viewSide(view, world.events[2 * i + 1]) > 0) side[i] = Side::Gone;
        }
        // Visible vertices first, in input order: when nothing is clipped or refined, output
        // vertex i is the image of input vertex i (unreferenced input vertices aside).
        for (size_t i = 0; i < nv; ++i)
            if (side[i] == Side::Inside && world.vertex_used[i]) vertexPoint(uint32_t(i));
    }

    uint32_t vertexPoint(uint32_t i) {
        if (vertex_out[i] == kUnset) {
            const Event& anchor = world.events[2 * i + anchorCap(i)];
            vertex_out[i] = emit(cutWorldline(view, anchor, world.motion.velocity, one_minus_b2).event,
                                 world.mesh.positions[i]);
        }
        return vertex_out[i];
    }

    // The crossing of edge `edge` at cap `cap` (0 = a, 1 = b), always parametrised from the
    // lower vertex id so both triangles of the edge compute the same point.
    uint32_t crossingPoint(uint32_t edge, int cap) {
        uint32_t& slot = crossing_out[2 * edge + cap];
        if (slot == kUnset) {
            const Edge& e = world.edges[edge];
            const Event& p0 = world.events[2 * e.lo + cap];
            const Event& p1 = world.events[2 * e.hi + cap];
            const double s = cutSegment(view, p0, p1);
            const Vec3 rest = world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s;
            slot = emit(lerp(p0, p1, s), rest);
        }
        return slot;
    }

    // Step (refinement): split edge `edge` into the fewest equal parameter segments whose exact
    // midpoints lie within T/4 of their chords; computed once per frame, from lo to hi.
    void refineEdge(uint32_t edge) {
        if (edge_segments[edge] != 0) return;
        const Edge& e = world.edges[edge];
        const uint32_t v[3] = {e.lo, e.hi, e.hi};
        const int cap = anchorCap(e.lo);
        const double limit = kEdgeMidpointShare * settings.tolerance;
        const Vec3 y0 = out.positions[vertexPoint(e.lo)], y1 = out.positions[vertexPoint(e.hi)];
        auto at = [&](double s) {
            const double l[3] = {1 - s, s, 0};
            return surfaceAt(v, l, cap);
        };
        // First guess from the whole edge's midpoint deviation: chord error shrinks as 1/n^2.
        const double dev1 = norm(at(0.5).x - (y0 + y1) * 0.5);
        int n = dev1 <= limit ? 1 : int(std::ceil(std::sqrt(dev1 / limit)));
        std::vector<Event> pts;
        for (;;) {
            n = std::min(n, settings.max_segments);
            pts.assign(size_t(n) + 1, Event{});
            for (int i = 1; i < n; ++i) pts[size_t(i)] = at(double(i) / n);
            pts[0] = {0, y0};
            pts[size_t(n)] = {0, y1};
            double worst = 0;
            for (int i = 0; i < n; ++i)
                worst = std::max(worst, norm(at((i + 0.5) / n).x - (pts[size_t(i)].x + pts[size_t(i) + 1].x) * 0.5));
            if (worst <= limit || n >= settings.max_segments) break;
            n = std::max(n + 1, int(std::ceil(n * std::sqrt(worst / limit))));
        }
        edge_segments[edge] = uint32_t(n);
        edge_first[edge] = uint32_t(edge_points.size());
        for (int i = 1; i < n; ++i) {
            const double s = double(i) / n;
            edge_points.push_back(emit(pts[size_t(i)], world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s));
        }
    }

    // Step (refinement): one whole triangle to the tolerance.
    void refineTriangle(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const uint32_t v[3] = {tri[0], tri[1], tri[2]};
        const uint32_t corner[3] = {vertexPoint(v[0]), vertexPoint(v[1]), vertexPoint(v[2])};
        uint32_t n[3];
        for (int c = 0; c < 3; ++c) {
            refineEdge(world.triangle_edges[f][c]);
            n[c] = edge_segments[world.triangle_edges[f][c]];
        }
        const double limit = kMidpointShare * settings.tolerance;
        const int cap = anchorCap(v[0]);
        const Vec3 y[3] = {out.positions[corner[0]], out.positions[corner[1]], out.positions[corner[2]]};
        const double third[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
        const double centroid_dev = norm(surfaceAt(v, third, cap).x - (y[0] + y[1] + y[2]) / 3.0);
        if (n[0] == 1 && n[1] == 1 && n[2] == 1 && centroid_dev <= limit) {
            addOutput(f, {corner[0], corner[1], corner[2]});
            return;
        }
        ++out.refined_triangles;

        // The domain is triangulated with each edge's own points and an interior grid of level
        // `level` (tessellate.h); the level grows until every inner chord passes.
        uint32_t level = uint32_t(std::ceil(std::sqrt(std::max(centroid_dev, 1e-300) / limit)));
        level = std::max({level, n[0], n[1], n[2], 3u});
        for (;;) {
            level = std::min<uint32_t>(level, uint32_t(std::max(settings.max_segments, 3)));
            const DomainTriangulation dom = triangulateDomain(n, level);

            // Step: output ids of the boundary points (corners and shared edge points) and exact
            // points for the interior lattice.
            std::vector<uint32_t> ids(dom.points.size());
            for (int c = 0; c < 3; ++c) {
                const uint32_t edge = world.triangle_edges[f][c];
                const bool forward = v[c] == world.edges[edge].lo;  // edge points run lo -> hi
                ids[boundaryIndex(n, c, 0)] = corner[c];
                for (uint32_t k = 1; k < n[c]; ++k)
                    ids[boundaryIndex(n, c, k)] = edge_points[edge_first[edge] + (forward ? k : n[c] - k) - 1];
            }
            const size_t first_interior = out.positions.size();
            for (size_t p = dom.boundary_count; p < dom.points.size(); ++p) {
                const double l[3] = {1 - dom.points[p][0] - dom.points[p][1], dom.points[p][0], dom.points[p][1]};
                ids[p] = emit(surfaceAt(v, l, cap), restAt(v, l));
            }

            // Step: check every chord that is not a boundary segment (those passed refineEdge).
            auto isBoundarySegment = [&](uint32_t a, uint32_t b) {
                const size_t nb = dom.boundary_count;
                return a < nb && b < nb && ((a + 1) % nb == b || (b + 1) % nb == a);
            };
            double worst = 0;
            for (const auto& t : dom.triangles) {
                for (int c = 0; c < 3; ++c) {
                    const uint32_t a = t[c], b = t[(c + 1) % 3];
                    if (a > b || isBoundarySegment(a, b)) continue;  // each interior chord once
                    const double pu = 0.5 * (dom.points[a][0] + dom.points[b][0]);
                    const double pv = 0.5 * (dom.points[a][1] + dom.points[b][1]);
                    const double l[3] = {1 - pu - pv, pu, pv};
                    const Vec3 mid = (out.positions[ids[a]] + out.positions[ids[b]]) * 0.5;
                    const double dv = norm(surfaceAt(v, l, cap).x - mid);
                    worst = std::max(worst, dv);
                }
            }
            if (worst <= limit || level >= uint32_t(settings.max_segments)) {
                if (worst > limit) ++out.limited_triangles;
                for (const auto& t : dom.triangles) addOutput(f, {ids[t[0]], ids[t[1]], ids[t[2]]});
                return;
            }
            // Too coarse: drop this attempt's interior points and refine the grid.
            out.positions.resize(first_interior);
            out.emission_times.resize(first_interior);
            out.rest_points.resize(first_interior);
            level = std::max(level + 1, uint32_t(std::ceil(level * std::sqrt(worst / limit))));
        }
    }

    // Step: one triangle: refined, whole, or clipped to the span (Sutherland-Hodgman over the caps).
    void addTriangle(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const Side s0 = side[tri[0]], s1 = side[tri[1]], s2 = side[tri[2]];
        if (s0 == Side::Inside && s1 == Side::Inside && s2 == Side::Inside) {
            if (settings.tolerance > 0) refineTriangle(f);
            else addOutput(f, {vertexPoint(tri[0]), vertexPoint(tri[1]), vertexPoint(tri[2])});
            return;
        }
        if (s0 == s1 && s1 == s2) return;  // wholly before or after existence
        ++out.clipped_triangles;
        uint32_t polygon[6];  // a triangle clipped by a slab has at most 5 corners
        int n = 0;
        for (int c = 0; c < 3; ++c) {
            const uint32_t vi = tri[c], vj = tri[(c + 1) % 3];
            const Side si = side[vi], sj = side[vj];
            const uint32_t edge = world.triangle_edges[f][c];
            if (si == Side::Inside) polygon[n++] = vertexPoint(vi);
            if (si == sj) continue;
            // Caps crossed going from vi to vj, in order along the edge.
            const bool cross_a = si == Side::NotYet || sj == Side::NotYet;
            const bool cross_b = si == Side::Gone || sj == Side::Gone;
            const bool a_first = si == Side::NotYet || sj == Side::Gone;
            if (cross_a && cross_b) {
                polygon[n++] = crossingPoint(edge, a_first ? 0 : 1);
                polygon[n++] = crossingPoint(edge, a_first ? 1 : 0);
            } else {
                polygon[n++] = crossingPoint(edge, cross_a ? 0 : 1);
            }
        }
        // Fan over the clipped polygon, convex in the triangle's parameter domain.
        for (int k = 1; k + 1 < n; ++k) addOutput(f, {polygon[0], polygon[k], polygon[k + 1]});
    }
};

}  // namespace

ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view, const SliceSettings& settings) {
    FrameBuilder b(world, view, settings);
    if (world.empty()) return std::move(b.out);
    b.classifyVertices();
    b.crossing_out.assign(2 * world.edges.size(), kUnset);
    if (settings.tolerance > 0) {
        b.edge_segments.assign(world.edges.size(), 0);
        b.edge_first.assign(world.edges.size(), 0);
    }
    for (size_t f = 0; f < world.mesh.triangles.size(); ++f) b.addTriangle(f);
    return std::move(b.out);
}

Event exactApparentPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    const Event anchor = labFromRest(world.motion, 0.0, q);
    return cutWorldline(view, anchor, world.motion.velocity, oneMinusSquare(world.motion.beta)).event;
}

}  // namespace mesh4d
