// The state of one frame's cut (internal to mesh4d/cut and mesh4d/refine): FrameBuilder holds
// the frame's inputs, its output and the refinement's working arrays; its stages live in one file
// each (mesh4d/refine/refine.h lists them). Not a public header: include mesh4d/slice.h.
// What is an algorithm's own lives beside it, with the reasons its .cpp steps hold: the vertex
// clip (cut/vertex_clip.h), the rest clip (cut/rest_clip.h), the bisection's inline parts
// (refine/bisect.h), the templates (refine/templates.h); the first pass's in refine/refine.h.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>

#include "mesh4d/slice.h"
#include "mesh4d/cut/rest_clip.h"
#include "mesh4d/cut/vertex_clip.h"
#include "mesh4d/refine/chord_error.h"
#include "mesh4d/exact_side.h"
#include "mesh4d/refine/form_bisect.h"
#include "mesh4d/refine/slide_bound.h"
#include "mesh4d/robust.h"
#include "mesh4d/refine/tessellate.h"
#include "mesh4d/motion/worldline.h"
#include "mesh4d/refine/worldline_refine.h"

namespace mesh4d {
namespace slicing {

constexpr uint32_t kUnset = 0xffffffffu;

// The terms of the a-priori bound of one point (chord_error.h PointTerms), side by side: what a
// corner or an edge's end contributes is read from one place.
using VTerms = PointTerms;

struct REdge {
    uint32_t mid;   // midpoint vertex once made, else kUnset
    uint32_t on;    // a record past the mesh's edges: the mesh edge it is a part of, else kUnset (an inner edge)
    double len;     // EdgeBubble::length once known, else NaN
    double c;       // EdgeBubble::c, known with len
    double xm_mid;  // EdgeBubble::xm_mid, known with len (the midpoint's |x|_M, for its split)
};
// Triangles of the refinement, the leaves only: ids below r_nt are the mesh's triangles (records
// made when first touched), later ids pieces made by splits. A split keeps one half in the
// record it halves (the one with the slot that does not move) and appends the other. Each slot c
// is the edge from v[c] to v[c + 1]; the slots on one edge form a cycle (the next slot of each,
// kept apart from the records in an array indexed by the slot itself), as World4D::slot_next
// does for the mesh, so that an edge is split in every triangle that has it: no T-junctions,
// however the splits go.
// kCoarse: its bound fails, but its whole-piece form (chord_error.h pieceForm) is tight enough
// that a template fills it (tessellate.h) instead of further bisection.
// kBoundFailed: a mesh triangle as the mesh has it whose bound and whole-piece form refineFrame's
// first pass found to fail (the drain's verdict on it, from the same terms, bit for bit): the
// drain goes on from its coarseForm test without judging it again.
enum : uint8_t { kUnknown = 0, kPassed = 1, kFailed = 2, kCoarse = 3, kBoundFailed = 4 };
struct RTri {
    uint32_t v[3];
    uint32_t edge[3];  // the edge record of each slot
    uint32_t src;      // the mesh triangle it lies on
    uint8_t depth;     // bisections since the mesh triangle (at most 2 log2(max_segments) <= 60)
    uint8_t state;     // kUnknown, or its bound is known to pass or to fail (it waits for a neighbour's split)
    int16_t longest;   // the slot of its longest edge once known, else -1
};
// A slot (triangle record, side) as one number: id << 2 | side (the mesh's World4D::slot_next
// counts 3 id + side; meshSlot converts). At most 2^30 records. The slot after slot p on its
// edge is next[p] (4 entries per record, the fourth unused); itself on a boundary edge.
inline uint32_t slotOf(uint32_t id, int side) { return id << 2 | uint32_t(side); }
inline uint32_t slotTri(uint32_t slot) { return slot >> 2; }
inline uint32_t slotSide(uint32_t slot) { return slot & 3; }
inline uint32_t meshSlot(uint32_t slot3) { return slotOf(slot3 / 3, int(slot3 % 3)); }
constexpr int kSucc[3] = {1, 2, 0};  // the next corner

// The refinement's working arrays, kept per thread from frame to frame: a frame reuses the pages the
// previous one touched instead of faulting fresh ones in (the arrays are several times the size of
// the output). Cleared, not freed, by each frame; freed after a frame that made them larger than
// kScratchKeep bytes, so a single huge frame does not hold its memory for the program's life.
struct RefineScratch {
    std::vector<Vec3> pos, rest;
    std::vector<double> time;
    std::vector<VTerms> terms;
    std::vector<Event> cap;
    std::vector<uint8_t> init, limited;
    std::vector<REdge> edges;
    std::unique_ptr<RTri[]> tri;
    std::unique_ptr<uint32_t[]> next;  // 4 per record (slotOf)
    size_t tri_cap = 0;
    std::vector<uint32_t> members, stack;
    std::vector<Side> side;
    std::vector<uint32_t> vertex_out;
    std::vector<double> spread;  // per mesh edge: its |u|_M^2 (refineFrame's first pass)
    // The templates (refineFrame without a real cap): the coarse pieces' forms, each record's
    // form (index, or kUnset), each edge record's segment count and first point, one piece's
    // local triangles and its local-to-global point map.
    std::vector<PieceForm> forms;
    std::vector<uint8_t> form_aniso;  // per form: filled by FormBisection (form_bisect.h), not a grid
    FormBisection bisection;
    std::vector<uint32_t> form_of, edge_count, edge_first, local_map;
    std::vector<uint32_t> coarse;  // every record marked kCoarse, as marked (repeats, stale ones included)
    std::vector<uint32_t> candidates, failing;  // refineFrame's first pass: triangles its corners' bound fails, and its a-priori bound
    std::vector<double> quadratic;              // per mesh triangle in `failing`: its bound's quadratic part (kBoundFailed)
    // Faces containing the velocity (slide_bound.h), asked per frame, made once each: per mesh
    // triangle whether its plane contains v, per mesh edge whether it is inner to such a face
    // (-1 not yet asked).
    std::vector<int8_t> tri_slides, edge_inner;
    std::vector<std::array<uint32_t, 3>> local;

