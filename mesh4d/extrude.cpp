#include "extrude.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "motion/keyed.h"
#include "motion/kinds.h"
#include "robust.h"
#include "motion/worldline.h"

#ifdef __GLIBC__
#include <malloc.h>  // malloc_trim
#endif

namespace mesh4d {

namespace {

// extrude, with the mesh copied into the world from `mesh`, or moved from `*take` when given
// (then `mesh` is `*take`); without `edge_tables`, edges, triangle_edges and slot_next stay empty.
World4D extrudeMesh(const RestMesh& mesh, RestMesh* take, const Motion& motion, double tau_a, double tau_b,
                    bool cap_a_real, bool cap_b_real, bool edge_tables = true) {
    World4D world;
    world.motion = motion;
    world.tau_a = tau_a;
    world.tau_b = tau_b;
    world.cap_a_real = cap_a_real;
    world.cap_b_real = cap_b_real;
    const size_t nv = mesh.positions.size();

    // Unique edges, numbered in order of first appearance (slot 3 f + c is edge c of triangle f)
    // so that the numbering depends on the mesh alone. The slots are grouped by their edge with a
    // counting sort on the lower vertex and a sort of each small group on (higher vertex, slot):
    // linear memory, no hash table.
    const size_t nf = mesh.triangles.size();
    const size_t slots = 3 * nf;
    world.vertex_used.assign(nv, 0);
    if (!edge_tables) {  // slabs for tracing (extrudeSlabs): the used vertices only
        for (const auto& tri : mesh.triangles)
            for (uint32_t v : tri) world.vertex_used[v] = 1;
    } else {
        std::vector<uint32_t> offset(nv + 1, 0);
        for (const auto& tri : mesh.triangles)
            for (int c = 0; c < 3; ++c) {
                world.vertex_used[tri[c]] = 1;
                ++offset[std::min(tri[c], tri[(c + 1) % 3]) + 1];
            }
        for (size_t v = 0; v < nv; ++v) offset[v + 1] += offset[v];
        std::vector<uint64_t> by_lo(slots);  // (hi << 32) | slot, grouped by lo
        {
            std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
            for (size_t f = 0; f < nf; ++f)
                for (int c = 0; c < 3; ++c) {
                    uint32_t a = mesh.triangles[f][c], b = mesh.triangles[f][(c + 1) % 3];
                    if (a > b) std::swap(a, b);
                    by_lo[fill[a]++] = (uint64_t(b) << 32) | uint32_t(3 * f + c);
                }
        }
        // Each group of equal (lo, hi), its slots in triangle order: the first slot stands for the
        // edge (stored in triangle_edges until numbered), and the cycle of slot_next links the slots
        // of non-degenerate triangles (World4D::slot_next).
        world.triangle_edges.resize(nf);
        auto first_slot = [&](uint32_t slot) -> uint32_t& { return world.triangle_edges[slot / 3][slot % 3]; };
        world.slot_next.resize(slots);
        auto degenerate = [&](uint32_t slot) {
            const auto& t = mesh.triangles[slot / 3];
            return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
        };
        size_t edge_count = 0;  // one per group of equal (lo, hi)
        for (size_t v = 0; v < nv; ++v) {
            uint64_t* g = by_lo.data() + offset[v];
            uint64_t* const g_end = by_lo.data() + offset[v + 1];
            std::sort(g, g_end);
            while (g < g_end) {
                uint64_t* e = g;
                while (e < g_end && (*e >> 32) == (*g >> 32)) ++e;
                const uint32_t first = uint32_t(*g);
                uint32_t cycle_first = UINT32_MAX, cycle_last = UINT32_MAX;
                for (uint64_t* it = g; it < e; ++it) {
                    const uint32_t slot = uint32_t(*it);
                    first_slot(slot) = first;
                    world.slot_next[slot] = slot;
                    if (degenerate(slot)) continue;
                    if (cycle_first == UINT32_MAX) cycle_first = slot;
                    else world.slot_next[cycle_last] = slot;
                    cycle_last = slot;
                }
                if (cycle_last != UINT32_MAX) world.slot_next[cycle_last] = cycle_first;
                ++edge_count;
                g = e;
            }
        }
        std::vector<uint64_t>().swap(by_lo);
        std::vector<uint32_t>().swap(offset);
        // The scratch's pages go back to the system (glibc keeps a freed block of this size in its
        // heap, resident, and the events below do not fit into it): at 1M triangles the resident
        // peak of a load fell from 111 to 98 MB (docs/PERFORMANCE.md). The edges' array is reserved
        // at its size, so it is not grown by copies that leave holes of their own.
    #ifdef __GLIBC__
        if (slots >= (size_t(1) << 20)) malloc_trim(0);  // 8 MB of scratch and more
    #endif
        world.edges.reserve(edge_count);
        // Numbering in slot order: a slot's first slot is never after it, so it is numbered already.
        for (uint32_t slot = 0; slot < slots; ++slot) {
            if (first_slot(slot) == slot) {
                const auto& t = mesh.triangles[slot / 3];
                uint32_t a = t[slot % 3], b = t[(slot % 3 + 1) % 3];
                if (a > b) std::swap(a, b);
                first_slot(slot) = uint32_t(world.edges.size());
                world.edges.push_back({a, b});
            } else {
                first_slot(slot) = first_slot(first_slot(slot));
            }
        }
    }

    // The mesh (its one copy, or the caller's handed over) and the events, after the edges'
    // scratch arrays are freed: the peak memory is the world itself.
    if (take)
        world.mesh = std::move(*take);
    else
        world.mesh = mesh;
    const RestMesh& m = world.mesh;
    // Events: both caps of every vertex's worldline.
    world.events.resize(2 * nv);
    for (size_t i = 0; i < nv; ++i) {
        world.events[2 * i + 0] = worldlineEvent(motion, tau_a, m.positions[i]);
        world.events[2 * i + 1] = worldlineEvent(motion, tau_b, m.positions[i]);
    }

    world.simple = true;
    for (size_t i = 0; i < nv; ++i) {
        if (world.vertex_used[i]) world.shape_radius = std::max(world.shape_radius, norm(m.positions[i]));
        else world.simple = false;
    }
    for (const auto& t : m.triangles)
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) world.simple = false;

