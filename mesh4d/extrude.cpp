#include "extrude.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "robust.h"

namespace mesh4d {

World4D extrude(const RestMesh& mesh, const Motion& motion, double tau_a, double tau_b,
                bool cap_a_real, bool cap_b_real) {
    World4D world;
    world.motion = motion;
    world.mesh = mesh;
    world.tau_a = tau_a;
    world.tau_b = tau_b;
    world.cap_a_real = cap_a_real;
    world.cap_b_real = cap_b_real;

    // Events: both caps of every vertex's worldline.
    const size_t nv = mesh.positions.size();
    world.events.resize(2 * nv);
    for (size_t i = 0; i < nv; ++i) {
        world.events[2 * i + 0] = labFromRest(motion, tau_a, mesh.positions[i]);
        world.events[2 * i + 1] = labFromRest(motion, tau_b, mesh.positions[i]);
    }

    // Unique edges, keyed by (lo, hi), numbered in order of first appearance so that the
    // numbering depends on the mesh alone.
    std::unordered_map<uint64_t, uint32_t> edge_index;
    edge_index.reserve(mesh.triangles.size() * 2);
    world.triangle_edges.resize(mesh.triangles.size());
    world.vertex_used.assign(nv, 0);
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
        const auto& tri = mesh.triangles[f];
        for (int c = 0; c < 3; ++c) {
            world.vertex_used[tri[c]] = 1;
            uint32_t a = tri[c], b = tri[(c + 1) % 3];
            if (a > b) std::swap(a, b);
            const uint64_t key = (uint64_t(a) << 32) | b;
            auto [it, inserted] = edge_index.emplace(key, uint32_t(world.edges.size()));
            if (inserted) world.edges.push_back({a, b});
            world.triangle_edges[f][c] = it->second;
        }
    }

    // The cycle of slots around each edge (World4D::slot_next).
    {
        const uint32_t unset = 0xffffffffu;
        std::vector<uint32_t> first(world.edges.size(), unset), last(world.edges.size(), unset);
        world.slot_next.resize(3 * mesh.triangles.size());
        for (size_t f = 0; f < mesh.triangles.size(); ++f) {
            const auto& t = mesh.triangles[f];
            const bool degenerate = t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
            for (int c = 0; c < 3; ++c) {
                const uint32_t slot = uint32_t(3 * f + c);
                world.slot_next[slot] = slot;
                if (degenerate) continue;
                const uint32_t e = world.triangle_edges[f][c];
                if (first[e] == unset) first[e] = slot;
                else world.slot_next[last[e]] = slot;
                last[e] = slot;
            }
        }
        for (size_t e = 0; e < world.edges.size(); ++e)
            if (last[e] != unset) world.slot_next[last[e]] = first[e];
    }

    // Three tetrahedra per prism, staircase split over the vertices sorted by id.
    world.tets.reserve(3 * mesh.triangles.size());
    for (const auto& tri : mesh.triangles) {
        std::array<uint32_t, 3> s = tri;
        std::sort(s.begin(), s.end());
        const uint32_t ia = 2 * s[0], ib = ia + 1, ja = 2 * s[1], jb = ja + 1, ka = 2 * s[2], kb = ka + 1;
        world.tets.push_back({ia, ja, ka, kb});
        world.tets.push_back({ia, ja, jb, kb});
        world.tets.push_back({ia, ib, jb, kb});
    }

    world.simple = true;
    for (size_t i = 0; i < nv; ++i) {
        if (world.vertex_used[i]) world.shape_radius = std::max(world.shape_radius, norm(mesh.positions[i]));
        else world.simple = false;
    }
    for (const auto& t : mesh.triangles)
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) world.simple = false;

    // Runs of triangles with the 4D boxes of their cap events, for the per-frame cull.
    for (uint32_t f0 = 0; f0 < mesh.triangles.size(); f0 += kChunkTriangles) {
        TriangleChunk c;
        c.first = f0;
        c.last = uint32_t(std::min<size_t>(mesh.triangles.size(), size_t(f0) + kChunkTriangles));
        for (uint32_t f = c.first; f < c.last; ++f)
            for (uint32_t v : mesh.triangles[f])
                for (int cap = 0; cap < 2; ++cap) c.cap[cap].add(world.events[2 * v + cap]);
        world.chunks.push_back(c);
    }
    return world;
}

ProperTimeSpan spanSeen(const RestMesh& mesh, const Motion& motion, const ViewSurface& first, const ViewSurface& last) {
    ProperTimeSpan span{INFINITY, -INFINITY};
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
