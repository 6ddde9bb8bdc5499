// Faces containing the velocity: which triangles and edges they have, and the rim test of their pieces.
#include "mesh4d/cut/frame_builder.h"

namespace mesh4d {
namespace slicing {

bool FrameBuilder::slides(uint32_t f) {
    std::vector<int8_t>& known = scratch.tri_slides;
    if (known.size() != r_nt) known.assign(r_nt, -1);
    if (known[f] < 0) {
        const auto& t = world.mesh.triangles[f];
        const auto& p = world.mesh.positions;
        known[f] = planeContains(p[t[0]], p[t[1]], p[t[2]], world.motion.velocity) ? 1 : 0;
    }
    return known[f] == 1;
}

bool FrameBuilder::innerEdge(uint32_t e, uint32_t f) {
    std::vector<int8_t>& known = scratch.edge_inner;
    if (known.size() != r_ne) known.assign(r_ne, -1);
    if (known[e] >= 0) return known[e] == 1;
    // Step: the edge's slot in f, and the one other triangle around it.
    int k = 0;
    while (k < 3 && world.triangle_edges[f][size_t(k)] != e) ++k;
    bool inner = false;
    if (k < 3) {
        const uint32_t slot = 3 * f + uint32_t(k), other = world.slot_next[slot];
        if (other != slot && world.slot_next[other] == slot && slides(other / 3)) {
            // Step: coplanar (the other's far corner on f's plane, to rounding of the mesh's size).
            const auto& p = world.mesh.positions;
            const auto& t = world.mesh.triangles[f];
            const auto& g = world.mesh.triangles[other / 3];
            const Vec3 n = cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]);
            double far = 0;
            for (uint32_t q : g) far = std::max(far, std::fabs(dot(n, p[q] - p[t[0]])));
            double size = 0;
            for (int i = 0; i < 3; ++i) size = std::max(size, norm(p[g[size_t(i)]] - p[t[0]]));
            inner = far <= 1e-12 * norm(n) * size;
        }
    }
    known[e] = inner ? 1 : 0;
    return inner;
}

bool FrameBuilder::rimPasses(uint32_t f, const uint32_t v[3], const uint32_t rec[3], const double c[3],
                             const double len[3], const double xm_mid[3]) {
    for (int k = 0; k < 3; ++k) {
        const uint32_t e = rec[k] < r_ne ? rec[k] : r_edges[rec[k]].on;
        if (e == kUnset || innerEdge(e, f)) continue;
        const uint32_t a = std::min(v[k], v[kSucc[k]]), b = std::max(v[k], v[kSucc[k]]);
        const double d = rimChordError(world.motion, bound_speed, r_terms[a], r_terms[b], c[k], len[k], xm_mid[k]);
        if (!(d <= settings.tolerance)) return false;
    }
    return true;
}

}  // namespace slicing
}  // namespace mesh4d