    // Runs of triangles with the 4D boxes of their cap events, for the per-frame cull. A vertex's
    // two events are 8 consecutive doubles (t, x, y, z of cap a, then of cap b), taken two at a
    // time: eight independent running minima and maxima instead of one chain per bound, each
    // the same comparison in the same order as EventBox::add (so the same bits).
    static_assert(sizeof(Event) == 4 * sizeof(double), "Event is t, x, y, z without padding");
    typedef double Pair __attribute__((vector_size(16)));
    world.chunks.reserve((m.triangles.size() + kChunkTriangles - 1) / kChunkTriangles);
    const double* const events = &world.events.data()->t;
    for (uint32_t f0 = 0; f0 < m.triangles.size(); f0 += kChunkTriangles) {
        TriangleChunk c;
        c.first = f0;
        c.last = uint32_t(std::min<size_t>(m.triangles.size(), size_t(f0) + kChunkTriangles));
        Pair lo[4], hi[4];
        for (int k = 0; k < 4; ++k) {
            lo[k] = Pair{INFINITY, INFINITY};
            hi[k] = Pair{-INFINITY, -INFINITY};
        }
        for (uint32_t f = c.first; f < c.last; ++f)
            for (uint32_t v : m.triangles[f]) {
                const double* e = events + 8 * size_t(v);
                for (int k = 0; k < 4; ++k) {
                    Pair p;
                    std::memcpy(&p, e + 2 * k, sizeof(p));
                    lo[k] = p < lo[k] ? p : lo[k];  // std::min(lo, p)
                    hi[k] = hi[k] < p ? p : hi[k];  // std::max(hi, p)
                }
            }
        for (int cap = 0; cap < 2; ++cap) {
            const Pair& l0 = lo[2 * cap];
            const Pair& l1 = lo[2 * cap + 1];
            const Pair& h0 = hi[2 * cap];
            const Pair& h1 = hi[2 * cap + 1];
            c.cap[cap].t_lo = l0[0];
            c.cap[cap].t_hi = h0[0];
            c.cap[cap].lo = {l0[1], l1[0], l1[1]};
            c.cap[cap].hi = {h0[1], h1[0], h1[1]};
        }
        world.chunks.push_back(c);
    }
    return world;
}

}  // namespace

