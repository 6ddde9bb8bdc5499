#include "worldline_refine.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "key_split.h"
#include "mesh4d/motion/worldline.h"
#include "worldline_bound.h"

namespace mesh4d {

namespace {

constexpr uint32_t kUnset = 0xffffffffu;
constexpr int kMaxSubGrid = 16;  // the finest measuring sub-grid of one piece (worldline_refine.h)

// A point of a piece's polygon: a grid node (i, j) of its mesh triangle's level, or a finer point
// k (from the edge's lower vertex) of mesh edge e, or the piece's centroid.
struct PNode {
    enum Kind : uint8_t { Grid, EdgePoint, Centroid } kind = Grid;
    uint32_t a = 0, b = 0;
    Vec3 q;
};

struct Refiner {
    const World4D& world;
    const ViewSurface& view;
    const SliceSettings& settings;
    const ViewAnchor anchor;
    const Motion& m;
    const double shear;
    const double T;
    int max_level = 2;
    std::vector<int> level;        // per mesh triangle
    std::vector<int> edge_level;   // per mesh edge
    std::vector<uint8_t> limited;  // per mesh triangle: the level stopped at max_level
    std::vector<std::vector<uint32_t>> edge_triangles;  // per mesh edge: the triangles around it
    std::unordered_map<uint64_t, CornerCrossing> cache;  // crossing()'s, for triangle cache_f
    size_t cache_f = size_t(-1);
    bool over_budget = false;

    Refiner(const World4D& w, const ViewSurface& v, const SliceSettings& s)
        : world(w), view(v), settings(s), anchor(viewAnchor(v, w.motion)), m(w.motion), shear(norm(v.shear)),
          T(s.tolerance) {
        const int segs = std::max(2, s.max_segments);
        while (max_level < segs && max_level < (1 << 20)) max_level *= 2;
    }

    bool degenerate(size_t f) const {
        const auto& t = world.mesh.triangles[f];
        return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    }
    const Vec3& vertex(uint32_t v) const { return world.mesh.positions[v]; }

    // The point at fraction phi (exact: k / 2^p) from va toward vb, computed from the lower id.
    Vec3 edgePoint(uint32_t va, uint32_t vb, double phi) const {
        if (va < vb) return vertex(va) + (vertex(vb) - vertex(va)) * phi;
        return vertex(vb) + (vertex(va) - vertex(vb)) * (1 - phi);
    }
    // Grid node (i, j) of triangle f at level n: corners, side points from their edge, or interior.
    Vec3 nodePoint(size_t f, int n, int i, int j) const {
        const auto& t = world.mesh.triangles[f];
        if (i == 0 && j == 0) return vertex(t[0]);
        if (i == n && j == 0) return vertex(t[1]);
        if (i == 0 && j == n) return vertex(t[2]);
        if (j == 0) return edgePoint(t[0], t[1], double(i) / n);
        if (i + j == n) return edgePoint(t[1], t[2], double(j) / n);
        if (i == 0) return edgePoint(t[2], t[0], double(n - j) / n);
        const Vec3 A = vertex(t[0]);
        return A + (vertex(t[1]) - A) * (double(i) / n) + (vertex(t[2]) - A) * (double(j) / n);
    }

    CornerCrossing cut(const Vec3& q) const {
        bool ok = true;
        CornerCrossing c = cornerCrossing(view, m, q, &ok);
        if (!ok) c.lambda = -1;  // no bound: the piece fails (NaN or infinite input only)
        return c;
    }
    // The output point of a crossing in the local coordinates of the output (sheared as sliceWorld's).
    Vec3 image(const CornerCrossing& c) const {
        return (c.event.x - anchor.origin) - view.shear * (c.event.t - anchor.time_origin);
    }

    // Where a piece lies in its mesh triangle's grid, so that its sub-grid points are that grid's
    // points at a finer level (cached across levels, crossing()); none for a fan piece.
    struct Placement {
        size_t f;
        int n;  // 0: not on the grid
        int i, j;
        bool down;
    };

