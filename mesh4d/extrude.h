// Temporal extrusion: a triangle mesh at rest, swept along its worldlines, becomes a static
// tetrahedral 3-manifold in 4D, the object's history (Black et al. 2007, section III; docs/DESIGN.md
// sections 1 and 3).
//
// Each rest vertex q_i gives two lab events, E(i, a) = labFromRest(tau_a, q_i) and
// E(i, b) = labFromRest(tau_b, q_i), stored once at index 2 i + cap. The segment between them is
// a piece of the vertex's worldline (a timelike "lateral" edge). Each triangle (i, j, k) gives a
// prism with caps at tau_a and tau_b, cut into three tetrahedra by the standard staircase split
// over its vertices sorted by global id: with i < j < k,
//     {ia, ja, ka, kb}, {ia, ja, jb, kb}, {ia, ib, jb, kb}.
// Sorting by id makes the diagonal chosen on each lateral quad depend on the quad's two vertex
// ids only, so the prisms of neighbouring triangles share their quad diagonals exactly and the
// tetrahedra form a conforming complex.
//
// Only the proper-time span [tau_a, tau_b] the frames can see is extruded (docs/DESIGN.md section 7).
// A cap is "real" where the object begins or ends existing there, and "open" where the span was
// cut to what the frames see: only real caps clip the apparent surface.
#pragma once

#include <array>
#include <cmath>
#include <utility>
#include <cstdint>
#include <vector>

#include "motion/motion.h"
#include "box.h"
#include "event.h"
#include "lightcone.h"