World4D extrude(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, bool cap_a_real,
                bool cap_b_real) {
    return extrudeMesh(mesh, nullptr, motion, tau_a, tau_b, cap_a_real, cap_b_real);
}

World4D extrude(RestMesh&& mesh, const Motion& motion, double tau_a, double tau_b, bool cap_a_real, bool cap_b_real) {
    return extrudeMesh(mesh, &mesh, motion, tau_a, tau_b, cap_a_real, cap_b_real);
}

namespace {

// The largest |axis x e| over the rest mesh's edges e: how fast an edge turns off its own line per
// unit turn rate about `axis` (unit); edges along the axis do not turn.
double largestTurningEdge(const RestMesh& mesh, const Vec3& axis) {
    double edge = 0;
    for (const auto& t : mesh.triangles)
        for (int c = 0; c < 3; ++c)
            edge = std::max(edge, norm(cross(axis, mesh.positions[t[c]] - mesh.positions[t[(c + 1) % 3]])));
    return edge;
}

// The largest ds with K ds / 2 + M ds^2 / 8 <= chord (extrude.h), the positive root without
// cancellation; infinity when neither term grows.
double stepWithin(double K, double M, double chord) {
    const double root = K + std::sqrt(K * K + 2 * M * chord);
    if (!(root > 0)) return INFINITY;
    return 4 * chord / root;
}

// Segment j's step of a keyframed path (keyed.h): between two keys the path is straight in its
// own frame plus a turn at the segment's rate about the segment's axis, so the spin's bound: K the
// rate times the largest |axis x e|, M the rate^2 times rho (every |q| bounding its distance from
// any axis); infinity without a turn (the worldlines are straight between keys).
double keyedSegmentStep(const RestMesh& mesh, const KeyedMotion& k, size_t j, double rho, double chord) {
    if (!(k.rate[j] > 0)) return INFINITY;
    return stepWithin(k.rate[j] * largestTurningEdge(mesh, k.axis[j]), k.rate[j] * k.rate[j] * rho, chord);
}

// An acceleration's step over times with |s| <= s_max: M = sqrt(2) |a|^2 xi_max cosh(|a| s_max)
// (extrude.h), K = 0.
double accelerationStep(double a, double xi_max, double s_max, double chord) {
    return stepWithin(0, std::sqrt(2.0) * a * a * xi_max * std::cosh(a * s_max), chord);
}

double largestRadius(const RestMesh& mesh) {
    double rho = 0;
    for (const Vec3& q : mesh.positions) rho = std::max(rho, norm(q));
    return rho;
}

double largestHorizonDistance(const RestMesh& mesh, const Motion& motion) {
    double xi = 0;
    for (const Vec3& q : mesh.positions) xi = std::max(xi, horizonDistance(motion, q));
    return xi;
}

// A cell of the grid split into more steps than this is "too fine": slabSamples gives up first.
constexpr double kMaxCellSteps = 1e15;

// A keyframed path: the segments over [tau_a, tau_b], each with its own bound (keyedSegmentStep).
double keyedSlabSpacing(const RestMesh& mesh, const KeyedMotion& k, double tau_a, double tau_b, double chord) {
    const double rho = largestRadius(mesh);
    double ds = INFINITY;
    for (size_t j = 1; j < k.s.size(); ++j)
        if (k.s[j] > tau_a && k.s[j - 1] < tau_b) ds = std::min(ds, keyedSegmentStep(mesh, k, j, rho, chord));
    return ds;
}

}  // namespace

