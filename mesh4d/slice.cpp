#include "slice.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "exact_side.h"
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

// Segment count or lattice level from a deviation ratio (chord error falls as 1/n^2): the ratio
// is clamped in double before the conversion, so NaN, infinities and huge ratios give `cap`
// instead of undefined behaviour.
uint32_t levelFor(double current, double ratio, uint32_t cap) {
    const double want = current * std::sqrt(ratio);
    if (!(want < double(cap))) return cap;  // also NaN
    return std::max<uint32_t>(1, uint32_t(std::ceil(want)));
}

struct FrameBuilder {
    const World4D& world;
    const ViewSurface& view;
    const SliceSettings& settings;
    const ViewAnchor anchor;  // the frame's local coordinates (positions relative to the object's apparent origin)
    ApparentMesh out;
    std::vector<Side> side;
    std::vector<uint32_t> vertex_out;     // rest vertex -> output vertex
    std::vector<uint32_t> crossing_out;   // 2 * edge + cap -> output vertex
    // Refinement of each edge: its segment count (0 = not yet decided), and the events and output
    // ids (made on first use) of its inner points from lo to hi, at edge_first[e] .. + segments - 2.
    std::vector<uint32_t> edge_segments, edge_first, edge_ids;
    std::vector<Event> edge_events;
    // Cap crossings on segments of refined mesh edges, keyed by (edge, segment, cap).
    std::map<std::pair<uint64_t, uint64_t>, uint32_t> sub_crossings;
    uint32_t cur_edges[3] = {0, 0, 0};  // mesh edges of the triangle being refined
    bool rest_clip = false;             // at rest, past cone, real caps, tolerance > 0: restPlan
    double rest_tolerance = 0;          // the tolerance restPlan keeps (settings.tolerance is 0 at rest)
    size_t limited_edges = 0;           // edges that reached max_segments before the tolerance

    FrameBuilder(const World4D& w, const ViewSurface& v, const SliceSettings& s)
        : world(w), view(v), settings(s), anchor(viewAnchor(v, w.motion)) {
        out.origin = anchor.origin;
        out.time_origin = anchor.time_origin;
    }

    void addOutput(size_t f, const std::array<uint32_t, 3>& t) {
        // A clip point that fell on a visible corner is that corner (see crossingPoint): the
        // triangle has no area then and is not emitted.
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return;
        out.triangles.push_back(t);
        out.source_triangles.push_back(uint32_t(f));
    }


    uint32_t emit(const Event& e, const Vec3& rest) {
        out.positions.push_back(e.x);
        out.emission_times.push_back(e.t);
        out.rest_points.push_back(rest);
        return uint32_t(out.positions.size() - 1);
    }

    // The exact cut (local coordinates) of the worldline of the rest point with barycentrics `l` on vertices `v`.
    Event surfaceAt(const uint32_t v[3], const double l[3]) const {
        return cutRestLocal(anchor, world.motion, restAt(v, l));
    }

    Vec3 restAt(const uint32_t v[3], const double l[3]) const {
        return world.mesh.positions[v[0]] * l[0] + world.mesh.positions[v[1]] * l[1] + world.mesh.positions[v[2]] * l[2];
    }

    // Step: classify every vertex against the real caps, and cut the worldlines of the rest.
    // With `live` (one flag per chunk), only the vertices of live chunks are looked at.
    void classifyVertices(const std::vector<uint8_t>* live) {
        const size_t nv = world.mesh.positions.size();
        side.assign(nv, Side::Inside);
        vertex_out.assign(nv, kUnset);
        std::vector<uint8_t> needed;
        if (live) {
            needed.assign(nv, 0);
            for (size_t c = 0; c < world.chunks.size(); ++c)
                if ((*live)[c])
                    for (uint32_t f = world.chunks[c].first; f < world.chunks[c].last; ++f)
                        for (uint32_t v : world.mesh.triangles[f]) needed[v] = 1;
        }
        for (size_t i = 0; i < nv; ++i) {
            if (live && !needed[i]) side[i] = Side::NotYet;  // only culled triangles use it
            else if (world.cap_a_real && viewSideSign(view, world.events[2 * i]) < 0) side[i] = Side::NotYet;
            else if (world.cap_b_real && viewSideSign(view, world.events[2 * i + 1]) > 0) side[i] = Side::Gone;
        }
        // Visible vertices first, in input order: when nothing is clipped or refined, output
        // vertex i is the image of input vertex i (unreferenced input vertices aside).
        for (size_t i = 0; i < nv; ++i)
            if (side[i] == Side::Inside && world.vertex_used[i]) vertexPoint(uint32_t(i));
    }

    uint32_t vertexPoint(uint32_t i) {
        if (vertex_out[i] == kUnset) {
            vertex_out[i] = emit(vertexEvent(i), world.mesh.positions[i]);
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
            // The cap passes exactly through a visible end (a frame at the instant the object
            // begins or ends): the clip point is that vertex, not a copy of it.
            if (s == 0 && side[e.lo] == Side::Inside) return slot = vertexPoint(e.lo);
            if (s == 1 && side[e.hi] == Side::Inside) return slot = vertexPoint(e.hi);
            const Vec3 rest = world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s;
            // The crossing event lies on the worldline of `rest` (a worldline meets the view surface
            // once), so its image is the anchored cut of that rest point: relative accuracy however
            // far the object is; only the parameter s carries the absolute events' rounding.
            slot = emit(cutRestLocal(anchor, world.motion, rest), rest);
        }
        return slot;
    }

    // The exact image of vertex i (local coordinates), without emitting it.
    Event vertexEvent(uint32_t i) const { return cutRestLocal(anchor, world.motion, world.mesh.positions[i]); }
    // Its position: the emitted one when the vertex is visible (the same value, computed once).
    Vec3 vertexImage(uint32_t i) const {
        return vertex_out[i] != kUnset ? out.positions[vertex_out[i]] : vertexEvent(i).x;
    }

    // Which side of the real caps a rest point falls on, from its events on both caps.
    Side sideOf(const Event& on_a, const Event& on_b) const {
        if (world.cap_a_real && viewSideSign(view, on_a) < 0) return Side::NotYet;
        if (world.cap_b_real && viewSideSign(view, on_b) > 0) return Side::Gone;
        return Side::Inside;
    }

