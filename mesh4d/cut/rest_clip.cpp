// The rest clip (restPlan): objects at rest on the past cone with a real cap and a tolerance.
#include "mesh4d/cut/rest_clip.h"

#include "mesh4d/cut/frame_builder.h"

namespace mesh4d {
namespace slicing {

void barycentrics(const Key& k, double l[3]) {
    l[1] = double(k.first) / double(kRestOne);
    l[2] = double(k.second) / double(kRestOne);
    l[0] = double(kRestOne - k.first - k.second) / double(kRestOne);
}

double FrameBuilder::pieceRatio(const uint32_t v[3], const RestPiece& p, double limit) const {
    double l[3][3];
    for (int c = 0; c < 3; ++c) barycentrics(p.k[c], l[c]);
    return clipRatio(v, l[0], l[1], l[2], limit);
}

int cornerOf(const Key& k) {
    if (k.first == 0 && k.second == 0) return 0;
    if (k.first == kRestOne && k.second == 0) return 1;
    if (k.first == 0 && k.second == kRestOne) return 2;
    return -1;
}

bool onSide(const Key& k, int s, int64_t* place) {
    if (s == 0 && k.second == 0) { *place = k.first; return true; }
    if (s == 1 && k.first + k.second == kRestOne) { *place = k.second; return true; }
    if (s == 2 && k.first == 0) { *place = kRestOne - k.second; return true; }
    return false;
}

int64_t FrameBuilder::placeFromLo(const uint32_t v[3], int s, uint32_t edge, int64_t place) const {
    return world.edges[edge].lo == v[s] ? place : kRestOne - place;
}

int sideOfKey(const Key& k, int64_t* place) {
    for (int s = 0; s < 3; ++s)
        if (onSide(k, s, place)) return s;
    return -1;
}

void FrameBuilder::restPlan(size_t f) {
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

void FrameBuilder::restEmit(const RestPlan& plan) {
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

Key keyOnSide(int s, int64_t place) {
    if (s == 0) return {place, 0};
    if (s == 1) return {kRestOne - place, place};
    return {0, kRestOne - place};
}

void FrameBuilder::splitPiece(const uint32_t v[3], const RestPiece& p, double ratio, int depth, int max_depth, double limit,
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

void FrameBuilder::hangingCorners(const uint32_t v[3], const Key& a, const Key& b, const std::set<Key>& corners,
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

void innerHanging(const Key& a, const Key& b, const std::set<Key>& corners, std::vector<Key>* out_keys) {
    if ((a.first + b.first) % 2 != 0 || (a.second + b.second) % 2 != 0) return;
    const Key m{(a.first + b.first) / 2, (a.second + b.second) / 2};
    if (!corners.count(m)) return;
    innerHanging(a, m, corners, out_keys);
    out_keys->push_back(m);
    innerHanging(m, b, corners, out_keys);
}

uint32_t FrameBuilder::restPoint(const uint32_t v[3], const Key& k, std::map<Key, uint32_t>& points) {
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

Side FrameBuilder::restSide(const uint32_t v[3], const Key& k) const {
    const int corner = cornerOf(k);
    if (corner >= 0) return side[v[corner]];
    double l[3];
    barycentrics(k, l);
    return sideOf(capAt(v, l, 0), capAt(v, l, 1));
}

uint32_t FrameBuilder::restCrossing(const uint32_t v[3], const Key& a, const Key& b, Side sa, Side sb, int cap,
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
    const uint32_t out_id = crossingAt(
        s, sfrom, sto, [&](int end) { return restPoint(v, end == 0 ? from : to, points); },
        [&] {
            double lm[3];
            for (int c = 0; c < 3; ++c) lm[c] = l0[c] * (1 - s) + l1[c] * s;
            return restAt(v, lm);
        });
    return *id = out_id;
}

void FrameBuilder::clipRestPolygon(size_t f, const uint32_t v[3], const std::vector<Key>& poly, std::map<Key, uint32_t>& points,
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
    std::vector<uint32_t> ids(2 * n);
    ids.resize(size_t(clipToSpan(
        int(n), sd.data(), [&](int i) { return restPoint(v, poly[size_t(i)], points); },
        [&](int i, int j, int cap) {
            return restCrossing(v, poly[size_t(i)], poly[size_t(j)], sd[size_t(i)], sd[size_t(j)], cap, points, crossings);
        },
        ids.data())));
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

}  // namespace slicing
}  // namespace mesh4d
