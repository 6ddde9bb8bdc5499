// The bisection: conforming longest-edge splits of the pieces whose bound fails (the drain).
#include "mesh4d/refine/bisect.h"
#include "mesh4d/refine/templates.h"

namespace mesh4d {
namespace slicing {

void FrameBuilder::makeEdge(REdge& e, uint32_t a, uint32_t b) const {
    storeEdge(e, edgeBubble(world.motion, r_now, r_term_data[std::min(a, b)], r_term_data[std::max(a, b)]));
}

void FrameBuilder::splitEdge(uint32_t id, int c, const uint32_t* members, uint32_t n, std::vector<uint32_t>& stack) {
    const uint32_t m = midVertex(id, c);
    const uint32_t lo = std::min(rt[id].v[c], rt[id].v[kSucc[c]]);
    const uint32_t hi = std::max(rt[id].v[c], rt[id].v[kSucc[c]]);
    uint32_t pending = kUnset, pending_o = 0;  // an inner edge (m, pending_o) waiting for its pair
    const uint32_t lo_rec = uint32_t(r_edges.size()), hi_rec = lo_rec + 1;
    const uint32_t parent = rt[id].edge[c];
    const uint32_t on = parent < r_ne ? parent : r_edge_data[parent].on;  // the halves lie on the parent's mesh edge
    r_edges.resize(r_edges.size() + 2 + n, REdge{kUnset, kUnset, NAN, NAN, NAN});
    r_edge_data = r_edges.data();
    r_edge_data[lo_rec].on = r_edge_data[hi_rec].on = on;
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
        // A face containing v (slide_bound.h): judged on its rim, never filled by a template.
        const bool slide = r_slide && slides(rt[id].src);
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
                if (slide && ce.bound <= settings.attribute_tolerance) {
                    const double len[3] = {e[0]->len, e[1]->len, e[2]->len};
                    const double xm_mid[3] = {e[0]->xm_mid, e[1]->xm_mid, e[2]->xm_mid};
                    if (rimPasses(rt[id].src, v, rt[id].edge, c, len, xm_mid)) {
                        rt[id].state = kPassed;
                        continue;
                    }
                }
                // The bubbles pass but the third-order term does not.
                if (ce.quadratic <= settings.tolerance && passesByForm(k0.s, k1.s, k2.s)) {
                    rt[id].state = kPassed;
                    continue;
                }
                quadratic = ce.quadratic;
            }
            // (The form is worth making only for a piece that needs a level of kMinLevel or more).
            if (r_templates && !slide && quadratic >= 0.5 * kMinLevel * kMinLevel * settings.tolerance &&
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
            if (split == kSplitBlocked && slide) {
                again = splitLongestPath(id, stack, false) == kSplitOther;
            } else if (split == kSplitBlocked) {
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