    // Clip curves on the past cone (objects at rest, see restPlan). On a cap, events are affine in the rest
    // point, and h = viewSide = (t_c - t) - |x - C| is concave along them: negative at every corner
    // of a segment or triangle, it may still be positive inside (a cap curve poking in between
    // samples: the middle of a large triangle seen first). Its excess over the corners' largest
    // value is at most L^2 / (8 d) on a segment and L^2 / (6 d) on a triangle (L: longest side of
    // the cap events, d: their least distance from the camera). This returns how much finer the
    // piece must get, as a ratio in levelFor's sense (<= 1: it cannot hide a crossing). A poke
    // whose h stays below limit^2 / (2 dmin) is ignored: about its top (at distance r0 <= dmin
    // from the camera) h falls off as rho^2 / (2 r0) with the distance rho, so it is narrower
    // than `limit`.
    double hiddenCrossingRatio(const Event* e, const double* h, int n, double limit) const {
        double hmax = -INFINITY, L = 0, dmin = INFINITY, tmax = -INFINITY;
        for (int i = 0; i < n; ++i) {
            if (!(h[i] < 0)) return 0;  // a corner on the inside: no hidden crossing to fear
            hmax = std::max(hmax, h[i]);
            tmax = std::max(tmax, view.t_c - e[i].t);
            dmin = std::min(dmin, norm(e[i].x - view.apex));
            for (int j = i + 1; j < n; ++j) L = std::max(L, norm(e[i].x - e[j].x));
        }
        if (view.kind != ViewKind::PastCone) return 0;  // h is affine on a hyperplane
        const double d = dmin - L;
        if (!(d > 0)) {
            // The camera among the events: h <= t_c - t there; the light has not left any of them
            // yet, or so little time ago that whatever shows is narrower than the limit.
            return tmax <= limit ? 0 : INFINITY;
        }
        const double excess = L * L / ((n == 2 ? 8.0 : 6.0) * d);
        const double narrow = limit * limit / (2 * dmin);
        if (hmax + excess <= narrow) return 0;
        // Twice the ratio that would just pass, so a refined piece clears the bound with margin.
        return 2 * excess / std::max(-hmax, narrow);
    }

    bool capReal(int cap) const { return cap == 0 ? world.cap_a_real : world.cap_b_real; }

    // The cap event of the rest point with barycentrics `l` on vertices `v` (affine in l).
    Event capAt(const uint32_t v[3], const double l[3], int cap) const {
        Event r{0, {0, 0, 0}};
        for (int c = 0; c < 3; ++c) {
            const Event& e = world.events[2 * v[c] + cap];
            r.t += l[c] * e.t;
            r.x += e.x * l[c];
        }
        return r;
    }

    // How much finer the domain must get around the piece (a, b, c) (barycentrics on `v`) for its
    // clip to hold: a real cap's curve may not hide in it or its sides, and where the curve
    // crosses it the straight output edge between the two exact crossings must lie within `limit`
    // of the curve's image (measured at the chord's middle, against the curve point found on the
    // line across the chord there). Ratio as in levelFor; <= 1 when the piece passes.
    double clipRatio(const uint32_t v[3], const double* la, const double* lb, const double* lc, double limit) const {
        if (view.kind != ViewKind::PastCone) return 0;  // hyperplane: straight clip lines, exact crossings
        const double* l[3] = {la, lb, lc};
        double ratio = 0;
        for (int cap = 0; cap < 2; ++cap) {
            if (!capReal(cap)) continue;
            Event e[3];
            double h[3];
            for (int i = 0; i < 3; ++i) {
                e[i] = capAt(v, l[i], cap);
                h[i] = viewSide(view, e[i]);
            }
            ratio = std::max(ratio, hiddenCrossingRatio(e, h, 3, limit));
            // The curve's crossings of the sides; a side with both ends outside may hide two.
            double cross[2][3];
            int found = 0;
            for (int i = 0; i < 3; ++i) {
                const int j = (i + 1) % 3;
                if ((h[i] < 0) == (h[j] < 0)) {
                    const Event se[2] = {e[i], e[j]};
                    const double sh[2] = {h[i], h[j]};
                    ratio = std::max(ratio, hiddenCrossingRatio(se, sh, 2, limit));
                    continue;
                }
                if (found == 2) continue;
                const double t = cutSegment(view, e[i], e[j]);
                for (int k = 0; k < 3; ++k) cross[found][k] = l[i][k] * (1 - t) + l[j][k] * t;
                ++found;
            }
            if (found != 2) continue;
            if (cross[0][1] == cross[1][1] && cross[0][2] == cross[1][2]) continue;  // through a corner: no chord
            double mid[3], across[3];
            for (int k = 0; k < 3; ++k) mid[k] = 0.5 * (cross[0][k] + cross[1][k]);
            // Across the chord in the (u, v) = (l1, l2) parameter plane, as long as the chord.
            const double du = cross[1][1] - cross[0][1], dv = cross[1][2] - cross[0][2];
            across[1] = -dv;
            across[2] = du;
            across[0] = -(across[1] + across[2]);
            double p0[3], p1[3];
            for (int k = 0; k < 3; ++k) {
                p0[k] = mid[k] - across[k];
                p1[k] = mid[k] + across[k];
            }
            const Event q0 = capAt(v, p0, cap), q1 = capAt(v, p1, cap);
            if ((viewSide(view, q0) < 0) == (viewSide(view, q1) < 0)) {
                ratio = std::max(ratio, 4.0);  // the curve bends away by more than the chord: halve it
                continue;
            }
            const double t = cutSegment(view, q0, q1);
            double on[3];
            for (int k = 0; k < 3; ++k) on[k] = p0[k] * (1 - t) + p1[k] * t;
            const Vec3 chord_mid = (surfaceAt(v, cross[0]).x + surfaceAt(v, cross[1]).x) * 0.5;
            const double dev = norm(surfaceAt(v, on).x - chord_mid);
            if (!(dev == dev)) return INFINITY;
            ratio = std::max(ratio, dev / limit);
        }
        return ratio;
    }