    // worldline_refine.h's test of one piece with exact corners.
    bool piecePasses(const CornerCrossing c[3], const Placement& at_grid) {
        double d2 = 0;
        for (int i = 0; i < 3; ++i) d2 = std::max(d2, norm2(c[(i + 1) % 3].q - c[i].q));
        const PieceBound whole = pieceBound(m, view, shear, c);
        if (whole.K * d2 / 6 + whole.kink <= T) return true;
        const Vec3 F[3] = {image(c[0]), image(c[1]), image(c[2])};
        std::vector<CornerCrossing> g, coarse;
        double eps = 0;  // measured at the points of every sub-grid so far (each holds the one before)
        for (int sub = 2; sub <= kMaxSubGrid; sub *= 2) {
            // The sub-grid's exact points (those of the sub-grid before taken over: the same
            // barycentrics, exactly) and the largest measured |F - L| there.
            coarse.swap(g);
            g.assign(size_t(sub + 1) * (sub + 1), CornerCrossing{});
            auto at = [&](int a, int b) -> CornerCrossing& { return g[size_t(b) * (sub + 1) + a]; };
            for (int b = 0; b <= sub; ++b)
                for (int a = 0; a + b <= sub; ++a) {
                    if (a + b == 0) at(a, b) = c[0];
                    else if (a == sub) at(a, b) = c[1];
                    else if (b == sub) at(a, b) = c[2];
                    else if (sub > 2 && a % 2 == 0 && b % 2 == 0) at(a, b) = coarse[size_t(b / 2) * (sub / 2 + 1) + a / 2];
                    else {
                        const double l1 = double(a) / sub, l2 = double(b) / sub, l0 = 1 - l1 - l2;
                        if (at_grid.n > 0) {
                            const int I = at_grid.down ? (at_grid.i + 1) * sub - b : at_grid.i * sub + a;
                            const int J = at_grid.down ? at_grid.j * sub + a + b : at_grid.j * sub + b;
                            at(a, b) = crossing(at_grid.f, at_grid.n * sub, I, J);
                        } else {
                            at(a, b) = cut(c[0].q * l0 + c[1].q * l1 + c[2].q * l2);
                        }
                        eps = std::max(eps, norm(image(at(a, b)) - (F[0] * l0 + F[1] * l1 + F[2] * l2)));
                    }
                }
            if (!(eps <= T)) return false;  // measured over: no finer sub-grid can pass it
            // What lies between: each sub-piece's own bound K (its corners exact, its side d / sub).
            const double scale = d2 / (6.0 * sub * sub);
            double rem = 0;
            auto bound = [&](const CornerCrossing piece[3]) {
                const PieceBound pb = pieceBound(m, view, shear, piece);
                return pb.K * scale + pb.kink;
            };
            for (int b = 0; b < sub && eps + rem <= T; ++b)
                for (int a = 0; a + b < sub && eps + rem <= T; ++a) {
                    const CornerCrossing up[3] = {at(a, b), at(a + 1, b), at(a, b + 1)};
                    rem = std::max(rem, bound(up));
                    if (a + b + 1 < sub) {
                        const CornerCrossing down[3] = {at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)};
                        rem = std::max(rem, bound(down));
                    }
                }
            if (eps + rem <= T) return true;
        }
        return false;
    }

    // Triangle f at level n: true when every grid piece passes.
    bool gridPasses(size_t f, int n) {
        std::vector<CornerCrossing> g(size_t(n + 1) * (n + 1));
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i + j <= n; ++i) g[size_t(j) * (n + 1) + i] = crossing(f, n, i, j);
        auto at = [&](int i, int j) -> const CornerCrossing& { return g[size_t(j) * (n + 1) + i]; };
        for (int j = 0; j < n; ++j)
            for (int i = 0; i + j < n; ++i) {
                const CornerCrossing up[3] = {at(i, j), at(i + 1, j), at(i, j + 1)};
                if (!piecePasses(up, {f, n, i, j, false})) return false;
                if (i + j + 1 < n) {
                    const CornerCrossing down[3] = {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
                    if (!piecePasses(down, {f, n, i, j, true})) return false;
                }
            }
        return true;
    }

    // The crossing of grid node (i, j) of triangle f at level n, cached for the triangle being
    // leveled (cache_f) by its place at the finest level a test can reach.
    CornerCrossing crossing(size_t f, int n, int i, int j) {
        if (cache_f != f) {
            cache.clear();
            cache_f = f;
        }
        const uint64_t scale = uint64_t(max_level) * kMaxSubGrid / uint64_t(n);
        const uint64_t key = (uint64_t(i) * scale) << 32 | (uint64_t(j) * scale);
        const auto hit = cache.find(key);
        if (hit != cache.end()) return hit->second;
        const CornerCrossing c = cut(nodePoint(f, n, i, j));
        cache.emplace(key, c);
        return c;
    }

