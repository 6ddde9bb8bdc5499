// Attributes of the cut's vertices from the rest triangles they lie on (surface_look.h).
#include "exporters/surface_look.h"

namespace apparent {

using mesh4d::Vec3;

std::array<double, 3> restBarycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q) {
    if (q == a) return {1, 0, 0};
    if (q == b) return {0, 1, 0};
    if (q == c) return {0, 0, 1};
    const Vec3 e1 = b - a, e2 = c - a, w = q - a;
    const double d11 = mesh4d::dot(e1, e1), d12 = mesh4d::dot(e1, e2), d22 = mesh4d::dot(e2, e2);
    const double r1 = mesh4d::dot(w, e1), r2 = mesh4d::dot(w, e2);
    const double det = d11 * d22 - d12 * d12;
    if (!(det > 0)) return {1, 0, 0};  // degenerate triangles are dropped on reading
    const double l1 = (r1 * d22 - r2 * d12) / det;
    const double l2 = (r2 * d11 - r1 * d12) / det;
    return {1 - l1 - l2, l1, l2};
}

void interpolateLook(const SurfaceLook& look, const mesh4d::RestMesh& rest_mesh, const mesh4d::ApparentMesh& mesh,
                     VertexLook* out) {
    const size_t nv = mesh.positions.size();
    // Step: each attribute the look has, with its components per vertex.
    struct Channel {
        const std::vector<double>* in;
        std::vector<double>* out;
        size_t per;
    };
    std::vector<Channel> channels;
    for (Channel c : {Channel{&look.texcoord, &out->texcoord, 2}, Channel{&look.texcoord1, &out->texcoord1, 2},
                      Channel{&look.color, &out->color, 4}}) {
        c.out->assign(c.in->empty() ? 0 : c.per * nv, 0.0);
        if (!c.in->empty()) channels.push_back(c);
    }
    if (channels.empty() || mesh.rest_points.size() != nv || mesh.source_triangles.size() != mesh.triangles.size())
        return;
    // Step: each vertex from the first triangle that uses it (on a shared edge both agree).
    std::vector<bool> done(nv, false);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const std::array<uint32_t, 3>& rest = rest_mesh.triangles[mesh.source_triangles[t]];
        for (const uint32_t v : mesh.triangles[t]) {
            if (done[v]) continue;
            done[v] = true;
            const std::array<double, 3> l =
                restBarycentric(rest_mesh.positions[rest[0]], rest_mesh.positions[rest[1]],
                                rest_mesh.positions[rest[2]], mesh.rest_points[v]);
            for (const Channel& ch : channels)
                for (size_t c = 0; c < ch.per; ++c) {
                    double s = 0;
                    for (int k = 0; k < 3; ++k)
                        if (l[size_t(k)] != 0) s += l[size_t(k)] * (*ch.in)[ch.per * rest[size_t(k)] + c];
                    (*ch.out)[ch.per * v + c] = s;
                }
        }
    }
}

}  // namespace apparent