    // Step (refinement): split edge `edge` into the fewest equal parameter segments whose exact
    // midpoints lie within T/8 of their chords; decided once per frame, from lo to hi, from the
    // edge alone. The inner points' events are kept; output vertices are made on first use.
    void refineEdge(uint32_t edge) {
        if (edge_segments[edge] != 0) return;
        const Edge& e = world.edges[edge];
        const uint32_t v[3] = {e.lo, e.hi, e.hi};
        const double limit = kEdgeMidpointShare * settings.tolerance;
        const Vec3 y0 = vertexImage(e.lo), y1 = vertexImage(e.hi);
        auto at = [&](double s) {
            const double l[3] = {1 - s, s, 0};
            return surfaceAt(v, l);
        };
        // First guess from the whole edge's midpoint deviation: chord error shrinks as 1/n^2.
        const double dev1 = norm(at(0.5).x - (y0 + y1) * 0.5);
        const uint32_t cap_n = uint32_t(std::max(settings.max_segments, 1));
        int n = dev1 <= limit ? 1 : int(levelFor(1.0, dev1 / limit, cap_n));
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
            if (worst <= limit || n >= settings.max_segments || !(worst == worst)) {
                if (!(worst <= limit)) ++limited_edges;
                break;
            }
            n = std::max(n + 1, int(levelFor(n, worst / limit, cap_n)));
        }
        edge_segments[edge] = uint32_t(n);
        edge_first[edge] = uint32_t(edge_events.size());
        for (int i = 1; i < n; ++i) {
            edge_events.push_back(pts[size_t(i)]);
            edge_ids.push_back(kUnset);
        }
    }

    // Output vertex of inner point k (1 .. n-1, counted from lo) of a refined edge.
    uint32_t edgePoint(uint32_t edge, uint32_t k) {
        uint32_t& id = edge_ids[edge_first[edge] + k - 1];
        if (id == kUnset) {
            const Edge& e = world.edges[edge];
            const double s = double(k) / edge_segments[edge];
            id = emit(edge_events[edge_first[edge] + k - 1], world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s);
        }
        return id;
    }

    // A point of a refined triangle's domain: a corner (vertex id), a refined edge's point (edge,
    // index from lo), or an interior lattice point (barycentrics on the triangle's vertices).
    struct DomainPoint {
        enum Kind : uint8_t { Corner, EdgePoint, Interior } kind = Interior;
        uint32_t a = 0, k = 0;
        double l[3] = {0, 0, 0};
        Side side = Side::Inside;
        uint32_t id = kUnset;
    };

    // The event of a domain point on cap `cap`; edge points are parametrised from lo, as refineEdge does.
    Event capEvent(const DomainPoint& p, const uint32_t v[3], int cap) const {
        if (p.kind == DomainPoint::Corner) return world.events[2 * p.a + cap];
        if (p.kind == DomainPoint::EdgePoint) {
            const Edge& e = world.edges[p.a];
            return lerp(world.events[2 * e.lo + cap], world.events[2 * e.hi + cap], double(p.k) / edge_segments[p.a]);
        }
        Event r{0, {0, 0, 0}};
        for (int c = 0; c < 3; ++c) {
            const Event& e = world.events[2 * v[c] + cap];
            r.t += p.l[c] * e.t;
            r.x += e.x * p.l[c];
        }
        return r;
    }

    Vec3 restOf(const DomainPoint& p, const uint32_t v[3]) const {
        if (p.kind == DomainPoint::Corner) return world.mesh.positions[p.a];
        if (p.kind == DomainPoint::EdgePoint) {
            const Edge& e = world.edges[p.a];
            const double s = double(p.k) / edge_segments[p.a];
            return world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s;
        }
        return restAt(v, p.l);
    }

    // The crossing of the domain segment p -> q with cap `cap`. A segment of a mesh edge is keyed by
    // (edge, segment, cap) and parametrised from lo, so the triangle on the other side of the edge
    // makes the same point; other segments are keyed within the triangle.
    uint32_t subCrossing(const DomainPoint& p, const DomainPoint& q, uint32_t pi, uint32_t qi, const uint32_t v[3], int cap,
                         std::map<std::pair<uint64_t, uint64_t>, uint32_t>& local) {
        uint32_t edge = kUnset, kp = 0, kq = 0;
        auto onEdge = [&](const DomainPoint& d, uint32_t e, uint32_t* k) {
            if (d.kind == DomainPoint::EdgePoint && d.a == e) { *k = d.k; return true; }
            if (d.kind == DomainPoint::Corner && d.a == world.edges[e].lo) { *k = 0; return true; }
            if (d.kind == DomainPoint::Corner && d.a == world.edges[e].hi) { *k = edge_segments[e]; return true; }
            return false;
        };
        const uint32_t candidate = p.kind == DomainPoint::EdgePoint ? p.a : (q.kind == DomainPoint::EdgePoint ? q.a : kUnset);
        if (candidate != kUnset && onEdge(p, candidate, &kp) && onEdge(q, candidate, &kq) &&
            (kp + 1 == kq || kq + 1 == kp))
            edge = candidate;
        if (edge == kUnset && p.kind == DomainPoint::Corner && q.kind == DomainPoint::Corner) {
            // A whole unsplit mesh edge: the vertex-mode crossing, keyed by the edge.
            for (int c = 0; c < 3; ++c) {
                const Edge& e = world.edges[cur_edges[c]];
                if ((e.lo == p.a && e.hi == q.a) || (e.lo == q.a && e.hi == p.a)) return crossingPoint(cur_edges[c], cap);
            }
        }
        std::pair<uint64_t, uint64_t> key;
        const DomainPoint *first = &p, *second = &q;
        if (edge != kUnset) {
            key = {uint64_t(edge) << 1 | 1u, (uint64_t(std::min(kp, kq)) << 1) | uint64_t(cap)};
            if (kq < kp) std::swap(first, second);
            auto it = sub_crossings.find(key);
            if (it != sub_crossings.end()) return it->second;
        } else {
            key = {(uint64_t(std::min(pi, qi)) << 32) | std::max(pi, qi), uint64_t(cap)};
            if (qi < pi) std::swap(first, second);
            auto it = local.find(key);
            if (it != local.end()) return it->second;
        }
        const Event e0 = capEvent(*first, v, cap), e1 = capEvent(*second, v, cap);
        const double s = cutSegment(view, e0, e1);
        uint32_t id;
        if (s == 0 && first->side == Side::Inside && first->id != kUnset) id = first->id;  // as in crossingPoint
        else if (s == 1 && second->side == Side::Inside && second->id != kUnset) id = second->id;
        else {
            const Vec3 rest = restOf(*first, v) * (1 - s) + restOf(*second, v) * s;
            id = emit(cutRestLocal(anchor, world.motion, rest), rest);  // as in crossingPoint
        }
        (edge != kUnset ? sub_crossings : local)[key] = id;
        return id;
    }

    // Step (refinement): one triangle to the tolerance; `clipped` when a real cap cuts it.
    void refineTriangle(size_t f, bool clipped) {
        const auto& tri = world.mesh.triangles[f];
        const uint32_t v[3] = {tri[0], tri[1], tri[2]};
        uint32_t n[3];
        for (int c = 0; c < 3; ++c) {
            cur_edges[c] = world.triangle_edges[f][c];
            refineEdge(cur_edges[c]);
            n[c] = edge_segments[cur_edges[c]];
        }
        const double limit = kMidpointShare * settings.tolerance;
        const Vec3 y[3] = {vertexImage(v[0]), vertexImage(v[1]), vertexImage(v[2])};
        const double third[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
        const double centroid_dev = norm(surfaceAt(v, third).x - (y[0] + y[1] + y[2]) / 3.0);
        if (n[0] == 1 && n[1] == 1 && n[2] == 1 && centroid_dev <= limit) {
            if (clipped) clipWhole(f);
            else addOutput(f, {vertexPoint(v[0]), vertexPoint(v[1]), vertexPoint(v[2])});
            return;
        }
        ++out.refined_triangles;
        const bool caps = world.cap_a_real || world.cap_b_real;

        // The domain is triangulated with each edge's own points and an interior grid of level
        // `level` (tessellate.h); the level grows until every inner chord passes.
        const uint32_t cap_level = uint32_t(std::max(settings.max_segments, 3));
        uint32_t level = levelFor(1.0, centroid_dev / limit, cap_level);
        level = std::max({level, n[0], n[1], n[2], 3u});
        for (;;) {
            level = std::min<uint32_t>(level, cap_level);
            const DomainTriangulation dom = triangulateDomain(n, level);

            // Step: describe every domain point and decide its side; visible boundary points get
            // their (shared) output vertices now, so that a retry below drops interior points only.
            std::vector<DomainPoint> dp(dom.points.size());
            for (int c = 0; c < 3; ++c) {
                const uint32_t edge = cur_edges[c];
                const bool forward = v[c] == world.edges[edge].lo;  // edge points run lo -> hi
                DomainPoint& corner = dp[boundaryIndex(n, c, 0)];
                corner.kind = DomainPoint::Corner;
                corner.a = v[c];
                corner.side = side[v[c]];
                for (uint32_t k = 1; k < n[c]; ++k) {
                    DomainPoint& d = dp[boundaryIndex(n, c, k)];
                    d.kind = DomainPoint::EdgePoint;
                    d.a = edge;
                    d.k = forward ? k : n[c] - k;
                }
            }
            for (size_t p = dom.boundary_count; p < dom.points.size(); ++p) {
                dp[p].l[0] = 1 - dom.points[p][0] - dom.points[p][1];
                dp[p].l[1] = dom.points[p][0];
                dp[p].l[2] = dom.points[p][1];
            }
            for (auto& d : dp)
                if (d.kind != DomainPoint::Corner && caps) d.side = sideOf(capEvent(d, v, 0), capEvent(d, v, 1));
            for (auto& d : dp) {
                if (d.side != Side::Inside) continue;
                if (d.kind == DomainPoint::Corner) d.id = vertexPoint(d.a);
                else if (d.kind == DomainPoint::EdgePoint) d.id = edgePoint(d.a, d.k);
            }
            const size_t first_interior = out.positions.size();
            for (auto& d : dp)
                if (d.kind == DomainPoint::Interior && d.side == Side::Inside) d.id = emit(surfaceAt(v, d.l), restAt(v, d.l));

            // Step: check every visible chord that is not a boundary segment (those passed refineEdge).
            auto isBoundarySegment = [&](uint32_t a, uint32_t b) {
                const size_t nb = dom.boundary_count;
                return a < nb && b < nb && ((a + 1) % nb == b || (b + 1) % nb == a);
            };
            double worst = 0;
            for (const auto& t : dom.triangles) {
                for (int c = 0; c < 3; ++c) {
                    const uint32_t a = t[c], b = t[(c + 1) % 3];
                    if (a > b || isBoundarySegment(a, b) || dp[a].side != Side::Inside || dp[b].side != Side::Inside)
                        continue;  // each inner chord once
                    const double pu = 0.5 * (dom.points[a][0] + dom.points[b][0]);
                    const double pv = 0.5 * (dom.points[a][1] + dom.points[b][1]);
                    const double l[3] = {1 - pu - pv, pu, pv};
                    const Vec3 mid = (out.positions[dp[a].id] + out.positions[dp[b].id]) * 0.5;
                    worst = std::max(worst, norm(surfaceAt(v, l).x - mid));
                }
            }
            if (worst <= limit || level >= cap_level || !(worst == worst)) {
                if (!(worst <= limit)) ++out.limited_triangles;
                emitDomain(f, dom, dp, v);
                return;
            }
            // Too coarse: drop this attempt's interior points and refine the grid.
            out.positions.resize(first_interior);
            out.emission_times.resize(first_interior);
            out.rest_points.resize(first_interior);
            level = std::max(level + 1, levelFor(level, worst / limit, cap_level));
        }
    }

    // Step: the domain's triangles; those a real cap cuts are clipped at exact cap crossings.
    void emitDomain(size_t f, const DomainTriangulation& dom, const std::vector<DomainPoint>& dp, const uint32_t v[3]) {
        std::map<std::pair<uint64_t, uint64_t>, uint32_t> local;
        for (const auto& t : dom.triangles) {
            const Side s[3] = {dp[t[0]].side, dp[t[1]].side, dp[t[2]].side};
            if (s[0] == Side::Inside && s[1] == Side::Inside && s[2] == Side::Inside) {
                addOutput(f, {dp[t[0]].id, dp[t[1]].id, dp[t[2]].id});
                continue;
            }
            if (s[0] == s[1] && s[1] == s[2]) continue;
            uint32_t polygon[6];
            int n = 0;
            for (int c = 0; c < 3; ++c) {
                const uint32_t pi = t[c], qi = t[(c + 1) % 3];
                const Side si = s[c], sj = s[(c + 1) % 3];
                if (si == Side::Inside) polygon[n++] = dp[pi].id;
                if (si == sj) continue;
                const bool cross_a = si == Side::NotYet || sj == Side::NotYet;
                const bool cross_b = si == Side::Gone || sj == Side::Gone;
                const bool a_first = si == Side::NotYet || sj == Side::Gone;
                if (cross_a && cross_b) {
                    polygon[n++] = subCrossing(dp[pi], dp[qi], pi, qi, v, a_first ? 0 : 1, local);
                    polygon[n++] = subCrossing(dp[pi], dp[qi], pi, qi, v, a_first ? 1 : 0, local);
                } else {
                    polygon[n++] = subCrossing(dp[pi], dp[qi], pi, qi, v, cross_a ? 0 : 1, local);
                }
            }
            for (int k = 1; k + 1 < n; ++k) addOutput(f, {polygon[0], polygon[k], polygon[k + 1]});
        }
    }

    // Step: a whole triangle clipped to the span in vertex mode (Sutherland-Hodgman over the caps).
    void clipWhole(size_t f) {
        const auto& tri = world.mesh.triangles[f];
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

    // Step (objects at rest on the past cone, with a real cap, tolerance > 0). The surface is the
    // input itself (the cut is affine), but a cap meets the cone in a sphere, so the clip curves
    // are circles. A triangle a cap may cut is split in four, recursively, where a cap's curve could
    // hide in a piece or its chord through the piece lies farther than T/4 from the circle
    // (clipRatio), at most to 2^-depth of the triangle with 2^depth <= max_segments. Each leaf
    // piece is then a convex polygon: its corners and the corners of finer neighbours on its sides
    // (so the pieces of a triangle meet edge to edge), clipped at exact crossings as in vertex mode.
    // Points and crossings on a mesh edge are keyed by the edge and their place along it, so the
    // two triangles of the edge share those they both make; where the two split the edge
    // differently they meet at T-junctions (the edge is straight: no gap). A whole mesh edge keeps
    // its vertex-mode crossing (crossingPoint).
    static constexpr int kRestDepth = 20;                          // deepest split the keys can hold
    static constexpr int64_t kRestOne = int64_t(1) << kRestDepth;  // barycentric 1 in piece keys
    using Key = std::pair<int64_t, int64_t>;                       // barycentrics on corners 1, 2 (x 2^-20)

    struct RestPiece {
        Key k[3];
    };

    // Points on mesh edges (per frame): (edge, place from lo in 2^-20) -> output vertex, and crossings
    // on a stretch of a mesh edge: (edge, from, to, cap) -> output vertex.
    std::map<std::pair<uint32_t, int64_t>, uint32_t> rest_edge_points;
    std::map<std::pair<std::pair<uint32_t, int64_t>, std::pair<int64_t, int>>, uint32_t> rest_edge_crossings;

    static void barycentrics(const Key& k, double l[3]) {
        l[1] = double(k.first) / double(kRestOne);
        l[2] = double(k.second) / double(kRestOne);
        l[0] = double(kRestOne - k.first - k.second) / double(kRestOne);
    }

    double pieceRatio(const uint32_t v[3], const RestPiece& p, double limit) const {
        double l[3][3];
        for (int c = 0; c < 3; ++c) barycentrics(p.k[c], l[c]);
        return clipRatio(v, l[0], l[1], l[2], limit);
    }

    // The triangle corner a key is, or -1.
    static int cornerOf(const Key& k) {
        if (k.first == 0 && k.second == 0) return 0;
        if (k.first == kRestOne && k.second == 0) return 1;
        if (k.first == 0 && k.second == kRestOne) return 2;
        return -1;
    }

    // Whether a key lies on triangle side s (0: corners 0-1, 1: 1-2, 2: 2-0), and its place along
    // the side from the side's first corner.
    static bool onSide(const Key& k, int s, int64_t* place) {
        if (s == 0 && k.second == 0) { *place = k.first; return true; }
        if (s == 1 && k.first + k.second == kRestOne) { *place = k.second; return true; }
        if (s == 2 && k.first == 0) { *place = kRestOne - k.second; return true; }
        return false;
    }
    // A place along triangle f's side s (from the side's first corner), counted from its mesh
    // edge's lo end instead: the same number for both triangles of the edge.
    int64_t placeFromLo(const uint32_t v[3], int s, uint32_t edge, int64_t place) const {
        return world.edges[edge].lo == v[s] ? place : kRestOne - place;
    }
    // The side a point that is no corner lies on, or -1.
    static int sideOfKey(const Key& k, int64_t* place) {
        for (int s = 0; s < 3; ++s)
            if (onSide(k, s, place)) return s;
        return -1;
    }

    // Pass 1 (restPlan, every triangle): the leaf pieces, and their places along the mesh edges;
    // pass 2 (restEmit, once all triangles are planned): the polygons, with the corners of finer
    // neighbours on every side, also across mesh edges, so the pieces meet edge to edge.
    struct RestPlan {
        size_t f = 0;
        std::vector<RestPiece> leaves;
        std::set<Key> corners;
    };
    std::vector<RestPlan> rest_plans;
    std::map<uint32_t, std::set<int64_t>> rest_edge_places;  // mesh edge -> leaf corners on it (place from lo)

    void restPlan(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const uint32_t v[3] = {tri[0], tri[1], tri[2]};
        const bool agree = side[v[0]] == side[v[1]] && side[v[1]] == side[v[2]];
        if (agree && side[v[0]] == Side::Gone) return;  // h > 0 at the corners of cap b holds inside
        const RestPiece whole{{{0, 0}, {kRestOne, 0}, {0, kRestOne}}};
        const double limit = kMidpointShare * rest_tolerance;
        const double whole_ratio = pieceRatio(v, whole, limit);
        if (agree && side[v[0]] == Side::NotYet && whole_ratio <= 1) return;  // nothing can show yet
        if (!agree || whole_ratio > 1) ++out.clipped_triangles;
        RestPlan plan;
        plan.f = f;
        int max_depth = 0;
        while (max_depth < kRestDepth && (int64_t(1) << (max_depth + 1)) <= std::max(settings.max_segments, 1)) ++max_depth;
        bool limited = false;
        splitPiece(v, whole, whole_ratio, 0, max_depth, limit, &plan.leaves, &plan.corners, &limited);
        if (limited) ++out.limited_triangles;
        for (const Key& k : plan.corners) {
            for (int sd = 0; sd < 3; ++sd) {
                int64_t place = 0;
                if (cornerOf(k) >= 0 || !onSide(k, sd, &place)) continue;
                const uint32_t edge = world.triangle_edges[f][sd];
                rest_edge_places[edge].insert(placeFromLo(v, sd, edge, place));
            }
        }
        rest_plans.push_back(std::move(plan));
    }

    void restEmit(const RestPlan& plan) {
        const size_t f = plan.f;
        const auto& tri = world.mesh.triangles[f];
        const uint32_t v[3] = {tri[0], tri[1], tri[2]};
        for (int c = 0; c < 3; ++c) cur_edges[c] = world.triangle_edges[f][c];
        std::map<Key, uint32_t> points;                                     // inner point -> output vertex
        std::map<std::pair<std::pair<Key, Key>, int>, uint32_t> crossings;  // inner stretch, cap -> output vertex
        std::vector<Key> poly;
        for (const RestPiece& p : plan.leaves) {
            poly.clear();
            for (int c = 0; c < 3; ++c) {
                poly.push_back(p.k[c]);
                hangingCorners(v, p.k[c], p.k[(c + 1) % 3], plan.corners, &poly);
            }
            clipRestPolygon(f, v, poly, points, crossings);
        }
    }

    // The key of the point at `place` along triangle side s from its first corner.
    static Key keyOnSide(int s, int64_t place) {
        if (s == 0) return {place, 0};
        if (s == 1) return {kRestOne - place, place};
        return {0, kRestOne - place};
    }

    void splitPiece(const uint32_t v[3], const RestPiece& p, double ratio, int depth, int max_depth, double limit,
                    std::vector<RestPiece>* leaves, std::set<Key>* corners, bool* limited) const {
        if (ratio > 1 && depth < max_depth) {
            Key m[3];
            for (int c = 0; c < 3; ++c)
                m[c] = {(p.k[c].first + p.k[(c + 1) % 3].first) / 2, (p.k[c].second + p.k[(c + 1) % 3].second) / 2};
            const RestPiece kids[4] = {{{p.k[0], m[0], m[2]}}, {{m[0], p.k[1], m[1]}}, {{m[2], m[1], p.k[2]}},
                                       {{m[0], m[1], m[2]}}};
            for (const RestPiece& kid : kids)
                splitPiece(v, kid, pieceRatio(v, kid, limit), depth + 1, max_depth, limit, leaves, corners, limited);
            return;
        }
        if (ratio > 1) *limited = true;
        leaves->push_back(p);
        for (const Key& k : p.k) corners->insert(k);
    }

    // Corners of other leaves strictly inside the side a -> b, in order: on a mesh edge, those of
    // both triangles of the edge; inside the triangle, those of its finer leaves (which halve the
    // side dyadically).
    void hangingCorners(const uint32_t v[3], const Key& a, const Key& b, const std::set<Key>& corners,
                        std::vector<Key>* out_keys) const {
        for (int sd = 0; sd < 3; ++sd) {
            int64_t pa = 0, pb = 0;
            if (!onSide(a, sd, &pa) || !onSide(b, sd, &pb)) continue;
            const uint32_t edge = cur_edges[sd];
            auto it = rest_edge_places.find(edge);
            if (it == rest_edge_places.end()) return;
            const int64_t qa = placeFromLo(v, sd, edge, pa), qb = placeFromLo(v, sd, edge, pb);
            std::vector<int64_t> between(it->second.upper_bound(std::min(qa, qb)), it->second.lower_bound(std::max(qa, qb)));
            if (qa > qb) std::reverse(between.begin(), between.end());
            for (int64_t q : between) out_keys->push_back(keyOnSide(sd, placeFromLo(v, sd, edge, q)));  // its own inverse
            return;
        }
        innerHanging(a, b, corners, out_keys);
    }

    static void innerHanging(const Key& a, const Key& b, const std::set<Key>& corners, std::vector<Key>* out_keys) {
        if ((a.first + b.first) % 2 != 0 || (a.second + b.second) % 2 != 0) return;
        const Key m{(a.first + b.first) / 2, (a.second + b.second) / 2};
        if (!corners.count(m)) return;
        innerHanging(a, m, corners, out_keys);
        out_keys->push_back(m);
        innerHanging(m, b, corners, out_keys);
    }

    // Output vertex of a piece corner: a mesh vertex, a point on a mesh edge (shared by the edge's
    // triangles), or an inner point of this triangle.
    uint32_t restPoint(const uint32_t v[3], const Key& k, std::map<Key, uint32_t>& points) {
        const int corner = cornerOf(k);
        if (corner >= 0) return vertexPoint(v[corner]);
        double l[3];
        barycentrics(k, l);
        int64_t place = 0;
        const int on = sideOfKey(k, &place);
        uint32_t* id;
        if (on >= 0) {
            const uint32_t edge = cur_edges[on];
            id = &rest_edge_points.try_emplace({edge, placeFromLo(v, on, edge, place)}, kUnset).first->second;
        } else {
            id = &points.try_emplace(k, kUnset).first->second;
        }
        if (*id == kUnset) {
            const Vec3 rest = restAt(v, l);
            *id = emit(cutRestLocal(anchor, world.motion, rest), rest);
        }
        return *id;
    }

    Side restSide(const uint32_t v[3], const Key& k) const {
        const int corner = cornerOf(k);
        if (corner >= 0) return side[v[corner]];
        double l[3];
        barycentrics(k, l);
        return sideOf(capAt(v, l, 0), capAt(v, l, 1));
    }

    // The crossing of the stretch a -> b of a piece's boundary with cap `cap`.
    uint32_t restCrossing(const uint32_t v[3], const Key& a, const Key& b, Side sa, Side sb, int cap,
                          std::map<Key, uint32_t>& points, std::map<std::pair<std::pair<Key, Key>, int>, uint32_t>& crossings) {
        // Parametrised from the smaller key so both pieces along the stretch make the same point.
        const bool forward = a < b;
        const Key& k0 = forward ? a : b;
        const Key& k1 = forward ? b : a;
        const Side s0 = forward ? sa : sb, s1 = forward ? sb : sa;
        // On a mesh edge: keyed by the edge and the stretch's places along it from lo.
        int64_t p0 = 0, p1 = 0;
        int on = -1;
        for (int side_index = 0; side_index < 3 && on < 0; ++side_index)
            if (onSide(k0, side_index, &p0) && onSide(k1, side_index, &p1)) on = side_index;
        // Two triangle corners: a whole mesh edge, whose vertex-mode crossing both triangles use.
        if (on >= 0 && cornerOf(k0) >= 0 && cornerOf(k1) >= 0) return crossingPoint(cur_edges[on], cap);
        uint32_t* id;
        bool flip = false;  // parametrise from the edge's lo end
        if (on >= 0) {
            const uint32_t edge = cur_edges[on];
            int64_t q0 = placeFromLo(v, on, edge, p0), q1 = placeFromLo(v, on, edge, p1);
            if (q1 < q0) {
                std::swap(q0, q1);
                flip = true;
            }
            id = &rest_edge_crossings.try_emplace({{edge, q0}, {q1, cap}}, kUnset).first->second;
        } else {
            id = &crossings.try_emplace({{k0, k1}, cap}, kUnset).first->second;
        }
        if (*id != kUnset) return *id;
        const Key& from = flip ? k1 : k0;
        const Key& to = flip ? k0 : k1;
        const Side sfrom = flip ? s1 : s0, sto = flip ? s0 : s1;
        double l0[3], l1[3];
        barycentrics(from, l0);
        barycentrics(to, l1);
        const double s = cutSegment(view, capAt(v, l0, cap), capAt(v, l1, cap));
        // The cap passes exactly through a visible end: the crossing is that point (as crossingPoint).
        if (s == 0 && sfrom == Side::Inside) return *id = restPoint(v, from, points);
        if (s == 1 && sto == Side::Inside) return *id = restPoint(v, to, points);
        double lm[3];
        for (int c = 0; c < 3; ++c) lm[c] = l0[c] * (1 - s) + l1[c] * s;
        const Vec3 rest = restAt(v, lm);
        return *id = emit(cutRestLocal(anchor, world.motion, rest), rest);
    }

    // One leaf polygon (convex, possibly with straight runs of corners) clipped to the span and
    // emitted: as a fan from its first kept corner when no three consecutive corners are in line,
    // else as a fan about the centre of its corners (no zero-area triangles).
    void clipRestPolygon(size_t f, const uint32_t v[3], const std::vector<Key>& poly, std::map<Key, uint32_t>& points,
                         std::map<std::pair<std::pair<Key, Key>, int>, uint32_t>& crossings) {
        const size_t n = poly.size();
        std::vector<Side> sd(n);
        bool all_inside = true, all_same = true;
        for (size_t i = 0; i < n; ++i) {
            sd[i] = restSide(v, poly[i]);
            all_inside &= sd[i] == Side::Inside;
            all_same &= sd[i] == sd[0];
        }
        if (all_same && !all_inside) return;
        std::vector<uint32_t> ids;
        for (size_t i = 0; i < n; ++i) {
            const size_t j = (i + 1) % n;
            const Side si = sd[i], sj = sd[j];
            if (si == Side::Inside) ids.push_back(restPoint(v, poly[i], points));
            if (si == sj) continue;
            const bool cross_a = si == Side::NotYet || sj == Side::NotYet;
            const bool cross_b = si == Side::Gone || sj == Side::Gone;
            const bool a_first = si == Side::NotYet || sj == Side::Gone;
            if (cross_a && cross_b) {
                ids.push_back(restCrossing(v, poly[i], poly[j], si, sj, a_first ? 0 : 1, points, crossings));
                ids.push_back(restCrossing(v, poly[i], poly[j], si, sj, a_first ? 1 : 0, points, crossings));
            } else {
                ids.push_back(restCrossing(v, poly[i], poly[j], si, sj, cross_a ? 0 : 1, points, crossings));
            }
        }
        // Drop repeats (a crossing that is a kept corner), then triangulate.
        std::vector<uint32_t> ring;
        for (uint32_t id : ids)
            if (ring.empty() || ring.back() != id) ring.push_back(id);
        while (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
        if (ring.size() < 3) return;
        auto inLine = [&](uint32_t a, uint32_t b, uint32_t c) {
            const Vec3 ab = out.positions[b] - out.positions[a], ac = out.positions[c] - out.positions[a];
            return norm(cross(ab, ac)) <= 1e-12 * norm2(ab) + 1e-12 * norm2(ac);
        };
        bool straight_run = false;
        for (size_t i = 0; i < ring.size() && !straight_run; ++i)
            straight_run = inLine(ring[i], ring[(i + 1) % ring.size()], ring[(i + 2) % ring.size()]);
        if (!straight_run) {
            for (size_t k = 1; k + 1 < ring.size(); ++k) addOutput(f, {ring[0], ring[k], ring[k + 1]});
            return;
        }
        Vec3 rest{0, 0, 0};
        for (uint32_t id : ring) rest += out.rest_points[id] * (1.0 / double(ring.size()));
        const uint32_t centre = emit(cutRestLocal(anchor, world.motion, rest), rest);
        for (size_t k = 0; k < ring.size(); ++k) addOutput(f, {centre, ring[k], ring[(k + 1) % ring.size()]});
    }

    // Step: one triangle: whole, refined, or clipped to the span.
    void addTriangle(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const Side s0 = side[tri[0]], s1 = side[tri[1]], s2 = side[tri[2]];
        if (rest_clip) {
            restPlan(f);
            return;
        }
        const bool inside = s0 == Side::Inside && s1 == Side::Inside && s2 == Side::Inside;
        if (!inside && s0 == s1 && s1 == s2) return;  // wholly before or after existence
        if (!inside) ++out.clipped_triangles;
        if (settings.tolerance > 0) refineTriangle(f, !inside);
        else if (inside) addOutput(f, {vertexPoint(tri[0]), vertexPoint(tri[1]), vertexPoint(tri[2])});
        else clipWhole(f);
    }
};

// The 4D-box cull of one run of triangles (SliceSettings::cull): true when some event of the run
// may be visible. On the cone, h = (t_c - t) - |x - C| is at most (t_c - t_lo) - dist(C, box) and
// at least (t_c - t_hi) - maxdist(C, box) over a box; on the hyperplane only the t terms remain.
// The margin covers the rounding of these bounds (a few ulps of the largest term).
bool chunkMayShow(const World4D& world, const ViewSurface& view, const TriangleChunk& c) {
    const bool cone = view.kind == ViewKind::PastCone;
    auto distances = [&](const EventBox& b, double* nearest, double* farthest) {
        double in[3], out[3];
        for (int k = 0; k < 3; ++k) {
            const double p = view.apex[k], lo = b.lo[k], hi = b.hi[k];
            in[k] = p < lo ? lo - p : (p > hi ? p - hi : 0.0);
            out[k] = std::max(std::fabs(p - lo), std::fabs(p - hi));
        }
        *nearest = norm(Vec3{in[0], in[1], in[2]});
        *farthest = norm(Vec3{out[0], out[1], out[2]});
    };
    auto margin = [&](const EventBox& b) {
        const double scale = std::fabs(view.t_c) + std::max(std::fabs(b.t_lo), std::fabs(b.t_hi)) + norm(view.apex) +
                             std::max(norm(b.lo), norm(b.hi));
        return 1e-12 * scale;
    };
    if (world.cap_a_real) {
        const EventBox& a = c.cap[0];
        double nearest = 0, farthest = 0;
        if (cone) distances(a, &nearest, &farthest);
        if ((view.t_c - a.t_lo) - nearest < -margin(a)) return false;  // none has begun existing
    }
    if (world.cap_b_real) {
        const EventBox& b = c.cap[1];
        double nearest = 0, farthest = 0;
        if (cone) distances(b, &nearest, &farthest);
        if ((view.t_c - b.t_hi) - farthest > margin(b)) return false;  // all have ended existing
    }
    return true;
}

}  // namespace

ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view, const SliceSettings& requested) {
    // Model only what the cut requires: on a hyperplane, or at rest, the map from the rest
    // surface to the apparent one is affine, so straight edges are exact and nothing is refined.
    SliceSettings settings = requested;
    // At rest on the past cone with a real cap, the caps' clip curves are circles: those alone
    // are refined (FrameBuilder::restPlan).
    const bool rest_clip = view.kind == ViewKind::PastCone && world.motion.beta == 0 && settings.tolerance > 0 &&
                           (world.cap_a_real || world.cap_b_real);
    if (view.kind == ViewKind::Hyperplane || world.motion.beta == 0) settings.tolerance = 0;
    FrameBuilder b(world, view, settings);
    b.rest_clip = rest_clip;
    b.rest_tolerance = requested.tolerance;
    if (world.empty()) return std::move(b.out);
    // Step: the fast path of vertex mode when nothing is clipped: output vertex i is the image of
    // input vertex i and the triangles are the input's (the same result as below, made in one pass).
    if (settings.tolerance == 0 && !world.cap_a_real && !world.cap_b_real && world.simple) {
        const size_t nv = world.mesh.positions.size(), nt = world.mesh.triangles.size();
        ApparentMesh& out = b.out;
        out.positions.resize(nv);
        out.emission_times.resize(nv);
        cutRestLocalBatch(b.anchor, world.motion, world.mesh.positions.data(), nv, out.positions.data(),
                          out.emission_times.data());
        out.rest_points = world.mesh.positions;
        out.triangles = world.mesh.triangles;
        out.source_triangles.resize(nt);
        for (size_t f = 0; f < nt; ++f) out.source_triangles[f] = uint32_t(f);
        return std::move(b.out);
    }
    // Step: the cull. Only real caps hide anything; without them every worldline meets the view.
    std::vector<uint8_t> live;
    const bool culling = settings.cull && (world.cap_a_real || world.cap_b_real) && !world.chunks.empty();
    if (culling) {
        live.resize(world.chunks.size());
        bool any = false;
        for (size_t c = 0; c < world.chunks.size(); ++c) {
            live[c] = chunkMayShow(world, view, world.chunks[c]);
            any |= live[c] != 0;
            if (!live[c]) b.out.culled_triangles += world.chunks[c].last - world.chunks[c].first;
        }
        if (!any) return std::move(b.out);
    }
    b.out.positions.reserve(world.mesh.positions.size());
    b.out.emission_times.reserve(world.mesh.positions.size());
    b.out.rest_points.reserve(world.mesh.positions.size());
    b.out.triangles.reserve(world.mesh.triangles.size());
    b.out.source_triangles.reserve(world.mesh.triangles.size());
    b.classifyVertices(culling ? &live : nullptr);
    b.crossing_out.assign(2 * world.edges.size(), kUnset);
    if (settings.tolerance > 0) {
        b.edge_segments.assign(world.edges.size(), 0);
        b.edge_first.assign(world.edges.size(), 0);
    }
    if (culling) {
        for (size_t c = 0; c < world.chunks.size(); ++c)
            if (live[c])
                for (uint32_t f = world.chunks[c].first; f < world.chunks[c].last; ++f) b.addTriangle(f);
    } else {
        for (size_t f = 0; f < world.mesh.triangles.size(); ++f) b.addTriangle(f);
    }
    for (const auto& plan : b.rest_plans) b.restEmit(plan);
    b.out.limited_triangles += b.limited_edges;
    return std::move(b.out);
}

Event exactApparentPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    const ViewAnchor anchor = viewAnchor(view, world.motion);
    const Event local = cutRestLocal(anchor, world.motion, q);
    return {anchor.time_origin + local.t, anchor.origin + local.x};
}

BoundingSphere apparentBound(const World4D& world, const ViewSurface& view) {
    const ViewAnchor anchor = viewAnchor(view, world.motion);
    const double b = world.motion.beta;
    const double stretch = view.kind == ViewKind::PastCone ? (1 + b) / world.motion.one_minus_beta2 : 1.0;
    // A relative 1e-9 more for the rounding of the points themselves.
    return {anchor.origin, world.shape_radius * stretch * (1 + 1e-9)};
}

Event exactLocalPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    return cutRestLocal(viewAnchor(view, world.motion), world.motion, q);
}

}  // namespace mesh4d
