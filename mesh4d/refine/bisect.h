// The bisection's inline parts (refine/bisect.cpp holds the rest): the growth of the triangle
// records and the look-ups and small steps the drain's hot loops call (FrameBuilder's members,
// declared with the records in mesh4d/cut/frame_builder.h), defined inline here for the files
// that call them: refine/first_pass.cpp, bisect.cpp and templates.cpp.
#pragma once

#include <algorithm>
#include <cstring>
#include <memory>

#include "mesh4d/cut/frame_builder.h"

namespace mesh4d {
namespace slicing {

inline void FrameBuilder::reserveTris(size_t n) {
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

inline void FrameBuilder::ensureBase(uint32_t id) {
    if (id >= r_nt || r_init_data[id]) return;
    r_init[id] = 1;
    RTri& t = rt[id];
    for (int c = 0; c < 3; ++c) {
        t.v[c] = world.mesh.triangles[id][c];
        rn[slotOf(id, c)] = meshSlot(world.slot_next[3 * id + c]);
        t.edge[c] = world.triangle_edges[id][c];
    }
    t.src = id;
    t.depth = 0;
    t.state = kUnknown;
    t.longest = -1;
}

inline uint32_t FrameBuilder::nextOf(uint32_t p) const {
    const uint32_t id = slotTri(p);
    if (id < r_nt && !r_init_data[id]) return meshSlot(world.slot_next[3 * id + slotSide(p)]);
    return rn[p];
}

inline void FrameBuilder::setNext(uint32_t p, uint32_t to) {
    ensureBase(slotTri(p));
    rn[p] = to;
}

inline uint32_t FrameBuilder::newVertex(const Vec3& rest, uint32_t a, uint32_t b, double xm) {
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

inline const REdge& FrameBuilder::edgeOf(uint32_t id, int c) {
    REdge& e = r_edge_data[rt[id].edge[c]];
    if (e.len != e.len) makeEdge(e, rt[id].v[c], rt[id].v[kSucc[c]]);
    return e;
}

inline void FrameBuilder::makeEdgePair(REdge& e0, uint32_t a0, uint32_t b0, REdge& e1, uint32_t a1, uint32_t b1) const {
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

inline void FrameBuilder::storeEdge(REdge& e, const EdgeBubble& eb) {
    e.len = eb.length;
    e.c = eb.c;
    e.xm_mid = eb.xm_mid;
}

inline uint32_t FrameBuilder::midVertex(uint32_t id, int c) {
    const uint32_t rec = rt[id].edge[c];
    if (r_edges[rec].mid != kUnset) return r_edges[rec].mid;
    const uint32_t a = rt[id].v[c], b = rt[id].v[kSucc[c]];
    // A mesh edge's midpoint from its lo end, as the edge's other triangles would make it.
    const uint32_t lo = std::min(a, b), hi = std::max(a, b);
    const Vec3 rest = (restOfId(lo) + restOfId(hi)) * 0.5;
    const double xm = edgeOf(id, c).xm_mid;  // made with the edge's bound
    return r_edges[rec].mid = newVertex(rest, lo, hi, xm);
}

inline void FrameBuilder::moveSlot(uint32_t from, uint32_t to) {
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

inline int FrameBuilder::longestOf(const uint32_t v[3], const REdge* const e[3]) {
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

inline int FrameBuilder::longestSlot(uint32_t id) {
    ensureBase(id);
    if (rt[id].longest >= 0) return rt[id].longest;
    return findLongest(id);
}

// Why the steps of refine/bisect.cpp hold:
//   - Without a real cap every point is inside and is given its output place in bulk (refineFrame):
//     side and vertex_out stay the mesh's.
//   - A piece back on the stack unchanged (its record is reset when it is halved) keeps its verdict:
//     its bound is not evaluated again.
//   - The bubbles pass but the third-order term does not: the whole-piece form (tighter near the
//     camera, chord_error.h pieceForm) may pass the piece as it is.
//   - (The form is worth making only for a piece that needs a level of kMinLevel or more: its
//     bubbles alone say about how much.)
//   - A split of a coarser neighbour first (kSplitOther) leaves id as it was (its edges are shorter
//     than the edge halved): id is judged again at once, as if pushed back and popped.
//   - The split would halve a piece a template fills: this piece is filled by its own template
//     instead (any level its form asks for), so the template stays whole, unless that template would
//     make more than kForceRatio times the triangles its bisection is expected to (then the split is
//     made: the template's halves are judged again).

}  // namespace slicing
}  // namespace mesh4d