    size_t bytes() const {
        return (pos.capacity() + rest.capacity()) * sizeof(Vec3) + time.capacity() * sizeof(double) +
               terms.capacity() * sizeof(VTerms) + (spread.capacity() + quadratic.capacity()) * sizeof(double) +
               cap.capacity() * sizeof(Event) +
               edges.capacity() * sizeof(REdge) + tri_cap * (sizeof(RTri) + 4 * sizeof(uint32_t)) +
               (vertex_out.capacity() + members.capacity() + stack.capacity()) * sizeof(uint32_t) +
               init.capacity() + limited.capacity() + side.capacity() + forms.capacity() * sizeof(PieceForm) +
               form_aniso.capacity() +
               (form_of.capacity() + edge_count.capacity() + edge_first.capacity() + local_map.capacity() +
                coarse.capacity() + candidates.capacity() + failing.capacity()) *
                   sizeof(uint32_t) +
               local.capacity() * sizeof(std::array<uint32_t, 3>);
    }
};
constexpr size_t kScratchKeep = size_t(256) << 20;

inline RefineScratch& threadScratch() {
    static thread_local RefineScratch scratch;
    return scratch;
}

struct FrameBuilder {
    const World4D& world;
    const ViewSurface& view;
    const SliceSettings& settings;
    const ViewAnchor anchor;  // the frame's local coordinates (positions relative to the object's apparent origin)
    ApparentMesh out;
    RefineScratch& scratch;               // this thread's working arrays (threadScratch)
    std::vector<Side>& side;
    std::vector<uint32_t>& vertex_out;    // rest vertex -> output vertex
    std::vector<uint32_t> crossing_out;   // 2 * edge + cap -> output vertex
    uint32_t cur_edges[3] = {0, 0, 0};  // mesh edges of the triangle being clipped (rest clip)
    bool rest_clip = false;             // at rest, past cone, real caps, tolerance > 0: restPlan
    double rest_tolerance = 0;          // the tolerance restPlan keeps (settings.tolerance is 0 at rest)
    double bound_speed = 0;             // boundSpeed(), once per frame