double slabSpacing(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, double chord) {
    switch (kindOf(motion)) {
        case MotionKind::Uniform:
            return INFINITY;
        case MotionKind::Keyed:
            return keyedSlabSpacing(mesh, *motion.keyed, tau_a, tau_b, chord);
        case MotionKind::Spin:
        case MotionKind::Hyperbolic:
            break;
        default: {  // a kind answered in its own file (kinds.h): its K and M, for all s
            double K = 0, M = 0;
            answersOf(motion)->slab_rates(motion, mesh, &K, &M);
            return stepWithin(K, M, chord);
        }
    }
    // M: the largest second derivative of a vertex's own-frame worldline over the span (spin:
    // |w|^2 rho, rho the vertex's distance from the axis); K: the largest difference of the first
    // derivatives of two points of one triangle (extrude.h).
    const double w = norm(motion.angular_velocity);
    const double a = norm(motion.acceleration);
    const double s_max = std::max(std::fabs(tau_a), std::fabs(tau_b));
    if (a > 0) return accelerationStep(a, largestHorizonDistance(mesh, motion), s_max, chord);
    double M = 0;
    for (const Vec3& q : mesh.positions) M = std::max(M, w * spinSpeed(motion, q));
    // An acceleration's E_i' - E_q' = |a| (xi_i - xi_q) (cosh, k sinh) is parallel to E_q': along
    // the history, not off it, so it adds no distance to the history (K = 0, accelerationStep). A
    // spin's is w x R (q_i - q), at most |w x e| over the triangle's edges e.
    const double K = !(w > 0) ? 0.0 : w * largestTurningEdge(mesh, motion.angular_velocity / w);
    return stepWithin(K, M, chord);
}

SlabGrid::SlabGrid(const RestMesh& mesh, const Motion& motion, double chord) : chord_(chord) {
    switch (kindOf(motion)) {
        case MotionKind::Uniform:
            return;
        case MotionKind::Keyed: {
            const KeyedMotion& k = *motion.keyed;
            const double rho = largestRadius(mesh);
            kind_ = Kind::Keyed;
            keys_ = k.s;
            counts_.assign(k.s.size(), 1.0);
            for (size_t j = 1; j < k.s.size(); ++j) {
                const double n = std::ceil((k.s[j] - k.s[j - 1]) / keyedSegmentStep(mesh, k, j, rho, chord));
                counts_[j] = std::isnan(n) ? kMaxCellSteps : std::clamp(n, 1.0, kMaxCellSteps);
            }
            return;
        }
        case MotionKind::Spin:
        case MotionKind::Hyperbolic:
        default:  // a kind answered in its own file (kinds.h): one step for all s, as a spin's
            break;
    }
    const double a = norm(motion.acceleration);
    if (a > 0) {
        kind_ = Kind::Acceleration;
        accel_ = a;
        step_ = 1 / (8 * a);
        xi_max_ = largestHorizonDistance(mesh, motion);
        return;
    }
    step_ = slabSpacing(mesh, motion, 0, 0, chord);
    if (step_ > 0 && step_ < INFINITY) kind_ = Kind::Spin;
}

double SlabGrid::blockCount(double j) const {
    const double n = std::ceil(step_ / accelerationStep(accel_, xi_max_, (j + 1) * step_, chord_));
    return std::isnan(n) ? kMaxCellSteps : std::clamp(n, 1.0, kMaxCellSteps);
}

void SlabGrid::cellOf(double s, double* lo, double* hi, double* n) const {
    *lo = -INFINITY;
    *hi = INFINITY;
    *n = 1;
    // Cells of equal length L = step_ from 0: j with j L <= s < (j + 1) L, the floor corrected for
    // the rounding of s / L.
    auto block = [&](double L) {
        double j = std::floor(s / L);
        while (j * L > s) j -= 1;
        while ((j + 1) * L <= s) j += 1;
        *lo = j * L;
        *hi = (j + 1) * L;
        return j;
    };
    switch (kind_) {
    case Kind::None:
        return;
    case Kind::Spin:
        block(step_);
        return;
    case Kind::Acceleration:
        if (s < 0) {
            *hi = 0;
            return;
        }
        *n = blockCount(block(step_));
        return;
    case Kind::Keyed: {
        const size_t j = size_t(std::upper_bound(keys_.begin(), keys_.end(), s) - keys_.begin());
        if (j > 0) *lo = keys_[j - 1];
        if (j < keys_.size()) *hi = keys_[j];
        if (j > 0 && j < keys_.size()) *n = counts_[j];
        return;
    }
    }
}