    // The polygon of the up piece (i, j) of triangle f at its level: its corners and, on the sides
    // that lie on a mesh edge cut finer, the edge's points. Returns the number of sides with such
    // points and the last one in *side.
    int upPolygon(size_t f, int i, int j, std::vector<PNode>* poly, int* side) const {
        const int n = level[f];
        const auto& t = world.mesh.triangles[f];
        const int corner[3][2] = {{i, j}, {i + 1, j}, {i, j + 1}};
        const bool on_edge[3] = {j == 0, i + j + 1 == n, i == 0};
        const int along0[3] = {i, j, n - j - 1};  // the side's start, in steps of 1/n from mesh corner c
        poly->clear();
        int with = 0;
        for (int c = 0; c < 3; ++c) {
            PNode p;
            p.kind = PNode::Grid;
            p.a = uint32_t(corner[c][0]);
            p.b = uint32_t(corner[c][1]);
            p.q = nodePoint(f, n, corner[c][0], corner[c][1]);
            poly->push_back(p);
            if (!on_edge[c]) continue;
            const uint32_t e = world.triangle_edges[f][c];
            const int ne = edge_level[e];
            if (ne <= n) continue;
            const int ratio = ne / n;
            const uint32_t va = t[c], vb = t[(c + 1) % 3];
            for (int k = 1; k < ratio; ++k) {
                const int fine = along0[c] * ratio + k;  // from mesh corner c
                PNode e_pt;
                e_pt.kind = PNode::EdgePoint;
                e_pt.a = e;
                e_pt.b = uint32_t(va < vb ? fine : ne - fine);
                e_pt.q = edgePoint(va, vb, double(fine) / ne);
                poly->push_back(e_pt);
            }
            ++with;
            *side = c;
        }
        return with;
    }

    // The triangles (indices into poly; poly.size() is the centroid) that cover the up piece:
    // itself; a fan from the corner opposite `side`, the one side with points; or a fan from the centroid.
    static void pieceTriangles(const std::vector<PNode>& poly, int with, int side,
                               std::vector<std::array<uint32_t, 3>>* tris) {
        tris->clear();
        const uint32_t np = uint32_t(poly.size());
        if (with == 0) {
            tris->push_back({0, 1, 2});
            return;
        }
        if (with == 1) {
            uint32_t opp = 0;  // the polygon index of corner side + 2
            for (uint32_t k = 0, corner = 0; k < np; ++k)
                if (poly[k].kind == PNode::Grid && int(corner++) == (side + 2) % 3) opp = k;
            // From opp the polygon runs: corner side, the side's points, corner side + 1, back to opp.
            for (uint32_t k = 1; k + 1 < np; ++k) tris->push_back({(opp + k) % np, (opp + k + 1) % np, opp});
            return;
        }
        for (uint32_t k = 0; k < np; ++k) tris->push_back({k, (k + 1) % np, np});
    }

    // Pieces with finer points on their sides pass as fans; doubles the level of triangles where
    // one does not. True when some level changed.
    // Only triangles marked in `dirty` (cleared here) are checked; the neighbours of a triangle
    // whose level grows are marked for the next pass.
    bool checkFans(size_t* total, std::vector<uint8_t>* dirty) {
        bool changed = false;
        std::vector<PNode> poly;
        std::vector<std::array<uint32_t, 3>> tris;
        std::vector<CornerCrossing> cuts;
        std::vector<uint32_t> grown;
        for (size_t f = 0; f < world.mesh.triangles.size(); ++f) {
            if (degenerate(f) || !(*dirty)[f]) continue;
            (*dirty)[f] = 0;
            const int n = level[f];
            bool finer = false;
            for (int c = 0; c < 3; ++c) finer |= edge_level[world.triangle_edges[f][c]] > n;
            if (!finer) continue;
            bool ok = true;
            for (int j = 0; j < n && ok; ++j)
                for (int i = 0; i + j < n && ok; ++i) {
                    if (!(j == 0 || i == 0 || i + j + 1 == n)) continue;
                    int side = 0;
                    const int with = upPolygon(f, i, j, &poly, &side);
                    if (with == 0) continue;
                    pieceTriangles(poly, with, side, &tris);
                    cuts.clear();
                    for (const PNode& p : poly) cuts.push_back(cut(p.q));
                    if (with > 1) cuts.push_back(cut(centroidOf(f, i, j)));
                    for (const auto& t : tris) {
                        const CornerCrossing c3[3] = {cuts[t[0]], cuts[t[1]], cuts[t[2]]};
                        if (!piecePasses(c3, {f, 0, 0, 0, false})) {
                            ok = false;
                            break;
                        }
                    }
                }
            if (ok) continue;
            if (!grow(f, total)) continue;
            changed = true;
            grown.push_back(uint32_t(f));
        }
        for (uint32_t f : grown)
            for (int c = 0; c < 3; ++c)
                for (uint32_t g : edge_triangles[world.triangle_edges[f][c]]) (*dirty)[g] = 1;
        return changed;
    }