    FrameBuilder(const World4D& w, const ViewSurface& v, const SliceSettings& s)
        : world(w), view(v), settings(s), anchor(viewAnchor(v, w.motion)), scratch(threadScratch()),
          side(scratch.side), vertex_out(scratch.vertex_out), r_pos(scratch.pos), r_time(scratch.time),
          r_terms(scratch.terms), r_rest(scratch.rest), r_cap(scratch.cap), scratch_members(scratch.members),
          r_edges(scratch.edges),
          r_tri(scratch.tri), r_next(scratch.next), rn(scratch.next.get()), r_tri_cap(scratch.tri_cap),
          r_init(scratch.init), r_limited(scratch.limited) {
        for (auto* a : {&r_pos, &r_rest}) a->clear();
        r_time.clear();
        r_terms.clear();
        for (auto* a : {&r_init, &r_limited}) a->clear();
        side.clear();
        vertex_out.clear();
        r_cap.clear();
        r_edges.clear();
        scratch_members.clear();
        scratch.stack.clear();
        scratch.tri_slides.clear();
        scratch.edge_inner.clear();
        out.origin = anchor.origin;
        out.time_origin = anchor.time_origin;
        bound_speed = boundSpeed();
    }
    ~FrameBuilder() {
        if (scratch.bytes() > kScratchKeep) scratch = RefineScratch();
    }
    FrameBuilder(const FrameBuilder&) = delete;
    FrameBuilder& operator=(const FrameBuilder&) = delete;

