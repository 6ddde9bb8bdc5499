#include "extrude.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "keyframes.h"
#include "robust.h"
#include "worldline.h"

#ifdef __GLIBC__
#include <malloc.h>  // malloc_trim
#endif

namespace mesh4d {

namespace {

// extrude, with the mesh copied into the world from `mesh`, or moved from `*take` when given
// (then `mesh` is `*take`).
World4D extrudeMesh(const RestMesh& mesh, RestMesh* take, const Motion& motion, double tau_a, double tau_b,
                    bool cap_a_real, bool cap_b_real) {
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

}  // namespace

// A keyframed path (keyframes.h) between two keys: straight in its own frame plus a turn at the
// segment's rate about the segment's axis, so the spin's bound with the segments over
// [tau_a, tau_b]: K the largest rate |axis x e|, M the largest rate^2 |q| (every |q| bounding its
// distance from any axis); without a turn the worldlines are straight between keys, where
// slabSamples puts a sample.
double keyedSlabSpacing(const RestMesh& mesh, const KeyedMotion& k, double tau_a, double tau_b, double chord) {
    double rho = 0;
    for (const Vec3& q : mesh.positions) rho = std::max(rho, norm(q));
    double K = 0, M = 0;
    for (size_t j = 1; j < k.s.size(); ++j)
        if (k.s[j] > tau_a && k.s[j - 1] < tau_b && k.rate[j] > 0) {
            K = std::max(K, k.rate[j] * largestTurningEdge(mesh, k.axis[j]));
            M = std::max(M, k.rate[j] * k.rate[j] * rho);
        }
    if (!(M > 0)) return INFINITY;
    return stepWithin(K, M, chord);
}

double slabSpacing(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, double chord) {
    if (isUniform(motion)) return INFINITY;
    if (motion.keyed) return keyedSlabSpacing(mesh, *motion.keyed, tau_a, tau_b, chord);
    // M: the largest second derivative of a vertex's own-frame worldline over the span (spin:
    // |w|^2 rho, rho the vertex's distance from the axis); K: the largest difference of the first
    // derivatives of two points of one triangle (extrude.h).
    const double w = norm(motion.angular_velocity);
    const double a = norm(motion.acceleration);
    const double s_max = std::max(std::fabs(tau_a), std::fabs(tau_b));
    const double ch = a > 0 ? std::cosh(a * s_max) : 1.0;
    double M = 0;
    for (const Vec3& q : mesh.positions)
        M = std::max(M, a > 0 ? std::sqrt(2.0) * a * a * horizonDistance(motion, q) * ch : w * spinSpeed(motion, q));
    // An acceleration's E_i' - E_q' = |a| (xi_i - xi_q) (cosh, k sinh) is parallel to E_q': along
    // the history, not off it, so it adds no distance to the history (K = 0). A spin's is
    // w x R (q_i - q), at most |w x e| over the triangle's edges e.
    const double K = a > 0 || !(w > 0) ? 0.0 : w * largestTurningEdge(mesh, motion.angular_velocity / w);
    return stepWithin(K, M, chord);
}

std::vector<double> slabSamples(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b, double chord,
                                size_t max_slabs) {
    std::vector<double> samples{tau_a};
    double s = tau_a;
    while (s < tau_b) {
        // The step bounded at s alone, then over [s, s + that step] (never longer: the bound grows with |s|).
        const double first = slabSpacing(mesh, motion, s, s, chord);
        double end = tau_b;  // a keyframed path's next key: its worldlines bend there
        if (motion.keyed)
            for (double key : motion.keyed->s)
                if (key > s && key < end) end = key;
        const double ds = slabSpacing(mesh, motion, s, std::min(end, s + first), chord);
        if (!(ds > 0) || samples.size() > max_slabs) return {};
        s = ds >= end - s ? end : s + ds;
        samples.push_back(s);
    }
    if (samples.size() - 1 > max_slabs) return {};
    return samples;
}

std::vector<World4D> extrudeSlabs(const RestMesh& mesh, const Motion& motion, const std::vector<double>& samples,
                                  bool cap_a_real, bool cap_b_real) {
    std::vector<World4D> slabs;
    if (samples.size() < 2) return slabs;
    const size_t count = samples.size() - 1;
    slabs.reserve(count);
    for (size_t k = 0; k < count; ++k)
        slabs.push_back(extrude(mesh, motion, samples[k], samples[k + 1], cap_a_real && k == 0, cap_b_real && k + 1 == count));
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