    Vec3 centroidOf(size_t f, int i, int j) const {
        const int n = level[f];
        return (nodePoint(f, n, i, j) + nodePoint(f, n, i + 1, j) + nodePoint(f, n, i, j + 1)) / 3.0;
    }

    // Doubles triangle f's level if the limits allow; false (and the limit noted) when not.
    bool grow(size_t f, size_t* total) {
        const int n = level[f];
        if (2 * n > max_level) {
            limited[f] = 1;
            return false;
        }
        const size_t more = size_t(3) * size_t(n) * size_t(n);
        if (settings.max_triangles > 0 && *total + more > settings.max_triangles) {
            over_budget = true;
            return false;
        }
        *total += more;
        level[f] = 2 * n;
        return true;
    }

    void takeEdgeLevels() {
        std::fill(edge_level.begin(), edge_level.end(), 1);
        for (size_t f = 0; f < world.mesh.triangles.size(); ++f) {
            if (degenerate(f)) continue;
            for (int c = 0; c < 3; ++c) {
                int& e = edge_level[world.triangle_edges[f][c]];
                e = std::max(e, level[f]);
            }
        }
    }

    ApparentMesh run() {
        const size_t nt = world.mesh.triangles.size();
        level.assign(nt, 1);
        limited.assign(nt, 0);
        edge_level.assign(world.edges.size(), 1);
        size_t total = 0;
        for (size_t f = 0; f < nt; ++f) total += degenerate(f) ? 0 : 1;
        // Step: each triangle's level, doubled until its grid passes.
        for (size_t f = 0; f < nt; ++f) {
            if (degenerate(f)) continue;
            while (!gridPasses(f, level[f]))
                if (!grow(f, &total)) break;
        }
        // Step: conforming edges; fans tested, levels raised where one fails, until stable.
        edge_triangles.assign(world.edges.size(), {});
        for (size_t f = 0; f < nt; ++f)
            if (!degenerate(f))
                for (int c = 0; c < 3; ++c) edge_triangles[world.triangle_edges[f][c]].push_back(uint32_t(f));
        std::vector<uint8_t> dirty(nt, 1);
        do takeEdgeLevels();
        while (checkFans(&total, &dirty));
        return emit();
    }