    // The factor a piece's bound multiplies the light delay's error by (chord_error.h
    // chordErrorOfBubbles): the object's speed |u|; |w| = |u - shear| when the view shears its
    // outputs (the finite model with a moving camera); settings.displacement when that is given
    // (outputs mapped afterwards: reflections seen by a moving camera, pipeline/stage/mirror.h).
    double boundSpeed() const {
        if (settings.displacement >= 0) return settings.displacement;
        if (view.sheared()) return norm(world.motion.velocity - view.shear);
        return world.motion.beta;
    }
    ChordError pointsBound(const double c[3], const VTerms& a, const VTerms& b, const VTerms& d) const {
        return chordErrorOfPoints(world.motion, bound_speed, c, a, b, d, settings.tolerance);
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
    void classifyVertices(const std::vector<uint8_t>* live);

    uint32_t vertexPoint(uint32_t i) {
        if (vertex_out[i] == kUnset) {
            vertex_out[i] = emit(vertexEvent(i), world.mesh.positions[i]);
        }
        return vertex_out[i];
    }

    // The crossing of edge `edge` at cap `cap` (0 = a, 1 = b), always parametrised from the
    // lower vertex id so both triangles of the edge compute the same point.
    uint32_t crossingPoint(uint32_t edge, int cap);

    // The output point of a cap crossing at parameter s along a segment whose ends lie on sides
    // s0 and s1. The cap passing exactly through a visible end (a frame at the instant the object
    // begins or ends) gives that end itself (end(0) or end(1)), not a copy of it. Otherwise the
    // crossing event lies on the worldline of the rest point at s (a worldline meets the view
    // surface once), so its image is the anchored cut of that point, rest(): relative accuracy
    // however far the object is; only the parameter s carries the absolute events' rounding.
    template <class End, class Rest>
    uint32_t crossingAt(double s, Side s0, Side s1, End end, Rest rest) {
        if (s == 0 && s0 == Side::Inside) return end(0);
        if (s == 1 && s1 == Side::Inside) return end(1);
        const Vec3 q = rest();
        return emit(cutRestLocal(anchor, world.motion, q), q);
    }

    // The exact image of vertex i (local coordinates), without emitting it.
    Event vertexEvent(uint32_t i) const {
        if (i < r_pos.size()) return {r_time[i], r_pos[i]};  // the refinement's batch cut (bit-identical)
        return cutRestLocal(anchor, world.motion, world.mesh.positions[i]);
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
    // piece must get, as a ratio of squared sizes (<= 1: it cannot hide a crossing). A poke
    // whose h stays below limit^2 / (2 dmin) is ignored: about its top (at distance r0 <= dmin
    // from the camera) h falls off as rho^2 / (2 r0) with the distance rho, so it is narrower
    // than `limit`.
    double hiddenCrossingRatio(const Event* e, const double* h, int n, double limit) const;

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
    // line across the chord there). A ratio of squared sizes; <= 1 when the piece passes.
    double clipRatio(const uint32_t v[3], const double* la, const double* lb, const double* lc, double limit) const;


    // ---- Step (refinement, tolerance > 0, moving, past cone): conforming bisection ----
    // Flat records, no allocation per piece: vertices as arrays indexed by id, edges and pieces as
    // records in one array each. Every decision is made from the a-priori bound (chord_error.h
    // edgeBubble, chordErrorOfBubbles): per point its terms (affine in the rest point but for one
    // square root), per edge its coefficient, once each. No exact cut is made for a decision: the
    // points the splits make are cut once, in one batch, after the last split.
    // Vertices of the refinement share one id space: ids below r_nv are the mesh's vertices, later
    // ids edge midpoints made when an edge is split. `side` and `vertex_out` grow with them.
    uint32_t r_nv = 0, r_nt = 0, r_ne = 0;
    bool r_caps = false;          // a cap is real: points are classified and pieces clipped
    bool r_templates = false;     // no real cap: pieces whose form is tight are filled by templates
    Vec3 r_now{0, 0, 0};          // the object's origin now, relative to the camera (nowBase)
    std::vector<Vec3>& r_pos;     // exact local image of every id (the batch cuts: mesh vertices first,
    std::vector<double>& r_time;  // the splits' points after the last split); its local emission time, -delta
    std::vector<VTerms>& r_terms; // its terms of the bound (for mesh vertices: w only where a triangle needs it)
    std::vector<Vec3>& r_rest;    // rest point of ids >= r_nv
    std::vector<Event>& r_cap;    // cap events (2 per id >= r_nv) when a cap is real
    std::vector<uint32_t>& scratch_members;

    // Edges of the refinement: records below r_ne are the mesh's edges, later ones the halves and
    // inner edges that splits make. Every slot on an edge refers to the edge's record, so its
    // midpoint and length are made once and seen from every triangle around it.
    std::vector<REdge>& r_edges;
    // The data of r_edges, r_terms and r_init while the splits run (set where they are sized): the
    // hot loops index them without going through the vectors.
    REdge* r_edge_data = nullptr;
    VTerms* r_term_data = nullptr;
    const uint8_t* r_init_data = nullptr;

    // Triangles (RTri): one array for all ids, left uninitialised (RTri is trivial): a large mesh
    // of which few triangles need refining touches only their pages (r_init says which base
    // records are made).
    std::unique_ptr<RTri[]>& r_tri;
    RTri* rt = nullptr;  // r_tri.get(), kept in step by reserveTris
    std::unique_ptr<uint32_t[]>& r_next;  // each slot's next slot on its edge (slotOf)
    uint32_t* rn;                         // r_next.get(), kept in step by reserveTris
    size_t& r_tri_cap;
    size_t r_tri_size = 0;
    std::vector<uint8_t>& r_init;
    std::vector<uint8_t>& r_limited;  // per mesh triangle: a piece reached the depth limit first
    uint32_t r_max_depth = 0;
    size_t r_leaves = 0;  // pieces so far (an upper bound of the output triangles before clipping)
    std::unordered_map<uint64_t, uint32_t> r_crossings[2];  // (lo << 32 | hi) -> clip point, per cap

    Vec3 restOfId(uint32_t id) const { return id < r_nv ? world.mesh.positions[id] : r_rest[id - r_nv]; }
    Event capOfId(uint32_t id, int cap) const { return id < r_nv ? world.events[2 * id + cap] : r_cap[2 * (id - r_nv) + cap]; }
    Event eventOfId(uint32_t id) const { return {r_time[id], r_pos[id]}; }

    // Room for n more triangle records (growth copies them: they are trivial).
    inline void reserveTris(size_t n);

    inline void ensureBase(uint32_t id);
    // The next slot around p's edge; an untouched mesh triangle still has the mesh's cycle.
    inline uint32_t nextOf(uint32_t p) const;
    inline void setNext(uint32_t p, uint32_t to);

    // A split's point: its terms now, its exact image in the batch after the last split.
    // xm: its |x|_M (edgeBubble made it, bit for bit normMOfShape of this shape offset).
    inline uint32_t newVertex(const Vec3& rest, uint32_t a, uint32_t b, double xm);

    // The edge record of slot c of triangle id (ensureBase'd), with its coefficient and length
    // (chord_error.h edgeBubble) made once per edge, from its ends in id order.
    // (The look-up inline, the bound made out of line: the hot loops stay small.)
    [[gnu::always_inline]] inline const REdge& edgeOf(uint32_t id, int c);
    [[gnu::noinline]] void makeEdge(REdge& e, uint32_t a, uint32_t b) const;
    // Two edges' records at once (chord_error.h edgeBubbleLanes, the same bits as makeEdge's;
    // makeEdge twice with APPARENT_NO_LANES).
    inline void makeEdgePair(REdge& e0, uint32_t a0, uint32_t b0, REdge& e1, uint32_t a1, uint32_t b1) const;
    static inline void storeEdge(REdge& e, const EdgeBubble& eb);

    // The midpoint vertex of slot c of triangle id (made once per edge, when the edge is split).
    inline uint32_t midVertex(uint32_t id, int c);

    // Moves slot `from` of a triangle being split (its record made) to slot `to` of its half:
    // same edge, same place in the edge's cycle. The common edge, on two triangles, is a 2-cycle:
    // the slot after `from` is the one before it, found without a walk.
    inline void moveSlot(uint32_t from, uint32_t to);

    // Halves the edge of slot c of triangle id at its midpoint, in every triangle around the edge:
    // each (a, b, o) becomes A = (a, m, o), kept in its record (slot c + 2 stays in place), and
    // B = (m, b, o), appended. The halves' slots on the edge form two new cycles, on two new edge
    // records; each triangle's new inner edge (m, o) gets its own record.
    // members: the edge's cycle from slot c of id, n slots (the walk that chose the edge collected
    // it; their records are made).
    // The new edges' bounds are made here, two at a time (makeEdgePair): every new piece is judged
    // on all three of its edges when popped, and these are its unmade ones.
    void splitEdge(uint32_t id, int c, const uint32_t* members, uint32_t n, std::vector<uint32_t>& stack);

    // Refines until every piece's bound (chord_error.h) is within the tolerance, or the piece is
    // wholly before or after existing (it shows nothing), or it reached the depth limit.
    void drain(std::vector<uint32_t>& stack);

    // Edge lengths in the map's metric (chord_error.h edgeLength), ordered totally: ties go by the
    // edge's vertex ids, so every triangle of an edge ranks it the same.
    struct Rank {
        double length;
        uint32_t lo, hi;
        bool operator<(const Rank& o) const {
            if (length != o.length) return length < o.length;
            return lo != o.lo ? lo < o.lo : hi < o.hi;
        }
    };
    // The slot of the longest of the three edges e[c] (lengths known) of the triangle on v.
    // (The ids are looked at only on a tie of lengths, as Rank orders them.)
    static inline int longestOf(const uint32_t v[3], const REdge* const e[3]);
    [[gnu::always_inline]] inline int longestSlot(uint32_t id);
    [[gnu::noinline]] int findLongest(uint32_t id);

    // Longest-edge bisection (Rivara): a triangle's longest edge is halved only once it is the
    // longest edge of every triangle around it; until then the neighbour whose longest edge is
    // another is refined first, along the path of ever longer edges (it ends: lengths grow
    // strictly along it in the total order). One split per call. Angles stay bounded in the
    // map's metric, so the pieces follow the stretch (long across the motion where the map
    // bends along it) without slivers.
    // True when the edge halved is id's own (along the path lengths grow strictly, so no edge
    // after the first is id's).
    // With `guard` (templates on), a split that would halve a piece marked kCoarse whose level
    // is kKeptLevel or more is not made: kSplitBlocked (the caller templates id instead).
    static constexpr int kSplitOther = 0, kSplitOwn = 1, kSplitBlocked = 2;
    // The edge's cycle is collected as it is walked (splitEdge needs it all): an edge on one or
    // two triangles (every edge of a closed manifold mesh and of its pieces) in a local pair, a
    // longer cycle in scratch_members. Every record the walk passes is made (longestSlot).
    [[gnu::noinline]] int splitLongestPath(uint32_t id, std::vector<uint32_t>& stack, bool guard = true);

    // ---- Templates (no real cap): the pieces the bisection leaves, each filled at once ----
    // When a template pays, how its level is chosen and why its output is within T, with its
    // constants: mesh4d/refine/templates.h.

    // True when the whole-piece form of the piece with corners' shape offsets a, b, c (chord_error.h
    // pieceForm: A >= the delay's Hessian on the whole piece) bounds the piece itself within the
    // tolerance: speed bubbleMax(A's sides) <= T. A sound bound of the piece as chordErrorOfPoints'
    // is; tighter than its third-order term near the camera (the form's slack there is second
    // order along the line of sight), so a piece it passes needs no further split.
    bool passesByForm(const Vec3& a, const Vec3& b, const Vec3& c) const;
    // Faces containing the velocity (slide_bound.h): on this frame (uniform motion, no real cap,
    // outputs not displaced), whether mesh triangle f's plane contains v, whether mesh edge e of
    // f is inner to its face (shared with exactly one triangle, coplanar, whose plane contains v
    // too), and whether piece id of such a triangle passes on its rim: each of its sides on a rim
    // edge within the tolerance (edge records e; a side's mesh edge is its record below r_ne,
    // else REdge::on).
    bool r_slide = false;
    bool slides(uint32_t f);
    bool innerEdge(uint32_t e, uint32_t f);
    bool rimPasses(uint32_t f, const uint32_t v[3], const uint32_t rec[3], const double c[3], const double len[3],
                   const double xm_mid[3]);

    // Whether piece id's forced template (its form made by coarseForm(id, s, true)) makes at
    // most kForceRatio times the triangles its bisection is expected to: n^2 against its
    // bubbles' bound over T (at least 1).
    bool forcedTemplatePays(uint32_t id);

    // The form of piece id (its corners' shape offsets s) when it is finite and (unless `force`:
    // the depth limit stopped the piece) the piece is better filled by a template (above); kept
    // in scratch.forms, indexed by scratch.form_of[id].
    bool coarseForm(uint32_t id, const Vec3 s[3], bool force);

    // The triangles the two halves of a piece are expected to make (coarseForm): each half's need
    // from the centroid's form on its own sides (the piece halved on its longest side in that
    // form: a half-side, the median, a whole side; the median's value by the parallelogram law,
    // which holds for any quadratic form), its excess of A over the centroid's form shrunk by
    // sqrt 2, its level rounded up by kRounding on average. per: need per unit of bubbleMax.
    static double halvesEstimate(const PieceForm& pf, double per, double infl);
    // A half's excess of A over the centroid's form: the piece's (infl - 1) shrunk by sqrt 2.
    static double halfGrowth(double infl) { return 1 + (infl - 1) / 1.4142135623730951; }
    // The triangles a half of need `child` is expected to make: its level rounded up by kRounding
    // on average, squared; at least one.
    static double halfCost(double child);

    // The triangles the fill of form f is expected to make: n^2 for a grid of level n (at most
    // cap), kAnisoCost times the form's need for the bisection in its metric.
    double fillEstimate(uint32_t f, uint32_t cap) const;

    // The least level n >= 1 with speed bubbleMax(c) / n^2 <= T, at most `cap`.
    uint32_t formLevel(const PieceForm& pf, uint32_t cap) const;

    // The first id of the count - 1 points that cut edge record e (ends a, b) into equal
    // segments, made once, from the lower id end: point i of the edge is lo + (hi - lo) i / count.
    uint32_t edgePoints(uint32_t e, uint32_t a, uint32_t b, uint32_t count);

    // Fills one leaf (corners v, edge records e, on mesh triangle src) with its template at
    // level N (form: the piece's form, or null for a piece within the bound as a whole) and
    // appends the triangles. base: the output index of the first new point.
    void fillLeaf(uint32_t src, const uint32_t v[3], const uint32_t e[3], uint32_t N, const PieceForm* form,
                  bool unsplit, size_t base, uint32_t cap, bool aniso = false);

    // Every leaf in record order filled by its template. When the templates would pass
    // settings.max_triangles, every level is scaled down until they fit and over_budget is set
    // (the tolerance is not met then, and the rings are not checked); false (nothing emitted)
    // when even the leaves alone do not fit: they are emitted as they are.
    double r_level_scale = 1;
    bool templateLeaves();

    uint32_t outId(uint32_t id);

    // The clip point of the leaf side a -> b at cap `cap`: keyed by the two ends, parametrised
    // from the smaller id, so both leaves on the side share it (on a whole mesh edge it is the
    // point crossingPoint makes in vertex mode).
    uint32_t leafCrossing(uint32_t a, uint32_t b, int cap);

    void emitLeaf(uint32_t src, const uint32_t v[3]);

    // The whole frame with the tolerance: bounds of every live mesh triangle from its corners and
    // edge midpoints (cut in batches), splits where a bound exceeds the tolerance, then the leaves
    // in mesh order. `live`: one flag per chunk (the cull), or null.
    void refineFrame(const std::vector<uint8_t>* live);

    // Step: a whole triangle clipped to the span in vertex mode (Sutherland-Hodgman over the caps).
    void clipWhole(size_t f);

    // Step (objects at rest on the past cone, with a real cap, tolerance > 0): the rest clip
    // (mesh4d/cut/rest_clip.h: why it holds, its keys and pieces).

    // Points on mesh edges (per frame): (edge, place from lo in 2^-20) -> output vertex, and crossings
    // on a stretch of a mesh edge: (edge, from, to, cap) -> output vertex.
    std::map<std::pair<uint32_t, int64_t>, uint32_t> rest_edge_points;
    std::map<std::pair<std::pair<uint32_t, int64_t>, std::pair<int64_t, int>>, uint32_t> rest_edge_crossings;

    double pieceRatio(const uint32_t v[3], const RestPiece& p, double limit) const;

    // A place along triangle f's side s (from the side's first corner), counted from its mesh
    // edge's lo end instead: the same number for both triangles of the edge.
    int64_t placeFromLo(const uint32_t v[3], int s, uint32_t edge, int64_t place) const;

    std::vector<RestPlan> rest_plans;
    std::map<uint32_t, std::set<int64_t>> rest_edge_places;  // mesh edge -> leaf corners on it (place from lo)

    void restPlan(size_t f);

    void restEmit(const RestPlan& plan);

    void splitPiece(const uint32_t v[3], const RestPiece& p, double ratio, int depth, int max_depth, double limit,
                    std::vector<RestPiece>* leaves, std::set<Key>* corners, bool* limited) const;

    // Corners of other leaves strictly inside the side a -> b, in order: on a mesh edge, those of
    // both triangles of the edge; inside the triangle, those of its finer leaves (which halve the
    // side dyadically).
    void hangingCorners(const uint32_t v[3], const Key& a, const Key& b, const std::set<Key>& corners,
                        std::vector<Key>* out_keys) const;

    // Output vertex of a piece corner: a mesh vertex, a point on a mesh edge (shared by the edge's
    // triangles), or an inner point of this triangle.
    uint32_t restPoint(const uint32_t v[3], const Key& k, std::map<Key, uint32_t>& points);

    Side restSide(const uint32_t v[3], const Key& k) const;

    // The crossing of the stretch a -> b of a piece's boundary with cap `cap`.
    uint32_t restCrossing(const uint32_t v[3], const Key& a, const Key& b, Side sa, Side sb, int cap,
                          std::map<Key, uint32_t>& points, std::map<std::pair<std::pair<Key, Key>, int>, uint32_t>& crossings);

    // One leaf polygon (convex, possibly with straight runs of corners) clipped to the span and
    // emitted: as a fan from its first kept corner when no three consecutive corners are in line,
    // else as a fan about the centre of its corners (no zero-area triangles).
    void clipRestPolygon(size_t f, const uint32_t v[3], const std::vector<Key>& poly, std::map<Key, uint32_t>& points,
                         std::map<std::pair<std::pair<Key, Key>, int>, uint32_t>& crossings);

    // Step: one triangle: whole, refined, or clipped to the span.
    void addTriangle(size_t f);
};

}  // namespace slicing
}  // namespace mesh4d
