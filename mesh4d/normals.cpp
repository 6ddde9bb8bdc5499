#include "normals.h"

#include <cmath>

#include "angles.h"

namespace mesh4d {

namespace {
Vec3 unitOr(const Vec3& v, const Vec3& fallback) {
    const double len = norm(v);
    return len > 0 ? v / len : fallback;
}
}  // namespace

CreasedMesh creaseSplit(const ApparentMesh& mesh, double crease_deg) {
    const double cos_crease = std::cos(crease_deg * kPi / 180.0);
    const size_t nf = mesh.triangles.size(), nv = mesh.positions.size();

    // Step: face area vectors and unit normals; faces around each vertex (CSR layout).
    std::vector<Vec3> area(nf), unit(nf);
    std::vector<uint32_t> start(nv + 1, 0), faces(3 * nf);
    for (size_t f = 0; f < nf; ++f) {
        const auto& t = mesh.triangles[f];
        area[f] = cross(mesh.positions[t[1]] - mesh.positions[t[0]], mesh.positions[t[2]] - mesh.positions[t[0]]);
        unit[f] = unitOr(area[f], {0, 0, 0});
        for (uint32_t v : t) ++start[v + 1];
    }
    for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t f = 0; f < nf; ++f)
        for (uint32_t v : mesh.triangles[f]) faces[fill[v]++] = uint32_t(f);

    // Step: one normal per corner from the faces within the crease angle; corners of a vertex
    // with bit-identical normals share one output vertex.
    CreasedMesh out;
    // Output vertices made for each input vertex, as linked lists through the output ids (most
    // vertices get one copy; no allocation per vertex).
    std::vector<uint32_t> first_copy(nv, UINT32_MAX), next_copy;
    next_copy.reserve(nv);
    out.mesh.positions.reserve(nv);
    out.mesh.emission_times.reserve(nv);
    out.normals.reserve(nv);
    out.mesh.triangles.resize(nf);
    for (size_t f = 0; f < nf; ++f) {
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = mesh.triangles[f][c];
            Vec3 sum{0, 0, 0};
            for (uint32_t k = start[v]; k < start[v + 1]; ++k) {
                const uint32_t g = faces[k];
                if (g == f || dot(unit[g], unit[f]) >= cos_crease) sum += area[g];
            }
            const Vec3 n = unitOr(sum, unitOr(area[f], {0, 0, 1}));
            uint32_t id = UINT32_MAX;
            for (uint32_t o = first_copy[v]; o != UINT32_MAX; o = next_copy[o])
                if (out.normals[o] == n) id = o;
            if (id == UINT32_MAX) {
                id = uint32_t(out.mesh.positions.size());
                out.mesh.positions.push_back(mesh.positions[v]);
                out.mesh.emission_times.push_back(mesh.emission_times[v]);
                out.normals.push_back(n);
                next_copy.push_back(first_copy[v]);  // prepend: the list's order does not matter
                first_copy[v] = id;
            }
            out.mesh.triangles[f][c] = id;
        }
    }
    out.mesh.clipped_triangles = mesh.clipped_triangles;
    out.mesh.origin = mesh.origin;
    out.mesh.time_origin = mesh.time_origin;
    return out;
}

}  // namespace mesh4d