namespace mesh4d {

// A triangle mesh in the object's rest frame (after rotation and scale), vertices indexed from 0.
struct RestMesh {
    std::vector<Vec3> positions;
    std::vector<std::array<uint32_t, 3>> triangles;
};

// An undirected mesh edge, lo < hi.
struct Edge {
    uint32_t lo = 0, hi = 0;
};

// A run of consecutive triangles with the boxes of their vertices' events on each cap: the
// bounding level of the per-frame cull (slice.h). Meshes from scanners and modellers keep
// neighbouring triangles near each other in the file, so runs are spatially compact.
struct TriangleChunk {
    uint32_t first = 0, last = 0;  // triangles [first, last)
    EventBox cap[2];               // events of the run's vertices on cap a and cap b
};
constexpr uint32_t kChunkTriangles = 256;

struct World4D {
    Motion motion;
    RestMesh mesh;
    double tau_a = 0, tau_b = 0;     // extruded proper-time span, tau_a < tau_b
    bool cap_a_real = false;         // the object begins existing at tau_a
    bool cap_b_real = false;         // the object ends existing at tau_b
    std::vector<Event> events;       // 2 per rest vertex: index 2 i + 0 (cap a), 2 i + 1 (cap b)
    std::vector<Edge> edges;                    // unique undirected edges of the mesh
    std::vector<std::array<uint32_t, 3>> triangle_edges;  // edge of (v0,v1), (v1,v2), (v2,v0)
    // The triangles around each edge as a cycle of slots: slot 3 f + c (edge c of triangle f) ->
    // the next slot on the same mesh edge, in triangle order, the last back to the first; a
    // boundary edge's slot points to itself (two slots on a manifold edge, more on a non-manifold
    // one). Triangles that repeat an index are left out (their slots point to themselves). The
    // adaptive refinement (slice.cpp) splits an edge in every triangle of its cycle.
    std::vector<uint32_t> slot_next;
    std::vector<uint8_t> vertex_used;           // 1 where a triangle references the rest vertex
    std::vector<TriangleChunk> chunks;          // runs of kChunkTriangles triangles, in order
    double shape_radius = 0;                    // max |q| over the used rest vertices
    bool simple = false;  // every vertex used and no triangle repeats an index (the vertex-mode fast path)
    bool empty() const { return mesh.triangles.empty() || !(tau_a < tau_b); }
    // The tetrahedra are implicit (computed from the triangles, not stored): 3 per triangle,
    // tetrahedron 3 f + k is prismTet(mesh.triangles[f], k).
    size_t tetCount() const { return 3 * mesh.triangles.size(); }
    std::array<uint32_t, 4> tet(size_t i) const;
};

// Tetrahedron k (0, 1, 2) of the prism over triangle `tri`, as indices into World4D::events: the
// staircase split over its vertices sorted by id (i < j < k): {ia, ja, ka, kb}, {ia, ja, jb, kb},
// {ia, ib, jb, kb}.
inline std::array<uint32_t, 4> prismTet(const std::array<uint32_t, 3>& tri, int k) {
    uint32_t s0 = tri[0], s1 = tri[1], s2 = tri[2];
    if (s0 > s1) std::swap(s0, s1);
    if (s1 > s2) std::swap(s1, s2);
    if (s0 > s1) std::swap(s0, s1);
    const uint32_t ia = 2 * s0, ja = 2 * s1, ka = 2 * s2;
    if (k == 0) return {ia, ja, ka, ka + 1};
    if (k == 1) return {ia, ja, ja + 1, ka + 1};
    return {ia, ia + 1, ja + 1, ka + 1};
}
inline std::array<uint32_t, 4> World4D::tet(size_t i) const { return prismTet(mesh.triangles[i / 3], int(i % 3)); }

// Builds the 4D history of `mesh` under `motion` over proper times [tau_a, tau_b].
// Preconditions: tau_a < tau_b, every triangle index < mesh.positions.size().
World4D extrude(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b,
                bool cap_a_real, bool cap_b_real);
// The same, the mesh handed to the world instead of copied (`mesh` is left empty): the world is
// then its only copy, for a caller that needs the rest mesh no more (pipeline/stage/worlds.h takeWorlds).
World4D extrude(RestMesh&& mesh, const Motion& motion, double tau_a, double tau_b, bool cap_a_real,
                bool cap_b_real);

// Time slabs (issue 18, item 5): for a motion that is not uniform (worldline.h) the history over
// [tau_a, tau_b] is cut at samples of the object's time s into slabs, each a World4D of prisms
// between two samples, whose cap events lie on the true worldlines. slabSpacing is the largest step
// ds for which every point of every slab's tetrahedra lies within `chord` (Euclidean, in the
// object's own frame: the centre frame of a spin, the start frame of an acceleration) of the true
// event of its rest point, or of the history near it (a shift along the history is no error).
// The argument: a point of a tetrahedron is sum l_i E_i(s_i) over its vertices' events, each s_i
// one of the slab's two samples, p the weight on the later one; the rest point q = sum l_i q_i has
// the event E_q(s) = sum l_i E_i(s) at every s (events are affine in q at fixed s), so at
// s = sum l_i s_i the difference is sum l_i [E_i'(s) - E_q'(s)] (s_i - s) plus Taylor remainders.
// With sum l_i |s_i - s| = 2 p (1 - p) ds and sum l_i (s_i - s)^2 = p (1 - p) ds^2 it is at most
//     p (1 - p) (2 K ds + M ds^2 / 2)  <=  K ds / 2 + M ds^2 / 8,
// K bounding the part of |E_i' - E_q'| off the history over a triangle (spin: E_i' - E_q' =
// w x R (q_i - q), at most the largest |w x e| over the rest edges e, edges along the axis not
// turning; acceleration: 0, since E_i' - E_q' = |a| (xi_i - xi_q)(cosh, k sinh) is parallel to
// E_q', a shift along the history) and M bounding |E''| (spin: |w|^2 rho, rho a vertex's distance
// from the axis, so M ds^2 / 8 is the sagitta rho w^2 ds^2 / 8 of each vertex's chord; acceleration:
// sqrt(2) |a|^2 xi_max cosh(|a| s_max); s_max the largest |s| of the span). The first term is the
// twist of a prism whose vertices move differently: its lateral quads are not flat, the
// tetrahedra fold them along a diagonal, and a long edge turning at |w| (a wheel's spoke, 1.8 ls
// at 0.9 rad/s) bends its faces by up to |w x e| ds / 2 off the history, more than the chords do;
// dropping it would leave that error unbounded. A boost or the Galilean carry stretches these
// distances by at most gamma (1 + b) in the lab (callers divide the lab chord by it). Uniform
// motion needs one slab: slabSpacing returns infinity. A keyframed path (keyed.h) is straight
// between keys in its own frame plus a turn: the spin's bound with each segment's turn rate and
// axis over the interval (rho bounded by max |q|), infinity without a turn; slabSamples puts a
// sample at every key, where the worldlines bend.
// ds over the interval [tau_a, tau_b] of s (s_max = max(|tau_a|, |tau_b|)).
double slabSpacing(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, double chord);

// The slab grid (issue 18): sample times fixed by the motion, the mesh and the chord alone, never by
// the span asked for, so that the slabs of any two spans are the same slabs where they overlap. A
// narrower span (the one the frames see, pipeline/stage/worlds.h) or a window of a long frame range
// (pipeline/trace/raytrace.h) then traces the very tetrahedra a wider span would: the same pictures, byte
// for byte. The grid points, each step within slabSpacing over its own cell:
//   spin: k ds for every integer k, ds = slabSpacing (constant: the bound does not depend on s);
//   acceleration: none before t0 (s < 0: uniform motion, straight worldlines); from s = 0 on,
//     blocks [j L, (j + 1) L], L = 1 / (8 |a|), block j cut into n_j = ceil(L / ds_j) equal steps,
//     ds_j = slabSpacing over the block (cosh(|a| s) grows by at most e^(1/8) across a block, so
//     the steps are within about 6 % of slabSpacing's at each s, and shrink as it does);
//   keyframed path: every key, and between keys j - 1 and j, n_j = ceil((s_j - s_{j-1}) / ds_j)
//     equal steps, ds_j the spin's bound with that segment's turn (infinity without one: n_j = 1);
//     none before the first key or after the last (the body rests there in the lab).
// The points are computed from their indices (k ds, j L + i (L / n_j)), never by accumulating
// steps, so that every span gets bit-identical times. Uniform motion has no grid points.
class SlabGrid {
public:
    SlabGrid() = default;  // no grid points
    // Precondition: chord > 0; mesh as for slabSpacing.
    SlabGrid(const RestMesh& mesh, const Motion& motion, double chord);
    // The least grid point > s (INFINITY when there is none).
    double after(double s) const;
    // The greatest grid point <= s (-INFINITY when there is none).
    double atOrBefore(double s) const;
    // The least grid point >= s (INFINITY when there is none).
    double atOrAfter(double s) const;
    // tau_a, the grid points strictly between tau_a and tau_b, tau_b; empty when more than
    // max_slabs slabs would be needed. Precondition: tau_a < tau_b.
    std::vector<double> samples(double tau_a, double tau_b, size_t max_slabs) const;

private:
    enum class Kind { None, Spin, Acceleration, Keyed };
    Kind kind_ = Kind::None;
    double step_ = INFINITY;  // spin: ds; acceleration: the block length L
    double accel_ = 0, xi_max_ = 0, chord_ = 0;  // acceleration: |a|, the largest horizon distance
    std::vector<double> keys_;    // keyframed: the key times s_k
    std::vector<double> counts_;  // keyframed: n_j for segment j (between keys j - 1 and j), index j
    double blockCount(double j) const;  // acceleration: n_j of block j (an integer, >= 1)
    // The cell [lo, hi) of s and its n equal steps (lo = -INFINITY or hi = INFINITY: no cell).
    void cellOf(double s, double* lo, double* hi, double* n) const;
};

// The sample times tau_a = s_0 < s_1 < ... < s_n = tau_b: SlabGrid(mesh, motion, chord).samples
// (every step within slabSpacing over its own interval); empty when more than max_slabs slabs
// would be needed.
std::vector<double> slabSamples(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, double chord,
                                size_t max_slabs);

// The history between consecutive samples, one World4D per slab; only the first slab's cap a and
// the last's cap b can be real. The slabs are for tracing (ray4d.h prepareSlabsTrace), which reads
// the mesh, events and spans only: their edges, triangle_edges and slot_next are left empty (not
// built: 36 bytes a triangle a slab, docs/PERFORMANCE.md section 6). Each
// slab holds its own copy of the mesh: memory grows with the number of slabs (callers bound it).
std::vector<World4D> extrudeSlabs(const RestMesh& mesh, const Motion& motion, const std::vector<double>& samples,
                                  bool cap_a_real, bool cap_b_real);

// The proper times at which the rest vertices' worldlines cross the first and the last view
// surface of a sequence: [min over vertices at `first`, max over vertices at `last`]. Crossing
// times grow monotonically with the camera time (a timelike worldline meets later cones later),
// so every frame in between sees vertex emissions inside this span. Precondition: beta < 1 for
// cone views; mesh non-empty.
struct ProperTimeSpan {
    double lo = 0, hi = 0;
};
ProperTimeSpan spanSeen(const RestMesh& mesh, const Motion& motion, const ViewSurface& first, const ViewSurface& last);

}  // namespace mesh4d