    ApparentMesh emit() {
        ApparentMesh out;
        out.origin = anchor.origin;  // unsheared: sliceWorld applies the shear
        out.time_origin = anchor.time_origin;
        std::vector<Vec3> rest;
        // Used vertices in input order, then edge points by edge.
        std::vector<uint32_t> vertex_out(world.mesh.positions.size(), kUnset);
        for (size_t v = 0; v < world.mesh.positions.size(); ++v)
            if (world.vertex_used.empty() || world.vertex_used[v]) {
                vertex_out[v] = uint32_t(rest.size());
                rest.push_back(world.mesh.positions[v]);
            }
        std::vector<uint32_t> edge_base(world.edges.size(), kUnset);
        for (size_t e = 0; e < world.edges.size(); ++e) {
            const int ne = edge_level[e];
            if (ne <= 1) continue;
            edge_base[e] = uint32_t(rest.size());
            const Edge& ed = world.edges[e];
            for (int k = 1; k < ne; ++k) rest.push_back(edgePoint(ed.lo, ed.hi, double(k) / ne));
        }
        std::vector<uint32_t> interior;
        std::vector<PNode> poly;
        std::vector<std::array<uint32_t, 3>> tris;
        std::vector<uint32_t> ids;
        for (size_t f = 0; f < world.mesh.triangles.size(); ++f) {
            if (degenerate(f)) continue;
            const int n = level[f];
            const auto& t = world.mesh.triangles[f];
            if (limited[f]) ++out.limited_triangles;
            bool fanned = false;
            interior.assign(size_t(n + 1) * (n + 1), kUnset);
            auto gridId = [&](int i, int j) -> uint32_t {
                if (i == 0 && j == 0) return vertex_out[t[0]];
                if (i == n && j == 0) return vertex_out[t[1]];
                if (i == 0 && j == n) return vertex_out[t[2]];
                int c = -1, along = 0;
                if (j == 0) c = 0, along = i;
                else if (i + j == n) c = 1, along = j;
                else if (i == 0) c = 2, along = n - j;
                if (c >= 0) {
                    const uint32_t e = world.triangle_edges[f][c];
                    const int ne = edge_level[e], fine = along * (ne / n);
                    const uint32_t va = t[c], vb = t[(c + 1) % 3];
                    return edge_base[e] + uint32_t(va < vb ? fine : ne - fine) - 1;
                }
                uint32_t& id = interior[size_t(j) * (n + 1) + i];
                if (id == kUnset) {
                    id = uint32_t(rest.size());
                    rest.push_back(nodePoint(f, n, i, j));
                }
                return id;
            };
            for (int j = 0; j < n; ++j)
                for (int i = 0; i + j < n; ++i) {
                    int side = 0;
                    const int with = (j == 0 || i == 0 || i + j + 1 == n) ? upPolygon(f, i, j, &poly, &side) : 0;
                    if (with == 0) {
                        out.triangles.push_back({gridId(i, j), gridId(i + 1, j), gridId(i, j + 1)});
                        out.source_triangles.push_back(uint32_t(f));
                    } else {
                        fanned = true;
                        pieceTriangles(poly, with, side, &tris);
                        ids.clear();
                        for (const PNode& p : poly)
                            ids.push_back(p.kind == PNode::Grid ? gridId(int(p.a), int(p.b)) : edge_base[p.a] + p.b - 1);
                        if (with > 1) {
                            ids.push_back(uint32_t(rest.size()));
                            rest.push_back(centroidOf(f, i, j));
                        }
                        for (const auto& tr : tris) {
                            out.triangles.push_back({ids[tr[0]], ids[tr[1]], ids[tr[2]]});
                            out.source_triangles.push_back(uint32_t(f));
                        }
                    }
                    if (i + j + 1 < n) {
                        out.triangles.push_back({gridId(i + 1, j), gridId(i + 1, j + 1), gridId(i, j + 1)});
                        out.source_triangles.push_back(uint32_t(f));
                    }
                }
            if (n > 1 || fanned) ++out.refined_triangles;
        }
        // Step: every output point's exact crossing, in the local coordinates of cutRestLocal.
        out.positions.resize(rest.size());
        out.emission_times.resize(rest.size());
        for (size_t i = 0; i < rest.size(); ++i) {
            const Event e = cutRestLocal(anchor, m, rest[i]);
            out.positions[i] = e.x;
            out.emission_times[i] = e.t;
        }
        out.rest_points = std::move(rest);
        out.over_budget = over_budget;
        return out;
    }
};

}  // namespace

ApparentMesh refineWorldlines(const World4D& world, const ViewSurface& view, const SliceSettings& settings) {
    if (!world.motion.keyed) {
        Refiner r(world, view, settings);
        return r.run();
    }
    // A keyframed path: split along the keys' curves first (key_split.h), then the grids on the
    // split mesh; its triangles report the input triangle they lie in.
    KeySplit split = splitAlongKeys(world, view, settings);
    const World4D fine = extrude(std::move(split.mesh), world.motion, world.tau_a, world.tau_b, false, false);
    Refiner r(fine, view, settings);
    ApparentMesh out = r.run();
    std::vector<uint32_t> count(world.mesh.triangles.size(), 0);
    for (uint32_t& f : out.source_triangles) ++count[f = split.source[f]];
    for (size_t f = 0; f < fine.mesh.triangles.size(); ++f) split.limited[split.source[f]] |= r.limited[f];
    out.refined_triangles = size_t(std::count_if(count.begin(), count.end(), [](uint32_t c) { return c > 1; }));
    out.limited_triangles = size_t(std::count(split.limited.begin(), split.limited.end(), uint8_t(1)));
    out.over_budget = out.over_budget || split.over_budget;
    return out;
}

}  // namespace mesh4d
