#include "mesh4d/slice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>

#include "mesh4d/refine/chord_error.h"
#include "mesh4d/exact_side.h"
#include "mesh4d/refine/form_bisect.h"
#include "mesh4d/robust.h"
#include "mesh4d/refine/tessellate.h"
#include "mesh4d/worldline.h"
#include "mesh4d/refine/worldline_refine.h"

namespace mesh4d {

namespace {

// Where a vertex's worldline crossing falls relative to the extruded span.
enum class Side : uint8_t { NotYet, Inside, Gone };

constexpr uint32_t kUnset = 0xffffffffu;

// The rest clip (restPlan): a chord of a cap's clip circle through a piece must lie within this
// fraction of the tolerance of the circle.
constexpr double kMidpointShare = 0.25;

// Sutherland-Hodgman over the span between the caps, for a convex polygon of n corners whose
// sides are s[i]: the corners inside the span, and on each side i -> i + 1 whose ends lie on
// different sides of a cap, that cap's crossing (both caps' crossings, in order along the side,
// when it runs from before existing to after). corner(i) and crossing(i, j, cap) give output ids.
// Writes at most 2 n ids to `out` and returns their count (a triangle gives at most 5).
template <class Corner, class Crossing>
int clipToSpan(int n, const Side* s, Corner corner, Crossing crossing, uint32_t* out) {
    int k = 0;
    for (int i = 0; i < n; ++i) {
        const int j = (i + 1) % n;
        const Side si = s[i], sj = s[j];
        if (si == Side::Inside) out[k++] = corner(i);
        if (si == sj) continue;
        const bool cross_a = si == Side::NotYet || sj == Side::NotYet;
        const bool cross_b = si == Side::Gone || sj == Side::Gone;
        const bool a_first = si == Side::NotYet || sj == Side::Gone;
        if (cross_a && cross_b) {
            out[k++] = crossing(i, j, a_first ? 0 : 1);
            out[k++] = crossing(i, j, a_first ? 1 : 0);
        } else {
            out[k++] = crossing(i, j, cross_a ? 0 : 1);
        }
    }
    return k;
}

// The terms of the a-priori bound of one point (chord_error.h PointTerms), side by side: what a
// corner or an edge's end contributes is read from one place.
using VTerms = PointTerms;

struct REdge {
    uint32_t mid;   // midpoint vertex once made, else kUnset
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

RefineScratch& threadScratch() {
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
    // (outputs mapped afterwards: reflections seen by a moving camera, pipeline/mirror.h).
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
    void classifyVertices(const std::vector<uint8_t>* live) {
        const size_t nv = world.mesh.positions.size();
        side.assign(nv, Side::Inside);
        // No real cap, nothing culled, every vertex used, the refinement's batch cut made: output
        // vertex i is the image of vertex i, copied in bulk (the same points vertexPoint emits).
        if (!world.cap_a_real && !world.cap_b_real && !live && world.simple && r_pos.size() == nv && out.positions.empty()) {
            out.positions.assign(r_pos.begin(), r_pos.end());
            out.emission_times.assign(r_time.begin(), r_time.end());
            out.rest_points = world.mesh.positions;
            vertex_out.resize(nv);
            for (size_t i = 0; i < nv; ++i) vertex_out[i] = uint32_t(i);
            return;
        }
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
            slot = crossingAt(
                s, side[e.lo], side[e.hi], [&](int end) { return vertexPoint(end == 0 ? e.lo : e.hi); },
                [&] { return world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s; });
        }
        return slot;
    }

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
    // line across the chord there). A ratio of squared sizes; <= 1 when the piece passes.
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
    void reserveTris(size_t n) {
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

    void ensureBase(uint32_t id) {
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
    // The next slot around p's edge; an untouched mesh triangle still has the mesh's cycle.
    uint32_t nextOf(uint32_t p) const {
        const uint32_t id = slotTri(p);
        if (id < r_nt && !r_init_data[id]) return meshSlot(world.slot_next[3 * id + slotSide(p)]);
        return rn[p];
    }
    void setNext(uint32_t p, uint32_t to) {
        ensureBase(slotTri(p));
        rn[p] = to;
    }

    // A split's point: its terms now, its exact image in the batch after the last split.
    // xm: its |x|_M (edgeBubble made it, bit for bit normMOfShape of this shape offset).
    uint32_t newVertex(const Vec3& rest, uint32_t a, uint32_t b, double xm) {
        const uint32_t id = uint32_t(r_terms.size());
        r_terms.push_back({(r_terms[a].s + r_terms[b].s) * 0.5, xm});  // shapeOffset is affine
        r_term_data = r_terms.data();
        r_rest.push_back(rest);
        // Without a real cap every point is inside and is given its output place in bulk
        // (refineFrame): side and vertex_out stay the mesh's.
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

    // The edge record of slot c of triangle id (ensureBase'd), with its coefficient and length
    // (chord_error.h edgeBubble) made once per edge, from its ends in id order.
    // (The look-up inline, the bound made out of line: the hot loops stay small.)
    [[gnu::always_inline]] const REdge& edgeOf(uint32_t id, int c) {
        REdge& e = r_edge_data[rt[id].edge[c]];
        if (e.len != e.len) makeEdge(e, rt[id].v[c], rt[id].v[kSucc[c]]);
        return e;
    }
    [[gnu::noinline]] void makeEdge(REdge& e, uint32_t a, uint32_t b) const {
        storeEdge(e, edgeBubble(world.motion, r_now, r_term_data[std::min(a, b)], r_term_data[std::max(a, b)]));
    }
    // Two edges' records at once (chord_error.h edgeBubblePair: the same bits as makeEdge's, the
    // two square-root and division chains side by side).
    void makeEdgePair(REdge& e0, uint32_t a0, uint32_t b0, REdge& e1, uint32_t a1, uint32_t b1) const {
        EdgeBubble eb[2];
        edgeBubblePair(world.motion, r_now, r_term_data[std::min(a0, b0)], r_term_data[std::max(a0, b0)],
                       r_term_data[std::min(a1, b1)], r_term_data[std::max(a1, b1)], eb);
        storeEdge(e0, eb[0]);
        storeEdge(e1, eb[1]);
    }
    static void storeEdge(REdge& e, const EdgeBubble& eb) {
        e.len = eb.length;
        e.c = eb.c;
        e.xm_mid = eb.xm_mid;
    }

    // The midpoint vertex of slot c of triangle id (made once per edge, when the edge is split).
    uint32_t midVertex(uint32_t id, int c) {
        const uint32_t rec = rt[id].edge[c];
        if (r_edges[rec].mid != kUnset) return r_edges[rec].mid;
        const uint32_t a = rt[id].v[c], b = rt[id].v[kSucc[c]];
        // A mesh edge's midpoint from its lo end, as the edge's other triangles would make it.
        const uint32_t lo = std::min(a, b), hi = std::max(a, b);
        const Vec3 rest = (restOfId(lo) + restOfId(hi)) * 0.5;
        const double xm = edgeOf(id, c).xm_mid;  // made with the edge's bound
        return r_edges[rec].mid = newVertex(rest, lo, hi, xm);
    }

    // Moves slot `from` of a triangle being split (its record made) to slot `to` of its half:
    // same edge, same place in the edge's cycle. The common edge, on two triangles, is a 2-cycle:
    // the slot after `from` is the one before it, found without a walk.
    void moveSlot(uint32_t from, uint32_t to) {
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

    // Halves the edge of slot c of triangle id at its midpoint, in every triangle around the edge:
    // each (a, b, o) becomes A = (a, m, o), kept in its record (slot c + 2 stays in place), and
    // B = (m, b, o), appended. The halves' slots on the edge form two new cycles, on two new edge
    // records; each triangle's new inner edge (m, o) gets its own record.
    // members: the edge's cycle from slot c of id, n slots (the walk that chose the edge collected
    // it; their records are made).
    // The new edges' bounds are made here, two at a time (makeEdgePair): every new piece is judged
    // on all three of its edges when popped, and these are its unmade ones.
    void splitEdge(uint32_t id, int c, const uint32_t* members, uint32_t n, std::vector<uint32_t>& stack) {
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

    // Refines until every piece's bound (chord_error.h) is within the tolerance, or the piece is
    // wholly before or after existing (it shows nothing), or it reached the depth limit.
    void drain(std::vector<uint32_t>& stack) {
        while (!stack.empty()) {
            const uint32_t id = stack.back();
            stack.pop_back();
            const uint8_t state = rt[id].state;
            if (r_caps) {
                const uint32_t* v = rt[id].v;
                const Side s0 = side[v[0]];
                if (s0 != Side::Inside && side[v[1]] == s0 && side[v[2]] == s0) continue;
            }
            // A piece back on the stack unchanged (its record is reset when it is halved) keeps
            // its verdict: its bound is not evaluated again.
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
                    // The bubbles pass but the third-order term does not: the whole-piece form (tighter
                    // near the camera, chord_error.h pieceForm) may pass the piece as it is.
                    if (ce.quadratic <= settings.tolerance && passesByForm(k0.s, k1.s, k2.s)) {
                        rt[id].state = kPassed;
                        continue;
                    }
                    quadratic = ce.quadratic;
                }
                // (The form is worth making only for a piece that needs a level of kMinLevel or
                // more: its bubbles alone say about how much.)
                if (r_templates && quadratic >= 0.5 * kMinLevel * kMinLevel * settings.tolerance &&
                    coarseForm(id, std::array<Vec3, 3>{k0.s, k1.s, k2.s}.data(), false)) {
                    rt[id].state = kCoarse;
                    scratch.coarse.push_back(id);
                    continue;
                }
                rt[id].state = kFailed;
                if (rt[id].longest < 0) rt[id].longest = int16_t(longestOf(v, e));
            }
            // A split of a coarser neighbour first (kSplitOther) leaves id as it was (its edges are
            // shorter than the edge halved): id is judged again at once, as if pushed back and popped.
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
                    // The split would halve a piece a template fills: this piece is filled by its
                    // own template instead (any level its form asks for), so the template stays
                    // whole, unless that template would make more than kForceRatio times the
                    // triangles its bisection is expected to (then the split is made: the
                    // template's halves are judged again).
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
    static int longestOf(const uint32_t v[3], const REdge* const e[3]) {
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
    [[gnu::always_inline]] int longestSlot(uint32_t id) {
        ensureBase(id);
        if (rt[id].longest >= 0) return rt[id].longest;
        return findLongest(id);
    }
    [[gnu::noinline]] int findLongest(uint32_t id) {
        const REdge* e[3] = {&edgeOf(id, 0), &edgeOf(id, 1), &edgeOf(id, 2)};
        const int best = longestOf(rt[id].v, e);
        rt[id].longest = int16_t(best);
        return best;
    }

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
    [[gnu::noinline]] int splitLongestPath(uint32_t id, std::vector<uint32_t>& stack, bool guard = true) {
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

    // ---- Templates (no real cap): the pieces the bisection leaves, each filled at once ----
    // The bisection above stops at a piece whose bound passes (kPassed) or that a template fills
    // better (kCoarse, coarseForm): its whole-piece form (chord_error.h pieceForm: one quadratic
    // form A >= the delay's Hessian all over the piece) asks for a level n >= kMinLevel,
    //     n = the least integer with speed bubbleMax(A's sides) / n^2 <= T,
    // the piece is not much worse shaped in A's metric than an equilateral triangle (area over
    // bound at least kShapeShare of the equilateral's: the template's triangles have the piece's
    // shape), and A is nearly the form at its centroid (within kCoarseSlack) or the n^2
    // triangles of the template are fewer than the two halves are expected to need (each half
    // asks for half the centroid's need, its excess of A over the centroid's form shrunk by
    // sqrt 2, its level rounded up by kRounding on average). With the form of chord_error.h
    // (second-order slack along the line of sight) this holds near the camera too. For a mesh
    // triangle (depth 0) whose A is within kNearlyUniform of its centroid's form, each half's
    // need is taken from the centroid's form on that half's own sides instead (halvesEstimate):
    // a well-shaped piece's halves keep about 3/4 of its need each, not 1/2, so the halves were
    // expected to be cheaper than they are, and a mesh triangle far from the camera (the plate
    // of docs/ACCURACY.md) was halved, its halves' grids rounding up to more triangles than its
    // own, or halved on down to pieces below kMinLevel and bisected to the end (the templates
    // then too small a share of the frame's leaves). Its level is now decided at once. On the
    // pieces the bisection made (near the camera, where the halves gain by adapting to the
    // varying form) the first estimate is kept: with the new one on every piece the box's
    // closest frame at T = 1e-4 x size made 14 % more triangles, at 2.8e-4 x size 0.86 of
    // uniform subdivision's (Refine.FewerTrianglesThanUniformSubdivisionAtEqualError: < 0.8).
    // A split that would halve a piece marked kCoarse at a level of kKeptLevel or more (the
    // longest-edge path of a neighbour reaching it) is not made: the neighbour is filled by its
    // own template instead (splitLongestPath's guard), so a template, once chosen, stays whole
    // (near the camera the bisection would otherwise cut every template its neighbours reach,
    // and each piece cut so pays the bisection's records instead of the template's few tens of
    // instructions per triangle). The neighbour's forced template rounds its level up, and the
    // neighbour may be stretched in the form's metric (no shape rule): where that template
    // would make more than kForceRatio times the triangles its bisection is expected to make
    // (its bubbles' bound over T, about the pieces halving down to T leaves), the split is made
    // after all and the template's halves are judged again (forcedTemplatePays). Guarding every
    // level without that rule templated the box's closest frame at T = 1e-3 x size into more
    // triangles than uniform subdivision's; guarding level 8 and more only left the box at
    // T = 1e-4 x size mostly bisected (docs/ACCURACY.md, "Templates").
    // The grid triangles of a piece at level n (the piece scaled by 1/n) are within T
    // (chord_error.h PieceForm). Each edge record gets the largest level of the pieces around
    // it, and both sides cut it into that many equal segments: no T-junctions, and the counts
    // depend on the pieces alone (deterministic). The template (tessellate.h) fills the piece:
    // grid triangles inside, a stitched ring along sides cut more finely than its level, every
    // ring triangle checked against A (the piece's level is raised until they pass: in the limit
    // the ring's triangles shrink to the sides' segments, each shorter than a grid edge of the
    // piece's first level). A piece that passed as a whole (and the mesh's triangles that needed
    // nothing) keeps level 1: its sides' extra points are fanned and, the delay being convex,
    // every triangle inside it is within its own bound.
    // A piece whose shape fails that rule and whose need is at most kAnisoMaxNeed is filled by
    // bisection in its form's metric instead (form_bisect.h: the grid would round its stretched
    // triangles up; the global bisection would pay its bounds and records per piece); its sides
    // get the counts FormBisection::sideSegments gives (each segment within 3 T / speed by the
    // form), in the same largest-count-around-each-edge rule, so its neighbours conform. Larger
    // needs are bisected on: their halves soon get grids, far cheaper per triangle (refine_bench
    // --count under callgrind: with no limit the plate at T = 1e-4, 1e-5 x size cost about 3
    // times main's instructions per triangle; with the limit at 32 the plate at 1e-3 x size 1.6
    // times per triangle; at 8 the sphere at 1e-4 x size lost the gain; docs/ACCURACY.md).
    // The template makes no record per output triangle; where it is not used (a level below
    // kMinLevel, or more triangles than the halves') the bisection goes on to pieces that
    // pass, which adapts more finely (docs/ACCURACY.md: the constants keep every trade ratio
    // within the issue's targets).
    static constexpr double kMinLevel = 2;
    static constexpr double kShapeShare = 0.3;
    static constexpr double kEquilateral = 2.598076211353316;  // 3 sqrt(3) / 2: area / bubbleMax of an equilateral triangle
    static constexpr double kCoarseSlack = 1.1;
    static constexpr double kRounding = 0.3;
    static constexpr double kTemplateShare = 0.5;  // least share of the leaves the templates' triangles must make (refineFrame)
    static constexpr uint32_t kKeptLevel = 2;      // least level of a template the guard keeps whole
    static constexpr double kForceRatio = 2;       // a forced template's triangles over its bisection's expected count, at most
    static constexpr double kAnisoCost = 2;        // FormBisection's triangles over the form's need (bubbleMax speed / T), about
    static constexpr double kAnisoMaxNeed = 16;    // the largest need (bubbleMax speed / T) FormBisection fills
    static constexpr uint32_t kNoCap = 1u << 20;   // formLevel without the max_segments cap
    static constexpr double kNearlyUniform = 1.2;  // a mesh triangle's A within this of its centroid's form: halvesEstimate

    // True when the whole-piece form of the piece with corners' shape offsets a, b, c (chord_error.h
    // pieceForm: A >= the delay's Hessian on the whole piece) bounds the piece itself within the
    // tolerance: speed bubbleMax(A's sides) <= T. A sound bound of the piece as chordErrorOfPoints'
    // is; tighter than its third-order term near the camera (the form's slack there is second
    // order along the line of sight), so a piece it passes needs no further split.
    bool passesByForm(const Vec3& a, const Vec3& b, const Vec3& c) const {
        const Vec3 s[3] = {a, b, c};
        return pieceFormWithin(world.motion, r_now, s, bound_speed, settings.tolerance);
    }

    // Whether piece id's forced template (its form made by coarseForm(id, s, true)) makes at
    // most kForceRatio times the triangles its bisection is expected to: n^2 against its
    // bubbles' bound over T (at least 1).
    bool forcedTemplatePays(uint32_t id) {
        const uint32_t* v = rt[id].v;
        const double c[3] = {edgeOf(id, 0).c, edgeOf(id, 1).c, edgeOf(id, 2).c};
        const ChordError ce = pointsBound(c, r_term_data[v[0]], r_term_data[v[1]], r_term_data[v[2]]);
        const double expected = std::max(1.0, ce.quadratic / settings.tolerance);
        return fillEstimate(scratch.form_of[id], kNoCap) <= kForceRatio * expected;
    }

    // The form of piece id (its corners' shape offsets s) when it is finite and (unless `force`:
    // the depth limit stopped the piece) the piece is better filled by a template (above); kept
    // in scratch.forms, indexed by scratch.form_of[id].
    bool coarseForm(uint32_t id, const Vec3 s[3], bool force) {
        std::vector<uint32_t>& form_of = scratch.form_of;
        if (form_of.size() <= id) form_of.resize(std::max<size_t>(r_tri_size, size_t(id) + 1), kUnset);
        form_of[id] = kUnset;
        const PieceForm pf = pieceForm(world.motion, r_now, s);
        if (!pf.finite) return false;
        const double whole = bubbleMax(pf.c[0], pf.c[1], pf.c[2]);
        const double need = bound_speed * whole / settings.tolerance;
        // Its shape in the form's metric: area over bound, against the equilateral's (the
        // template's triangles are the piece's shape, scaled).
        const double cuv = 0.5 * (pf.c[0] + pf.c[2] - pf.c[1]);
        const double area = std::sqrt(std::max(0.0, pf.c[0] * pf.c[2] - cuv * cuv));
        const bool shaped = area >= kShapeShare * kEquilateral * whole;
        // A piece the grid would fill with stretched triangles, and that needs at most
        // kAnisoMaxNeed, is filled by the bisection in the form's metric (form_bisect.h) instead:
        // about kAnisoCost times its need. (Larger ones are bisected on: their halves soon have
        // a shape the grid fills at a few tens of instructions per triangle, against the local
        // bisection's few hundred.)
        const double xa = std::ceil(std::sqrt(need));
        const bool aniso = !shaped && need <= kAnisoMaxNeed;
        if (!force) {
            const double centre = bubbleMax(pf.centre[0], pf.centre[1], pf.centre[2]);
            {  // the fill's triangles against the halves' (above)
                const double xc2 = bound_speed * centre / settings.tolerance;
                const double infl = whole / centre;
                const double cost_t = aniso ? kAnisoCost * need : xa * xa;
                double cost_b;
                if (infl <= kNearlyUniform && rt[id].depth == 0) {
                    cost_b = halvesEstimate(pf, bound_speed / settings.tolerance, infl);
                } else {
                    cost_b = 2 * halfCost(0.5 * xc2 * halfGrowth(infl));
                }
                if (!(cost_t <= cost_b) && !(whole <= kCoarseSlack * centre)) return false;
            }
            if (!aniso && !shaped) return false;
            if (!(need >= kMinLevel * kMinLevel)) return false;
        }
        form_of[id] = uint32_t(scratch.forms.size());
        scratch.forms.push_back(pf);
        scratch.form_aniso.push_back(aniso ? 1 : 0);
        return true;
    }

    // The triangles the two halves of a piece are expected to make (coarseForm): each half's need
    // from the centroid's form on its own sides (the piece halved on its longest side in that
    // form: a half-side, the median, a whole side; the median's value by the parallelogram law,
    // which holds for any quadratic form), its excess of A over the centroid's form shrunk by
    // sqrt 2, its level rounded up by kRounding on average. per: need per unit of bubbleMax.
    static double halvesEstimate(const PieceForm& pf, double per, double infl) {
        const double* q = pf.centre;
        int k = 0;  // the longest side (k -> k + 1)
        if (q[1] > q[k]) k = 1;
        if (q[2] > q[k]) k = 2;
        const double qc = q[k], qa = q[kSucc[k]], qb = q[kSucc[kSucc[k]]];  // sides k + 1, k + 2
        const double med = std::max(0.0, 0.25 * (2 * qa + 2 * qb - qc));
        const double grow = halfGrowth(infl);
        double cost = 0;
        for (const double other : {qb, qa}) cost += halfCost(per * bubbleMax(0.25 * qc, med, other) * grow);
        return cost;
    }
    // A half's excess of A over the centroid's form: the piece's (infl - 1) shrunk by sqrt 2.
    static double halfGrowth(double infl) { return 1 + (infl - 1) / 1.4142135623730951; }
    // The triangles a half of need `child` is expected to make: its level rounded up by kRounding
    // on average, squared; at least one.
    static double halfCost(double child) {
        return std::max(1.0, (std::sqrt(child) + kRounding) * (std::sqrt(child) + kRounding));
    }

    // The triangles the fill of form f is expected to make: n^2 for a grid of level n (at most
    // cap), kAnisoCost times the form's need for the bisection in its metric.
    double fillEstimate(uint32_t f, uint32_t cap) const {
        const PieceForm& pf = scratch.forms[f];
        if (scratch.form_aniso[f]) return std::max(1.0, kAnisoCost * bound_speed * bubbleMax(pf.c[0], pf.c[1], pf.c[2]) / settings.tolerance);
        const double n = formLevel(pf, cap);
        return n * n;
    }

    // The least level n >= 1 with speed bubbleMax(c) / n^2 <= T, at most `cap`.
    uint32_t formLevel(const PieceForm& pf, uint32_t cap) const {
        const double need = bound_speed * bubbleMax(pf.c[0], pf.c[1], pf.c[2]) / settings.tolerance;
        if (!(need <= double(cap) * double(cap))) return r_level_scale < 1 ? std::max(1u, uint32_t(cap * r_level_scale)) : cap;
        uint32_t n = std::max(1u, uint32_t(std::ceil(std::sqrt(need))));
        while (double(n) * double(n) < need) ++n;
        if (r_level_scale < 1) n = std::max(1u, uint32_t(double(n) * r_level_scale));
        return std::min(n, cap);
    }

    // The first id of the count - 1 points that cut edge record e (ends a, b) into equal
    // segments, made once, from the lower id end: point i of the edge is lo + (hi - lo) i / count.
    uint32_t edgePoints(uint32_t e, uint32_t a, uint32_t b, uint32_t count) {
        uint32_t& first = scratch.edge_first[e];
        if (first != kUnset) return first;
        first = uint32_t(r_nv + r_rest.size());
        const Vec3 lo = restOfId(std::min(a, b)), hi = restOfId(std::max(a, b));
        for (uint32_t i = 1; i < count; ++i) {
            const double t = double(i) / double(count);
            r_rest.push_back(lo * (1 - t) + hi * t);
        }
        return first;
    }

    // Fills one leaf (corners v, edge records e, on mesh triangle src) with its template at
    // level N (form: the piece's form, or null for a piece within the bound as a whole) and
    // appends the triangles. base: the output index of the first new point.
    void fillLeaf(uint32_t src, const uint32_t v[3], const uint32_t e[3], uint32_t N, const PieceForm* form,
                  bool unsplit, size_t base, uint32_t cap, bool aniso = false) {
        auto outOf = [&](uint32_t g) { return g < r_nv ? vertex_out[g] : uint32_t(base + (g - r_nv)); };
        const uint32_t* count = scratch.edge_count.data();  // segments - 1
        const int n[3] = {int(count[e[0]]) + 1, int(count[e[1]]) + 1, int(count[e[2]]) + 1};
        if (N == 1 && n[0] == 1 && n[1] == 1 && n[2] == 1) {
            addOutput(src, {outOf(v[0]), outOf(v[1]), outOf(v[2])});
            return;
        }
        TessForm tf;
        if (form) {
            tf.cu = form->c[0];
            tf.cv = form->c[2];
            tf.cuv = 0.5 * (form->c[0] + form->c[2] - form->c[1]);
            tf.limit = settings.tolerance / bound_speed;
        }
        std::vector<std::array<uint32_t, 3>>& local = scratch.local;
        // A fill's local points 0..2 are the corners, then each side's n[k] - 1 shared points from
        // side_first(k): both mapped to the frame's point ids (the sides' points in edge order).
        auto mapCornersAndSides = [&](std::vector<uint32_t>& map, auto side_first) {
            for (int k = 0; k < 3; ++k) map[size_t(k)] = v[k];
            for (int k = 0; k < 3; ++k) {
                if (n[k] == 1) continue;
                const uint32_t a = v[k], b = v[kSucc[k]];
                const uint32_t first = edgePoints(e[k], a, b, uint32_t(n[k]));
                for (int i = 1; i < n[k]; ++i)
                    map[side_first(k) + uint32_t(i - 1)] = first + uint32_t(a < b ? i - 1 : n[k] - i - 1);
            }
        };
        // A piece stretched in its form's metric: the bisection in that metric (form_bisect.h),
        // unless that fails (past cap^2 triangles, or a fan of slivers along a side held to its
        // points): then the grid below, on the same side counts.
        if (aniso && form) {
            FormBisection& fb = scratch.bisection;
            if (fb.fill(tf, n, size_t(cap) * size_t(cap), local)) {
                std::vector<uint32_t>& map = scratch.local_map;
                map.resize(fb.innerFirst() + fb.params().size());
                mapCornersAndSides(map, [&](int k) { return fb.sideFirst(k); });
                const Vec3 p0 = restOfId(v[0]), p1 = restOfId(v[1]), p2 = restOfId(v[2]);
                uint32_t id = uint32_t(r_nv + r_rest.size());
                for (size_t j = 0; j < fb.params().size(); ++j) {
                    const double l1 = fb.params()[j][0], l2 = fb.params()[j][1];
                    r_rest.push_back(p0 * (1 - l1 - l2) + p1 * l1 + p2 * l2);
                    map[fb.innerFirst() + j] = id++;
                }
                for (uint32_t& g : map) g = outOf(g);  // each point's output id once, not once per triangle on it
                for (const auto& t : local) addOutput(src, {map[t[0]], map[t[1]], map[t[2]]});
                if (unsplit && local.size() > 1) ++out.refined_triangles;
                return;
            }
        }
        int level = int(N);
        for (;;) {
            const TessLayout probe(level, n);
            const bool checked = form && probe.level() > 1;
            if (probe.tessellate(checked ? &tf : nullptr, local)) break;
            if (probe.level() >= int(cap)) {  // the ring cannot be made to pass: limited
                r_limited[src] = 1;
                probe.tessellate(nullptr, local);
                break;
            }
            level = probe.level() + 1;
        }
        const TessLayout lay(level, n);
        // Step: the leaf's points: corners, its sides' shared points, its own inner points.
        std::vector<uint32_t>& map = scratch.local_map;
        map.resize(lay.count());
        mapCornersAndSides(map, [&](int k) { return lay.sideFirst(k); });
        if (lay.innerCount() > 0) {
            const Vec3 p0 = restOfId(v[0]), p1 = restOfId(v[1]), p2 = restOfId(v[2]);
            uint32_t id = uint32_t(r_nv + r_rest.size());
            const int L = lay.level();
            auto add = [&](double l1, double l2) { r_rest.push_back(p0 * (1 - l1 - l2) + p1 * l1 + p2 * l2); };
            if (L == 1) {
                add(1.0 / 3, 1.0 / 3);
            } else {
                for (int j = 1; j + 2 <= L; ++j)
                    for (int i = 1; i + j + 1 <= L; ++i) add(double(i) / L, double(j) / L);
            }
            for (uint32_t p = lay.innerFirst(); p < lay.count(); ++p) map[p] = id++;
        }
        for (uint32_t& g : map) g = outOf(g);  // each point's output id once, not once per triangle on it
        for (const auto& t : local) addOutput(src, {map[t[0]], map[t[1]], map[t[2]]});
        if (unsplit && local.size() > 1) ++out.refined_triangles;
    }

    // Every leaf in record order filled by its template. When the templates would pass
    // settings.max_triangles, every level is scaled down until they fit and over_budget is set
    // (the tolerance is not met then, and the rings are not checked); false (nothing emitted)
    // when even the leaves alone do not fit: they are emitted as they are.
    double r_level_scale = 1;
    bool templateLeaves() {
        const uint32_t cap = uint32_t(std::max(settings.max_segments, 2));
        std::vector<uint32_t>& count = scratch.edge_count;  // per edge record: its segments - 1
        auto clear = [](std::vector<uint32_t>& v, size_t n, int byte) {
            v.resize(n);
            std::memset(v.data(), byte, n * sizeof(uint32_t));
        };
        std::vector<uint32_t>& form_of = scratch.form_of;
        if (form_of.size() < r_tri_size) form_of.resize(r_tri_size, kUnset);
        // Step: each record's level, and each edge's count (the largest level around it).
        // The estimate bounds the output: a leaf makes at most N^2 + 2 + the extra segments of its
        // sides (tessellate.h), an edge is on about two leaves.
        double estimate = 0;
        r_level_scale = 1;
        auto levelPass = [&](uint32_t id) {
            RTri& t = rt[id];
            if (t.state == kFailed) {  // the depth limit stopped it: its template is what it gets
                const Vec3 s[3] = {r_terms[t.v[0]].s, r_terms[t.v[1]].s, r_terms[t.v[2]].s};
                coarseForm(id, s, true);
            } else if (t.state != kCoarse) {
                return;
            }
            if (form_of[id] == kUnset) return;
            const PieceForm& pf = scratch.forms[form_of[id]];
            const uint32_t n = formLevel(pf, cap);
            // A form asking for more than max_segments segments gets that many: the tolerance is
            // not met there, counted as the depth limit is.
            if (n == cap && formLevel(pf, kNoCap) > cap) r_limited[t.src] = 1;
            if (scratch.form_aniso[form_of[id]] && !out.over_budget) {
                // The bisection's sides: each cut so that its segments pass alone (form_bisect.h).
                estimate += fillEstimate(form_of[id], cap);
                const double limit = settings.tolerance / bound_speed;
                for (int c = 0; c < 3; ++c) {
                    const uint32_t k = uint32_t(FormBisection::sideSegments(pf.c[c], limit, int(cap))) - 1;
                    count[t.edge[c]] = std::max(count[t.edge[c]], k);
                }
                return;
            }
            estimate += double(n) * double(n);
            for (int c = 0; c < 3; ++c) count[t.edge[c]] = std::max(count[t.edge[c]], n - 1);
        };
        auto levels = [&] {
            estimate = 3.0 * double(r_nt) + 3.0 * double(r_tri_size - r_nt);
            clear(count, r_edges.size(), 0);
            for (uint32_t f = 0; f < r_nt; ++f)
                if (r_init[f]) levelPass(f);
            for (uint32_t id = r_nt; id < r_tri_size; ++id) levelPass(id);
            for (uint32_t c : count) estimate += 2.0 * double(c);
        };
        levels();
        for (int round = 0; settings.max_triangles > 0 && estimate > double(settings.max_triangles); ++round) {
            out.over_budget = true;
            const double leaves = 3.0 * double(r_tri_size);
            if (round == 8 || double(settings.max_triangles) <= leaves) return false;
            r_level_scale *= 0.95 * std::sqrt((double(settings.max_triangles) - leaves) / (estimate - leaves));
            levels();
        }
        // Step: the templates, in record order.
        clear(scratch.edge_first, r_edges.size(), 0xff);  // kUnset
        // (The estimate counts 3 per leaf: about 1 is made.)
        const size_t expect = size_t(std::min(std::max(0.0, estimate - 2.0 * double(r_tri_size)), 1e8));
        out.triangles.reserve(out.triangles.size() + expect);
        out.source_triangles.reserve(out.source_triangles.size() + expect);
        r_rest.reserve(r_rest.size() + expect / 2 + 16);
        const size_t base = out.positions.size();
        auto fillRecord = [&](uint32_t id) {
            const RTri& t = rt[id];
            const bool formed = (t.state == kCoarse || t.state == kFailed) && form_of[id] != kUnset;
            const PieceForm* pf = formed ? &scratch.forms[form_of[id]] : nullptr;
            const uint32_t v[3] = {t.v[0], t.v[1], t.v[2]}, e[3] = {t.edge[0], t.edge[1], t.edge[2]};
            const bool aniso = pf && scratch.form_aniso[form_of[id]] && !out.over_budget;
            fillLeaf(t.src, v, e, pf ? formLevel(*pf, cap) : 1, out.over_budget ? nullptr : pf, t.depth == 0, base, cap, aniso);
        };
        for (uint32_t f = 0; f < r_nt; ++f) {
            if (r_init[f]) {
                fillRecord(f);
                continue;
            }
            const auto& tri = world.mesh.triangles[f];
            if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;  // no area: dropped
            const auto& te = world.triangle_edges[f];
            if ((count[te[0]] | count[te[1]] | count[te[2]]) == 0) {  // untouched, no finer neighbour
                out.triangles.push_back({vertex_out[tri[0]], vertex_out[tri[1]], vertex_out[tri[2]]});
                out.source_triangles.push_back(f);
                continue;
            }
            const uint32_t v[3] = {tri[0], tri[1], tri[2]};
            const uint32_t e[3] = {te[0], te[1], te[2]};
            fillLeaf(f, v, e, 1, nullptr, true, base, cap);
        }
        for (uint32_t id = r_nt; id < r_tri_size; ++id) fillRecord(id);
        return true;
    }

    uint32_t outId(uint32_t id) {
        if (vertex_out[id] == kUnset) vertex_out[id] = emit(eventOfId(id), restOfId(id));
        return vertex_out[id];
    }

    // The clip point of the leaf side a -> b at cap `cap`: keyed by the two ends, parametrised
    // from the smaller id, so both leaves on the side share it (on a whole mesh edge it is the
    // point crossingPoint makes in vertex mode).
    uint32_t leafCrossing(uint32_t a, uint32_t b, int cap) {
        const uint32_t lo = std::min(a, b), hi = std::max(a, b);
        auto [it, inserted] = r_crossings[cap].try_emplace((uint64_t(lo) << 32) | hi, kUnset);
        if (!inserted) return it->second;
        const double s = cutSegment(view, capOfId(lo, cap), capOfId(hi, cap));
        const uint32_t id = crossingAt(
            s, side[lo], side[hi], [&](int end) { return outId(end == 0 ? lo : hi); },
            [&] { return restOfId(lo) * (1 - s) + restOfId(hi) * s; });
        return it->second = id;
    }

    void emitLeaf(uint32_t src, const uint32_t v[3]) {
        const Side s[3] = {side[v[0]], side[v[1]], side[v[2]]};
        if (s[0] == Side::Inside && s[1] == Side::Inside && s[2] == Side::Inside) {
            addOutput(src, {outId(v[0]), outId(v[1]), outId(v[2])});
            return;
        }
        uint32_t polygon[6];
        const int n = clipToSpan(3, s, [&](int i) { return outId(v[i]); },
                                 [&](int i, int j, int cap) { return leafCrossing(v[i], v[j], cap); }, polygon);
        for (int k = 1; k + 1 < n; ++k) addOutput(src, {polygon[0], polygon[k], polygon[k + 1]});
    }

    // The whole frame with the tolerance: bounds of every live mesh triangle from its corners and
    // edge midpoints (cut in batches), splits where a bound exceeds the tolerance, then the leaves
    // in mesh order. `live`: one flag per chunk (the cull), or null.
    void refineFrame(const std::vector<uint8_t>* live) {
        rt = r_tri.get();
        r_nv = uint32_t(world.mesh.positions.size());
        r_nt = uint32_t(world.mesh.triangles.size());
        const size_t ne = world.edges.size();
        r_ne = uint32_t(ne);
        int levels = 1;
        while (levels < 30 && (int64_t(1) << levels) < int64_t(std::max(settings.max_segments, 2))) ++levels;
        r_max_depth = uint32_t(2 * levels);  // about max_segments pieces along each direction of a triangle
        auto isLive = [&](size_t f) { return !live || (*live)[f / kChunkTriangles]; };

        // Step: images of every vertex.
        r_pos.resize(r_nv);
        r_time.resize(r_nv);
        cutRestLocalBatch(anchor, world.motion, world.mesh.positions.data(), r_nv, r_pos.data(), r_time.data());
        const bool caps = world.cap_a_real || world.cap_b_real;
        r_caps = caps;
        r_templates = !caps;
        scratch.forms.clear();
        scratch.form_aniso.clear();
        scratch.form_of.clear();
        scratch.coarse.clear();
        if (caps) classifyVertices(live);  // else every side is Inside (classified below, if anything is refined)

        // Step: the corners' bound (chordErrorFromCorners) passes most triangles that need no
        // refinement; the others get the a-priori bound (chordErrorOfBubbles).
        std::vector<uint32_t>& candidates = scratch.candidates;
        std::vector<uint32_t>& failing = scratch.failing;
        candidates.clear();
        failing.clear();
        double expected_pieces = 0;
        r_now = nowBase(view, world.motion);
        r_terms.resize(r_nv);  // the bound's terms, once per vertex
        for (size_t i = 0; i < r_nv; ++i) {
            const Event e{r_time[i], r_pos[i]};
            r_terms[i].s = shapeOfEvent(world.motion, e);
            r_terms[i].xm = normMOfEvent(anchor, world.motion, e);
        }
        // (The corners' bounds have the factor |u|: a displaced bound takes the full one.)
        const bool displaced = view.sheared() || settings.displacement >= 0;
        // The corners' spread (chord_error.h cornerSpread: the largest |u|_M^2 of a triangle's
        // sides) from each mesh edge's |u|_M^2, made once per edge instead of once per side of
        // each triangle: |u|_M^2 is even in u (negating u negates its terms exactly), and the
        // largest of three does not depend on their order, so each triangle's spread is
        // cornerSpread's bit for bit. (With a cull, per triangle: most edges may be culled.)
        std::vector<double>& spread = scratch.spread;
        const bool edge_spread = !displaced && !live;
        // Every triangle passes when the whole mesh does: its largest spread D with the least
        // |x|_M of all its vertices X (passesFromSpread(D, {X, X, X})). Each triangle's d2 is at
        // most D (both the same std::max chain from 0 over the same spreads, which skips a NaN)
        // and its xmin at least X (no xm is NaN), and passesFromSpread is monotone in both as
        // rounded (chord_error.h): fl(4 d2), fl(xmin xmin) and fl(beta d2) grow with their
        // operand, and fl(3 (1 - beta^2) T) >= 0 is one factor of xmin. So the verdict is the
        // triangles' own (no candidates), without the pass over the triangles (with real caps
        // that pass also counts the clipped triangles: it is made then).
        bool whole_passes = false;
        if (edge_spread) {
            // The least |x|_M of all vertices, and their sum: NaN when one is (an infinity of
            // each sign makes NaN too, and the pass below is only skipped then). (Its own loop:
            // the terms' loop above stays vectorised.)
            double xm_least = INFINITY, xm_sum = 0;
            for (size_t i = 0; i < r_nv; ++i) {
                const double xm = r_terms[i].xm;
                xm_least = std::min(xm_least, xm);
                xm_sum += xm;
            }
            spread.resize(ne);
            const Vec3 v = world.motion.velocity;
            const double k = world.motion.one_minus_beta2;
            double d2_most = 0;
            for (size_t e = 0; e < ne; ++e) {
                const Vec3 u = r_terms[world.edges[e].hi].s - r_terms[world.edges[e].lo].s;
                const double uv = dot(u, v);
                const double d2 = uv * uv + k * norm2(u);
                spread[e] = d2;
                d2_most = std::max(d2_most, d2);
            }
            const double xm_all[3] = {xm_least, xm_least, xm_least};
            whole_passes = !caps && xm_sum == xm_sum && passesFromSpread(d2_most, xm_all, world.motion, settings.tolerance);
        }
        // (The arrays and the tolerance read through locals: the compiler cannot tell that
        // `candidates`'s stores leave them alone, and would load them again per triangle.)
        const std::array<uint32_t, 3>* const tris = world.mesh.triangles.data();
        const std::array<uint32_t, 3>* const tri_edges = world.triangle_edges.data();
        const VTerms* const corner_terms = r_terms.data();
        const double* const spreads = spread.data();
        const double tolerance = settings.tolerance;
        for (size_t f = whole_passes ? r_nt : 0; f < r_nt; ++f) {
            if (!isLive(f)) continue;
            const auto& t = tris[f];
            if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) continue;  // no area: dropped at output, never split
            if (caps) {
                const Side s0 = side[t[0]];
                if (s0 != Side::Inside && side[t[1]] == s0 && side[t[2]] == s0) continue;  // wholly before or after
                if (s0 != Side::Inside || side[t[1]] != Side::Inside || side[t[2]] != Side::Inside) ++out.clipped_triangles;
            }
            // The terms are the corners' own (shapeOfEvent, normMOfEvent): the corners' bound is
            // chordErrorFromCorners' bit for bit, from the one spread both tests use.
            if (!displaced) {
                const double xc[3] = {corner_terms[t[0]].xm, corner_terms[t[1]].xm, corner_terms[t[2]].xm};
                double d2;
                if (edge_spread) {
                    const auto& te = tri_edges[f];
                    d2 = std::max(std::max(std::max(0.0, spreads[te[0]]), spreads[te[1]]), spreads[te[2]]);
                } else {
                    const Vec3 sc[3] = {r_terms[t[0]].s, r_terms[t[1]].s, r_terms[t[2]].s};
                    d2 = cornerSpread(sc, world.motion);
                }
                if (passesFromSpread(d2, xc, world.motion, tolerance)) continue;
                if (!(chordErrorFromSpread(d2, xc, world.motion) > tolerance)) continue;
            }
            candidates.push_back(uint32_t(f));
        }
        // Each mesh edge's bound made once and kept for the splits (edgeOf makes the same bits:
        // ends in id order), when the candidates are enough to pay for the edge records' reset
        // (a large mesh with a few candidates computes their edges per triangle instead).
        const bool keep_edges = !candidates.empty() && 4 * candidates.size() >= ne;
        if (keep_edges) r_edges.assign(ne, REdge{kUnset, NAN, NAN, NAN});
        REdge* const kept = keep_edges ? r_edges.data() : nullptr;
        const VTerms* const terms = r_terms.data();
        for (uint32_t f : candidates) {
            const auto& te = world.triangle_edges[f];
            double c[3];
            for (int k = 0; k < 3; ++k) {
                const uint32_t e = te[k];
                if (kept) {
                    REdge& re = kept[e];
                    if (re.len != re.len) {
                        const Edge& ed = world.edges[e];
                        storeEdge(re, edgeBubble(world.motion, r_now, terms[ed.lo], terms[ed.hi]));
                    }
                    c[k] = re.c;
                } else {
                    const Edge& ed = world.edges[e];
                    c[k] = edgeBubble(world.motion, r_now, terms[ed.lo], terms[ed.hi]).c;
                }
            }
            // The corners' terms in place (the drain's pointsBound on the same record: the same
            // bits); the sides' |u|_M^2 are the edges' spreads when made (normM2 of the side
            // either way round: the same bits, chord_error.h chordErrorOfSides).
            const auto& t = world.mesh.triangles[f];
            const VTerms &k0 = terms[t[0]], &k1 = terms[t[1]], &k2 = terms[t[2]];
            ChordError ce;
            if (edge_spread) {
                auto sides = [&](double side2[3]) {
                    for (int k = 0; k < 3; ++k) side2[k] = spreads[te[k]];
                    return std::min(std::min(k0.xm, k1.xm), k2.xm);
                };
                ce = chordErrorOfSides(world.motion, bound_speed, c, sides, settings.tolerance);
            } else {
                ce = pointsBound(c, k0, k1, k2);
            }
            const double bound = ce.bound;
            if (bound > settings.tolerance &&
                !(ce.quadratic <= settings.tolerance && passesByForm(k0.s, k1.s, k2.s))) {
                // (Room for every mesh triangle's, made when the first one fails: set for the failing only.)
                if (failing.empty() && scratch.quadratic.size() < r_nt) scratch.quadratic.resize(r_nt);
                failing.push_back(f);
                scratch.quadratic[f] = ce.quadratic;
                // About bound / T pieces once halved down to T (the error falls about as the area).
                expected_pieces += std::min(bound / settings.tolerance, 1e6);
            }
        }
        // Nothing to refine on a simple mesh that exists throughout: vertex mode's output.
        if (failing.empty() && !caps && world.simple) {
            out.positions = std::move(r_pos);
            out.emission_times = std::move(r_time);
            out.rest_points = world.mesh.positions;
            out.triangles = world.mesh.triangles;
            out.source_triangles.resize(r_nt);
            for (size_t f = 0; f < r_nt; ++f) out.source_triangles[f] = uint32_t(f);
            return;
        }
        // Room for the pieces and points the refinement is expected to make (growth would copy them).
        // At most a million: reserving is only a saving, never a bound (max_triangles is).
        size_t expect = size_t(std::min(2 * expected_pieces, 1e6));
        if (settings.max_triangles > 0) expect = std::min(expect, settings.max_triangles);

        // Step: split until every piece passes.
        if (!failing.empty()) {
            if (!keep_edges) r_edges.assign(ne, REdge{kUnset, NAN, NAN, NAN});
            reserveTris(r_nt + expect);  // records made on first touch (ensureBase)
            r_tri_size = r_nt;
            r_edges.reserve(ne + 2 * expect);
            for (auto* v : {&r_pos, &r_rest}) v->reserve(v->size() + expect);
            r_terms.reserve(r_terms.size() + expect);
            r_time.reserve(r_time.size() + expect);
            if (caps) {  // the clipped leaves emit their points and triangles one by one (emitLeaf)
                out.positions.reserve(out.positions.size() + expect);
                out.emission_times.reserve(out.emission_times.size() + expect);
                out.rest_points.reserve(out.rest_points.size() + expect);
                out.triangles.reserve(out.triangles.size() + expect);
                out.source_triangles.reserve(out.source_triangles.size() + expect);
            }
            r_init.assign(r_nt, 0);
            r_init_data = r_init.data();
            r_edge_data = r_edges.data();
            r_term_data = r_terms.data();
            r_limited.assign(r_nt, 0);
            r_leaves = r_nt;
            std::vector<uint32_t>& stack = scratch.stack;
            for (uint32_t f : failing) {
                ensureBase(f);
                // Still as the mesh has it (only a split changes a record's corners, and it
                // deepens it; a neighbour's split may have made the record): the first pass's
                // verdict stands, from the same terms and edge records (edgeOf: the same bits).
                if (rt[f].depth == 0 && rt[f].state == kUnknown) rt[f].state = kBoundFailed;
                stack.push_back(f);
                drain(stack);
            }
            // Step: templates only where they make most of the output: else the few coarse
            // pieces are bisected on like the rest (the templates' pass over every leaf would
            // cost more than it saves).
            if (r_templates && !scratch.forms.empty() && !out.over_budget) {
                const uint32_t cap = uint32_t(std::max(settings.max_segments, 2));
                double templated = 0;
                auto share = [&](uint32_t id) {
                    if (rt[id].state == kCoarse) templated += fillEstimate(scratch.form_of[id], cap);
                };
                // The records still coarse, in id order (as a pass over all records would meet
                // them), from the list of those marked: no pass over every record.
                std::vector<uint32_t>& coarse = scratch.coarse;
                std::sort(coarse.begin(), coarse.end());
                coarse.erase(std::unique(coarse.begin(), coarse.end()), coarse.end());
                for (uint32_t id : coarse) share(id);
                if (templated < kTemplateShare * double(r_leaves)) {
                    r_templates = false;
                    for (uint32_t id : coarse) {
                        if (rt[id].state != kCoarse) continue;
                        rt[id].state = kUnknown;
                        stack.push_back(id);
                    }
                    drain(stack);
                    scratch.forms.clear();
                    scratch.form_aniso.clear();
                }
            }
        }
        // Step (no real cap): the output's points, once the splits are done: the visible vertices
        // (classifyVertices, in input order), then the points the splits (and the templates) made,
        // in room for all of them made once. Without templates the room is exact: each output
        // array is allocated once per frame and its points copied once.
        // Templates fill the leaves when the splits left coarse pieces (no real cap: r_templates).
        const bool filling = r_templates && !failing.empty() && !out.over_budget && !scratch.forms.empty();
        if (!caps) {
            const size_t points = r_nv + (filling ? std::max(r_rest.size(), expect) : r_rest.size());
            out.positions.reserve(points);
            out.emission_times.reserve(points);
            out.rest_points.reserve(points);
            classifyVertices(live);
        }
        // Step (no real cap): the leaves filled by their templates.
        // (Without a coarse piece every leaf is its own output triangle: emitted below as they are.)
        const bool templated = filling && templateLeaves();
        if (!failing.empty()) {
            for (uint8_t l : r_limited) out.limited_triangles += l;
            // Step: the exact images of the new points (splits' and templates'), in one batch.
            const size_t n_new = r_rest.size();
            r_pos.resize(r_nv + n_new);
            r_time.resize(r_nv + n_new);
            cutRestLocalBatch(anchor, world.motion, r_rest.data(), n_new, r_pos.data() + r_nv, r_time.data() + r_nv);
        }

        // Step: the leaves in record order: the mesh's triangles (or the piece each keeps), then
        // the pieces the splits appended.
        if (!caps) {
            // Nothing clipped: every point a split made is a corner of some leaf, so the points
            // follow the mesh's visible vertices in id order, copied in bulk.
            const size_t base = out.positions.size(), n_new = r_rest.size();
            out.positions.insert(out.positions.end(), r_pos.begin() + r_nv, r_pos.begin() + r_nv + n_new);
            out.emission_times.insert(out.emission_times.end(), r_time.begin() + r_nv, r_time.begin() + r_nv + n_new);
            out.rest_points.insert(out.rest_points.end(), r_rest.begin(), r_rest.begin() + n_new);
            if (templated) return;  // the triangles are made
            vertex_out.resize(r_nv + n_new);
            for (size_t k = 0; k < n_new; ++k) vertex_out[r_nv + k] = uint32_t(base + k);
            const size_t n_out = r_nt + (r_tri_size > r_nt ? r_tri_size - r_nt : 0);
            out.triangles.reserve(out.triangles.size() + n_out);
            out.source_triangles.reserve(out.source_triangles.size() + n_out);
            auto leaf = [&](uint32_t src, const uint32_t* v) {
                addOutput(src, {vertex_out[v[0]], vertex_out[v[1]], vertex_out[v[2]]});
            };
            for (size_t f = 0; f < r_nt; ++f) {
                const uint32_t* v = (r_init.empty() || !r_init[f]) ? world.mesh.triangles[f].data() : rt[f].v;
                leaf(uint32_t(f), v);
            }
            for (size_t id = r_nt; id < r_tri_size; ++id) leaf(rt[id].src, rt[id].v);
            return;
        }
        for (size_t f = 0; f < r_nt; ++f) {
            if (!isLive(f)) continue;
            if (r_init.empty() || !r_init[f]) {
                const auto& t = world.mesh.triangles[f];
                const uint32_t v[3] = {t[0], t[1], t[2]};
                emitLeaf(uint32_t(f), v);
            } else {
                emitLeaf(uint32_t(f), rt[f].v);
            }
        }
        for (size_t id = r_nt; id < r_tri_size; ++id)
            if (isLive(rt[id].src)) emitLeaf(rt[id].src, rt[id].v);
    }

    // Step: a whole triangle clipped to the span in vertex mode (Sutherland-Hodgman over the caps).
    void clipWhole(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const Side s[3] = {side[tri[0]], side[tri[1]], side[tri[2]]};
        uint32_t polygon[6];
        const int n = clipToSpan(3, s, [&](int i) { return vertexPoint(tri[size_t(i)]); },
                                 [&](int i, int, int cap) { return crossingPoint(world.triangle_edges[f][size_t(i)], cap); },
                                 polygon);
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
        const uint32_t out_id = crossingAt(
            s, sfrom, sto, [&](int end) { return restPoint(v, end == 0 ? from : to, points); },
            [&] {
                double lm[3];
                for (int c = 0; c < 3; ++c) lm[c] = l0[c] * (1 - s) + l1[c] * s;
                return restAt(v, lm);
            });
        return *id = out_id;
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
        if (inside) addOutput(f, {vertexPoint(tri[0]), vertexPoint(tri[1]), vertexPoint(tri[2])});
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

namespace {

// The cut in the view's own frame (sliceWorld before the shear).
ApparentMesh sliceUnsheared(const World4D& world, const ViewSurface& view, const SliceSettings& requested) {
    // Model only what the cut requires: on a hyperplane, or at rest, the map from the rest
    // surface to the apparent one is affine, so straight edges are exact and nothing is refined
    // (at rest under a shear it is not: chord_error.h displacedChordError).
    SliceSettings settings = requested;
    const bool at_rest = world.motion.beta == 0 && !view.sheared() && !(settings.displacement > 0);
    // At rest on the past cone with a real cap, the caps' clip curves are circles: those alone
    // are refined (FrameBuilder::restPlan).
    // A motion that is not uniform (worldline.h) is otherwise cut in vertex mode: exact points on
    // the true worldlines (lightcone.h sends each cut to crossWorldline).
    const bool uniform = isUniform(world.motion);
    // A motion that is not uniform, with a tolerance: worldline_refine.h (no real cap; the callers
    // refuse a tolerance for such an object that begins or ends existing, and a moving camera).
    if (!uniform && settings.tolerance > 0 && !world.cap_a_real && !world.cap_b_real && !(settings.displacement >= 0) &&
        !world.empty())
        return refineWorldlines(world, view, settings);
    const bool rest_clip = uniform && view.kind == ViewKind::PastCone && at_rest && settings.tolerance > 0 &&
                           (world.cap_a_real || world.cap_b_real);
    if (view.kind == ViewKind::Hyperplane || at_rest || !uniform) settings.tolerance = 0;
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
    if (settings.tolerance > 0) {  // moving, on the past cone
        b.refineFrame(culling ? &live : nullptr);
        return std::move(b.out);
    }
    b.out.positions.reserve(world.mesh.positions.size());
    b.out.emission_times.reserve(world.mesh.positions.size());
    b.out.rest_points.reserve(world.mesh.positions.size());
    b.out.triangles.reserve(world.mesh.triangles.size());
    b.out.source_triangles.reserve(world.mesh.triangles.size());
    b.classifyVertices(culling ? &live : nullptr);
    b.crossing_out.assign(2 * world.edges.size(), kUnset);
    if (culling) {
        for (size_t c = 0; c < world.chunks.size(); ++c)
            if (live[c])
                for (uint32_t f = world.chunks[c].first; f < world.chunks[c].last; ++f) b.addTriangle(f);
    } else {
        for (size_t f = 0; f < world.mesh.triangles.size(); ++f) b.addTriangle(f);
    }
    for (const auto& plan : b.rest_plans) b.restEmit(plan);
    return std::move(b.out);
}

// The output origin under the view's shear: (t, x) -> (t, x - shear t) at the anchor's origin.
Vec3 shearedOrigin(const ViewSurface& view, const ViewAnchor& anchor) {
    return anchor.origin - view.shear * anchor.time_origin;
}

}  // namespace

ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view, const SliceSettings& settings) {
    ApparentMesh out = sliceUnsheared(world, view, settings);
    if (!view.sheared()) return out;
    // Step: the Galilean map into the output frame, origin and local parts apart (each local
    // point moves by -shear times its local time, a term of the object's size).
    out.origin = out.origin - view.shear * out.time_origin;
    for (size_t i = 0; i < out.positions.size(); ++i) out.positions[i] -= view.shear * out.emission_times[i];
    return out;
}

Event exactApparentPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    const ViewAnchor anchor = viewAnchor(view, world.motion);
    const Event local = cutRestLocal(anchor, world.motion, q);
    return {anchor.time_origin + local.t, shearedOrigin(view, anchor) + (local.x - view.shear * local.t)};
}

BoundingSphere apparentBound(const World4D& world, const ViewSurface& view) {
    const ViewAnchor anchor = viewAnchor(view, world.motion);
    if (!isUniform(world.motion)) return {anchor.origin, INFINITY};  // no bound derived: never culled
    const double b = world.motion.beta;
    double stretch = view.kind == ViewKind::PastCone ? (1 + b) / world.motion.one_minus_beta2 : 1.0;
    // Sheared, local points are s - w delta, w = u - shear, with |s| <= R and |delta| <= R / (1 - b).
    if (view.sheared() && view.kind == ViewKind::PastCone)
        stretch = 1 + norm(world.motion.velocity - view.shear) * (1 + b) / world.motion.one_minus_beta2;
    // A relative 1e-9 more for the rounding of the points themselves.
    return {shearedOrigin(view, anchor), world.shape_radius * stretch * (1 + 1e-9)};
}

Event exactLocalPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    const Event local = cutRestLocal(viewAnchor(view, world.motion), world.motion, q);
    return {local.t, local.x - view.shear * local.t};
}

}  // namespace mesh4d
