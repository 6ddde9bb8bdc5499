// The bisection: conforming longest-edge splits of the pieces whose bound fails (the drain).
#include "mesh4d/cut/frame_builder.h"

namespace mesh4d {
namespace slicing {

void FrameBuilder::reserveTris(size_t n) {
    if (r_tri_size + n <= r_tri_cap) return;
    const size_t cap = std::max(r_tri_size + n, 2 * r_tri_cap);
    std::unique_ptr<RTri[]> grown(new RTri[cap]);
    std::unique_ptr<uint32_t[]> grown_next(new uint32_t[4 * cap]);
    if (r_tri_size > 0) {
        std::memcpy(static_cast<void*>(grown.get()), r_tri.get(), r_tri_size * sizeof(RTri));
        std::memcpy(grown_next.get(), r_next.get(), 4 * r_tri_size * sizeof(uint32_t));
    }
    r_tri = std::move(grown);
    rt = r_tri.get();
    r_next = std::move(grown_next);
    rn = r_next.get();
    r_tri_cap = cap;
}

uint32_t FrameBuilder::newVertex(const Vec3& rest, uint32_t a, uint32_t b, double xm) {
    const uint32_t id = uint32_t(r_terms.size());
    r_terms.push_back({(r_terms[a].s + r_terms[b].s) * 0.5, xm});  // shapeOffset is affine
    r_term_data = r_terms.data();
    r_rest.push_back(rest);
    // Without a real cap every point is inside and is given its output place in bulk.
    if (r_caps) {
        Event cap[2];
        for (int k = 0; k < 2; ++k) {
            const Event ea = capOfId(a, k), eb = capOfId(b, k);
            cap[k] = {0.5 * (ea.t + eb.t), (ea.x + eb.x) * 0.5};  // symmetric in a, b
            r_cap.push_back(cap[k]);
        }
        side.push_back(sideOf(cap[0], cap[1]));
        vertex_out.push_back(kUnset);
    }
    return id;
}

void FrameBuilder::makeEdge(REdge& e, uint32_t a, uint32_t b) const {
    storeEdge(e, edgeBubble(world.motion, r_now, r_term_data[std::min(a, b)], r_term_data[std::max(a, b)]));
}

void FrameBuilder::makeEdgePair(REdge& e0, uint32_t a0, uint32_t b0, REdge& e1, uint32_t a1, uint32_t b1) const {
#if defined(APPARENT_NO_LANES)
    makeEdge(e0, a0, b0);
    makeEdge(e1, a1, b1);
#else
    EdgeBubble eb[2];
    edgeBubbleLanes(world.motion, r_now, r_term_data[std::min(a0, b0)], r_term_data[std::max(a0, b0)],
                    r_term_data[std::min(a1, b1)], r_term_data[std::max(a1, b1)], eb);
    storeEdge(e0, eb[0]);
    storeEdge(e1, eb[1]);
#endif
}

uint32_t FrameBuilder::midVertex(uint32_t id, int c) {
    const uint32_t rec = rt[id].edge[c];
    if (r_edges[rec].mid != kUnset) return r_edges[rec].mid;
    const uint32_t a = rt[id].v[c], b = rt[id].v[kSucc[c]];
    // A mesh edge's midpoint from its lo end, as the edge's other triangles would make it.
    const uint32_t lo = std::min(a, b), hi = std::max(a, b);
    const Vec3 rest = (restOfId(lo) + restOfId(hi)) * 0.5;
    const double xm = edgeOf(id, c).xm_mid;  // made with the edge's bound
    return r_edges[rec].mid = newVertex(rest, lo, hi, xm);
}

void FrameBuilder::moveSlot(uint32_t from, uint32_t to) {
    const uint32_t nx = rn[from];
    if (nx == from) {
        rn[to] = to;
        return;
    }
    rn[to] = nx;
    uint32_t p = nx;
    for (uint32_t q = nextOf(p); q != from; q = nextOf(p)) p = q;
    setNext(p, to);
}

void FrameBuilder::splitEdge(uint32_t id, int c, const uint32_t* members, uint32_t n, std::vector<uint32_t>& stack) {
    const uint32_t m = midVertex(id, c);
    const uint32_t lo = std::min(rt[id].v[c], rt[id].v[kSucc[c]]);
    const uint32_t hi = std::max(rt[id].v[c], rt[id].v[kSucc[c]]);
    uint32_t pending = kUnset, pending_o = 0;  // an inner edge (m, pending_o) waiting for its pair
    const uint32_t lo_rec = uint32_t(r_edges.size()), hi_rec = lo_rec + 1;
    r_edges.resize(r_edges.size() + 2 + n, REdge{kUnset, NAN, NAN, NAN});
    r_edge_data = r_edges.data();
    reserveTris(n);
    uint32_t lo_first = kUnset, lo_prev = kUnset, hi_first = kUnset, hi_prev = kUnset;
    auto link = [&](uint32_t slot, uint32_t& first, uint32_t& prev) {
        if (first == kUnset) first = slot;
        else rn[prev] = slot;
        prev = slot;
    };
    uint32_t inner = hi_rec + 1;
    for (uint32_t k = 0; k < n; ++k) {
        const uint32_t q = members[k];
        const uint32_t u = slotTri(q);
        const int cu = int(slotSide(q)), c1 = kSucc[cu], c2 = kSucc[c1];
        RTri& A = rt[u];
        const uint32_t a = A.v[cu], b = A.v[c1], o = A.v[c2];
        const uint32_t B = uint32_t(r_tri_size++);
        const uint32_t a_half = a == lo ? lo_rec : hi_rec, b_half = a == lo ? hi_rec : lo_rec;
        if (A.depth == 0) ++out.refined_triangles;
        const uint8_t depth = uint8_t(A.depth + 1);
        RTri& Bt = rt[B];
        Bt = RTri{{m, b, o}, {b_half, A.edge[c1], inner}, A.src, depth, kUnknown, -1};
        rn[slotOf(B, 2)] = slotOf(u, c1);
        moveSlot(slotOf(u, c1), slotOf(B, 1));  // the side b -> o goes to B
        A.v[c1] = m;
        rn[slotOf(u, c1)] = slotOf(B, 2);
        A.edge[cu] = a_half;
        A.edge[c1] = inner;
        A.depth = depth;
        A.state = kUnknown;
        A.longest = -1;
        if (a == lo) {
            link(q, lo_first, lo_prev);
            link(slotOf(B, 0), hi_first, hi_prev);
        } else {
            link(slotOf(B, 0), lo_first, lo_prev);
            link(q, hi_first, hi_prev);
        }
        if (pending == kUnset) {
            pending = inner;
            pending_o = o;
        } else {
            makeEdgePair(r_edge_data[pending], m, pending_o, r_edge_data[inner], m, o);
            pending = kUnset;
        }
        ++inner;
        ++r_leaves;  // one piece became two
        stack.push_back(B);
        stack.push_back(u);
    }
    rn[lo_prev] = lo_first;  // close the two cycles
    rn[hi_prev] = hi_first;
    makeEdgePair(r_edge_data[lo_rec], lo, m, r_edge_data[hi_rec], m, hi);
    if (pending != kUnset) makeEdge(r_edge_data[pending], m, pending_o);
}

void FrameBuilder::drain(std::vector<uint32_t>& stack) {
    while (!stack.empty()) {
        const uint32_t id = stack.back();
        stack.pop_back();
        const uint8_t state = rt[id].state;
        if (r_caps) {
            const uint32_t* v = rt[id].v;
            const Side s0 = side[v[0]];
            if (s0 != Side::Inside && side[v[1]] == s0 && side[v[2]] == s0) continue;
        }
        // A piece back on the stack unchanged (its record is reset when it is halved).
        if (state == kPassed || state == kCoarse) continue;
        if (state == kUnknown || state == kBoundFailed) {
            const uint32_t v[3] = {rt[id].v[0], rt[id].v[1], rt[id].v[2]};
            const REdge* e[3] = {&edgeOf(id, 0), &edgeOf(id, 1), &edgeOf(id, 2)};
            const VTerms &k0 = r_term_data[v[0]], &k1 = r_term_data[v[1]], &k2 = r_term_data[v[2]];
            double quadratic;
            if (state == kBoundFailed) {
                quadratic = scratch.quadratic[id];
            } else {
                const double c[3] = {e[0]->c, e[1]->c, e[2]->c};
                const ChordError ce = pointsBound(c, k0, k1, k2);
                if (ce.bound <= settings.tolerance) {
                    rt[id].state = kPassed;
                    continue;
                }
                // The bubbles pass but the third-order term does not.
                if (ce.quadratic <= settings.tolerance && passesByForm(k0.s, k1.s, k2.s)) {
                    rt[id].state = kPassed;
                    continue;
                }
                quadratic = ce.quadratic;
            }
            // (The form is worth making only for a piece that needs a level of kMinLevel or more).
            if (r_templates && quadratic >= 0.5 * kMinLevel * kMinLevel * settings.tolerance &&
                coarseForm(id, std::array<Vec3, 3>{k0.s, k1.s, k2.s}.data(), false)) {
                rt[id].state = kCoarse;
                scratch.coarse.push_back(id);
                continue;
            }
            rt[id].state = kFailed;
            if (rt[id].longest < 0) rt[id].longest = int16_t(longestOf(v, e));
        }
        // A split of a coarser neighbour first (kSplitOther) leaves id as it was.
        for (bool again = true; again;) {
            if (rt[id].depth >= r_max_depth) {
                r_limited[rt[id].src] = 1;
                break;
            }
            if (settings.max_triangles > 0 && r_leaves >= settings.max_triangles) {
                out.over_budget = true;
                stack.clear();
                return;
            }
            const int split = splitLongestPath(id, stack);
            again = split == kSplitOther;
            if (split == kSplitBlocked) {
                // The split would halve a piece a template fills.
                const uint32_t* v = rt[id].v;
                const Vec3 s[3] = {r_term_data[v[0]].s, r_term_data[v[1]].s, r_term_data[v[2]].s};
                if (coarseForm(id, s, true)) {
                    if (forcedTemplatePays(id)) {
                        rt[id].state = kCoarse;
                        scratch.coarse.push_back(id);
                        break;
                    }
                    scratch.form_of[id] = kUnset;
                    scratch.forms.pop_back();
                    scratch.form_aniso.pop_back();
                }
                again = splitLongestPath(id, stack, false) == kSplitOther;
            }
        }
    }
}

int FrameBuilder::longestOf(const uint32_t v[3], const REdge* const e[3]) {
    int best = 0;
    double len = e[0]->len;
    for (int c = 1; c < 3; ++c) {
        const double lc = e[c]->len;
        if (!(lc > len)) {  // (a NaN length is never the longest, as in Rank)
            if (!(lc == len)) continue;
            const Rank r{len, std::min(v[best], v[kSucc[best]]), std::max(v[best], v[kSucc[best]])};
            const Rank rc{lc, std::min(v[c], v[kSucc[c]]), std::max(v[c], v[kSucc[c]])};
            if (!(r < rc)) continue;
        }
        len = lc;
        best = c;
    }
    return best;
}

int FrameBuilder::findLongest(uint32_t id) {
    const REdge* e[3] = {&edgeOf(id, 0), &edgeOf(id, 1), &edgeOf(id, 2)};
    const int best = longestOf(rt[id].v, e);
    rt[id].longest = int16_t(best);
    return best;
}

int FrameBuilder::splitLongestPath(uint32_t id, std::vector<uint32_t>& stack, bool guard) {
    uint32_t t = id;
    for (;;) {
        const int c = longestSlot(t);
        const uint32_t start = slotOf(t, c);
        uint32_t pair[2] = {start, rn[start]};
        const uint32_t* members = pair;
        uint32_t n = 1;
        if (pair[1] != start) {
            const uint32_t p = pair[1], q = slotTri(p);
            if (longestSlot(q) != int(slotSide(p))) {
                t = q;
                continue;
            }
            n = 2;
            const uint32_t after = rn[p];
            if (after != start) {
                std::vector<uint32_t>& more = scratch_members;
                more.assign(pair, pair + 2);
                uint32_t other = kUnset;
                for (uint32_t r = after; r != start; r = nextOf(r)) {
                    if (longestSlot(slotTri(r)) != int(slotSide(r))) {
                        other = slotTri(r);
                        break;
                    }
                    more.push_back(r);
                }
                if (other != kUnset) {
                    t = other;
                    continue;
                }
                members = more.data();
                n = uint32_t(more.size());
            }
        }
        if (guard && r_templates)
            for (uint32_t k = 0; k < n; ++k) {
                const uint32_t u = slotTri(members[k]);
                if (rt[u].state == kCoarse && formLevel(scratch.forms[scratch.form_of[u]], kNoCap) >= kKeptLevel)
                    return kSplitBlocked;
            }
        splitEdge(t, c, members, n, stack);
        return t == id ? kSplitOwn : kSplitOther;
    }
}

}  // namespace slicing
}  // namespace mesh4d
