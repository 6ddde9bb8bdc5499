#include "slice.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "robust.h"
#include "tessellate.h"

namespace mesh4d {

namespace {

// Where a vertex's worldline crossing falls relative to the extruded span.
enum class Side : uint8_t { NotYet, Inside, Gone };

constexpr uint32_t kUnset = 0xffffffffu;

// Refinement (see slice.h): each output chord's exact midpoint must lie within this fraction of
// the tolerance, so that the three midpoints of a triangle sum to at most 3/4 of it.
constexpr double kMidpointShare = 0.25;

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
        const double limit = kMidpointShare * settings.tolerance;
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
            out.triangles.push_back({corner[0], corner[1], corner[2]});
            return;
        }
        ++out.refined_triangles;

        // Boundary of the parameter domain (0,0), (M,0), (0,M), counter-clockwise from corner 0,
        // with the output id of each boundary point; edge c runs from corner c to corner c + 1.
        int level = int(std::ceil(std::sqrt(std::max(centroid_dev, 1e-300) / limit)));
        level = std::max<int>(level, int(std::max({n[0], n[1], n[2]})));
        for (;;) {
            level = std::min(level, settings.max_segments);
            // M: a common multiple of every segment count, so every lattice point is an integer.
            double M = double(level);
            for (int c = 0; c < 3; ++c) M = double(std::lcm((long long)M, (long long)n[c]));
            const double corners[3][2] = {{0, 0}, {M, 0}, {0, M}};
            std::vector<std::array<double, 2>> boundary, interior;
            std::vector<uint32_t> ids;
            std::vector<std::array<double, 3>> bary;  // barycentrics of every domain point
            for (int c = 0; c < 3; ++c) {
                boundary.push_back({corners[c][0], corners[c][1]});
                ids.push_back(corner[c]);
                const uint32_t edge = world.triangle_edges[f][c];
                const bool forward = v[c] == world.edges[edge].lo;  // edge points run lo -> hi
                const uint32_t segs = n[c];
                for (uint32_t i = 1; i < segs; ++i) {
                    const uint32_t k = forward ? i : segs - i;  // index along this triangle's edge
                    const double step = M / segs;
                    const double* a = corners[c];
                    const double* b = corners[(c + 1) % 3];
                    // Integer lattice point i steps from a towards b.
                    boundary.push_back({a[0] + (b[0] - a[0]) / M * step * i, a[1] + (b[1] - a[1]) / M * step * i});
                    ids.push_back(edge_points[edge_first[edge] + (k - 1)]);
                }
            }
            for (int i = 1; i < level; ++i)
                for (int j = 1; i + j < level; ++j) interior.push_back({M / level * i, M / level * j});
            const std::vector<std::array<uint32_t, 3>> local = triangulateDomain(boundary, interior);

            // Step: exact points for the interior grid; then check every output chord.
            const size_t first_interior = out.positions.size();
            for (const auto& p : interior) {
                const double l[3] = {1 - (p[0] + p[1]) / M, p[0] / M, p[1] / M};
                ids.push_back(emit(surfaceAt(v, l, cap), restAt(v, l)));
            }
            std::vector<std::array<double, 2>> param(boundary);
            param.insert(param.end(), interior.begin(), interior.end());
            double worst = 0;
            for (const auto& t : local) {
                for (int c = 0; c < 3; ++c) {
                    const uint32_t a = t[c], b = t[(c + 1) % 3];
                    if (a < boundary.size() && b < boundary.size() && (std::max(a, b) - std::min(a, b) == 1 ||
                                                                      std::max(a, b) - std::min(a, b) == boundary.size() - 1))
                        continue;  // a boundary segment: checked by refineEdge
                    const double px = 0.5 * (param[a][0] + param[b][0]), py = 0.5 * (param[a][1] + param[b][1]);
                    const double l[3] = {1 - (px + py) / M, px / M, py / M};
                    const Vec3 mid = (out.positions[ids[a]] + out.positions[ids[b]]) * 0.5;
                    worst = std::max(worst, norm(surfaceAt(v, l, cap).x - mid));
                }
            }
            if (worst <= limit || level >= settings.max_segments) {
                if (worst > limit) ++out.limited_triangles;
                for (const auto& t : local) out.triangles.push_back({ids[t[0]], ids[t[1]], ids[t[2]]});
                return;
            }
            // Too coarse: drop this attempt's interior points and refine the grid.
            out.positions.resize(first_interior);
            out.emission_times.resize(first_interior);
            out.rest_points.resize(first_interior);
            level = std::max(level + 1, int(std::ceil(level * std::sqrt(worst / limit))));
        }
    }

    // Step: one triangle: refined, whole, or clipped to the span (Sutherland-Hodgman over the caps).
    void addTriangle(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const Side s0 = side[tri[0]], s1 = side[tri[1]], s2 = side[tri[2]];
        if (s0 == Side::Inside && s1 == Side::Inside && s2 == Side::Inside) {
            if (settings.tolerance > 0) refineTriangle(f);
            else out.triangles.push_back({vertexPoint(tri[0]), vertexPoint(tri[1]), vertexPoint(tri[2])});
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
        for (int k = 1; k + 1 < n; ++k) out.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
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