double SlabGrid::after(double s) const {
    double lo, hi, n;
    cellOf(s, &lo, &hi, &n);
    if (!(lo > -INFINITY) || !(hi < INFINITY)) return hi;
    // Step i of the cell's n: lo + i h, the least > s.
    const double h = (hi - lo) / n;
    double i = std::floor((s - lo) / h) + 1;
    while (i > 1 && lo + (i - 1) * h > s) i -= 1;
    while (i < n && lo + i * h <= s) i += 1;
    return i >= n ? hi : lo + i * h;
}

double SlabGrid::atOrBefore(double s) const {
    double lo, hi, n;
    cellOf(s, &lo, &hi, &n);
    if (!(lo > -INFINITY) || !(hi < INFINITY)) return lo;
    const double h = (hi - lo) / n;
    double i = std::clamp(std::floor((s - lo) / h), 0.0, n - 1);
    while (i > 0 && lo + i * h > s) i -= 1;
    while (i + 1 < n && lo + (i + 1) * h <= s) i += 1;
    return lo + i * h;
}

double SlabGrid::atOrAfter(double s) const {
    const double before = atOrBefore(s);
    return before == s ? s : after(s);
}

std::vector<double> SlabGrid::samples(double tau_a, double tau_b, size_t max_slabs) const {
    std::vector<double> out{tau_a};
    for (double s = after(tau_a); s < tau_b; s = after(s)) {
        if (out.size() > max_slabs || !(s > out.back())) return {};
        out.push_back(s);
    }
    out.push_back(tau_b);
    if (out.size() - 1 > max_slabs) return {};
    return out;
}

std::vector<double> slabSamples(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, double chord,
                                size_t max_slabs) {
    return SlabGrid(mesh, motion, chord).samples(tau_a, tau_b, max_slabs);
}

std::vector<World4D> extrudeSlabs(const RestMesh& mesh, const Motion& motion, const std::vector<double>& samples,
                                  bool cap_a_real, bool cap_b_real) {
    std::vector<World4D> slabs;
    if (samples.size() < 2) return slabs;
    const size_t count = samples.size() - 1;
    slabs.reserve(count);
    for (size_t k = 0; k < count; ++k)
        slabs.push_back(extrudeMesh(mesh, nullptr, motion, samples[k], samples[k + 1], cap_a_real && k == 0,
                                    cap_b_real && k + 1 == count, false));
    return slabs;
}

ProperTimeSpan spanSeen(const RestMesh& mesh, const Motion& motion, const ViewSurface& first, const ViewSurface& last) {
    ProperTimeSpan span{INFINITY, -INFINITY};
    if (!isUniform(motion)) {  // worldline.h: the object's time s of each crossing
        for (const Vec3& q : mesh.positions) {
            span.lo = std::min(span.lo, crossWorldline(first, motion, q).s);
            span.hi = std::max(span.hi, crossWorldline(last, motion, q).s);
        }
        return span;
    }
    const Vec3 base_first = nowBase(first, motion), base_last = nowBase(last, motion);
    for (const Vec3& q : mesh.positions) {
        const double t_first = cutRestWorldline(first, motion, base_first, q).t;
        const double t_last = cutRestWorldline(last, motion, base_last, q).t;
        span.lo = std::min(span.lo, properTimeAt(motion, q, t_first));
        span.hi = std::max(span.hi, properTimeAt(motion, q, t_last));
    }
    return span;
}

}  // namespace mesh4d
