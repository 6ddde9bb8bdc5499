// An object's cut mesh as the file's float32 arrays (toPrimitive, glb.h): relative to the frame's
// origin, split along creases, and with meshopt also packed (packMeshopt, meshopt.cpp).
#include <algorithm>
#include <cmath>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "exporters/glb/glb.h"
#include "mesh4d/doppler_colour.h"
#include "mesh4d/normals.h"

namespace apparent::glb {

namespace {

// Vertices are split along creases sharper than this (degrees).
constexpr double kCreaseDeg = 30.0;

// The look's attributes per split vertex, as float32 (surface_look.h), and the triangles grouped by
// material (a stable counting sort: each part keeps the cut's order).
void lookArrays(const mesh4d::ApparentMesh& m, const ExportObject& object, const mesh4d::CreaseMap& map, bool shade,
                PrimitiveData* d) {
    const SurfaceLook& look = *object.look;
    VertexLook vertex_look;
    interpolateLook(look, *object.rest, m, &vertex_look);
    const std::vector<double>& rgba = vertex_look.color;
    const size_t nv = map.source.size();
    for (auto [uv, out] : {std::pair{&vertex_look.texcoord, &d->texcoords}, std::pair{&vertex_look.texcoord1, &d->texcoords1}}) {
        out->resize(uv->empty() ? 0 : 2 * nv);
        for (size_t k = 0; k < out->size() / 2; ++k)
            for (size_t c = 0; c < 2; ++c) (*out)[2 * k + c] = float((*uv)[2 * map.source[k] + c]);
    }
    // With --shade doppler the modulation W(D) (toPrimitive's COLOR_0) times the input's colour.
    if (!rgba.empty()) {
        d->colors.resize(3 * nv);
        for (size_t k = 0; k < nv; ++k) {
            const uint32_t v = map.source[k];
            const std::array<double, 3> w =
                shade ? mesh4d::dopplerModulation(m.doppler[v]) : std::array<double, 3>{1, 1, 1};
            for (size_t c = 0; c < 3; ++c)  // within [0, 1] as glTF asks (rounding of the interpolation)
                d->colors[3 * k + c] = float(w[c] * std::clamp(rgba[4 * v + c], 0.0, 1.0));
        }
    }
    // Step: each material's triangles, then where its part starts (materials without any: no part).
    std::vector<uint32_t> count(look.materials.size(), 0), next(look.materials.size(), 0);
    for (const uint32_t s : m.source_triangles) ++count[look.triangle_material[s]];
    d->part_first.clear();
    d->part_material.clear();
    uint32_t at = 0;
    for (uint32_t p = 0; p < count.size(); ++p) {
        next[p] = at;
        if (count[p] == 0) continue;
        d->part_first.push_back(at);
        d->part_material.push_back(p);
        at += count[p];
    }
    d->part_first.push_back(at);
    // Step: the triangles into their parts, in the cut's order within each.
    for (size_t t = 0; t < map.triangles.size(); ++t) {
        const uint32_t p = look.triangle_material[m.source_triangles[t]];
        std::memcpy(d->indices.data() + 3 * size_t(next[p]++), map.triangles[t].data(), sizeof(map.triangles[t]));
    }
}

}  // namespace

bool carriesLook(const GlbOptions& /*options*/, const ExportObject& object) { return bool(object.look); }

void toPrimitive(const mesh4d::ApparentMesh& m, const double origin[3], double step, double* max_err,
                 double* max_quant, PrimitiveData* d, mesh4d::CreaseMap* map, mesh4d::CreaseWork* work,
                 MeshoptScratch* scratch, MeshoptOrder* order, const GlbOptions& options,
                 const ExportObject& object) {
    const std::array<double, 4>& base_color = object.base_color;
    mesh4d::creaseSplitMap(m, kCreaseDeg, map, work);
    const size_t nv = map->source.size();
    d->positions.resize(3 * nv);
    d->normals.resize(3 * nv);
    d->emission.resize(nv);
    const bool doppler = options.doppler && m.doppler.size() == m.positions.size();
    const bool proper_time = options.proper_time && m.proper_time.size() == m.positions.size();
    d->doppler.resize(doppler ? nv : 0);
    d->proper_time.resize(proper_time ? nv : 0);
    const bool shade = options.shade_doppler && m.doppler.size() == m.positions.size();
    d->colors.resize(shade ? 3 * nv : 0);
    // With --shade doppler: the shaded base colour, or for an object that keeps its input's
    // materials the modulation W(D) of them (mesh4d/doppler_colour.h), the shaded colour of white.
    const bool look = carriesLook(options, object);
    const std::array<double, 3> base = look ? std::array<double, 3>{1, 1, 1}
                                            : std::array<double, 3>{base_color[0], base_color[1], base_color[2]};
    std::vector<double>& exact = scratch->exact;
    exact.resize(step > 0 ? 3 * nv : 0);
    // The object's own origin first: both large terms cancel before the small local one is added.
    const double shift[3] = {m.origin[0] - origin[0], m.origin[1] - origin[1], m.origin[2] - origin[2]};
    // The largest rounding and the float32 positions' bounds. std::min and std::max keep the
    // first of equal values (a signed zero) and the join takes the left part first, so the
    // bounds are GlbBuilder::bounds()'s in vertex order, bit for bit, whatever the split.
    struct Reduced {
        double worst = 0;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    };
    const Reduced reduced = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nv, 16384), Reduced{},
        [&](const tbb::blocked_range<size_t>& r, Reduced red) {
            // Local pointers: through the by-reference captures every array would be reloaded
            // after each store.
            const uint32_t* const source = map->source.data();
            const mesh4d::Vec3* const pos = m.positions.data();
            const mesh4d::Vec3* const nrm = map->normals.data();
            float* const out_pos = d->positions.data();
            float* const out_nrm = d->normals.data();
            float* const out_emission = d->emission.data();
            double* const out_exact = step > 0 ? exact.data() : nullptr;
            const double s0 = shift[0], s1 = shift[1], s2 = shift[2];
            double w = red.worst;
            double lo[3] = {red.lo[0], red.lo[1], red.lo[2]}, hi[3] = {red.hi[0], red.hi[1], red.hi[2]};
            for (size_t k = r.begin(); k < r.end(); ++k) {
                const uint32_t v = source[k];
                const double rel[3] = {s0 + pos[v].x, s1 + pos[v].y, s2 + pos[v].z};
                for (int c = 0; c < 3; ++c) {
                    const float fv = float(rel[c]);
                    out_pos[3 * k + c] = fv;
                    w = std::max(w, std::fabs(double(fv) - rel[c]));
                    lo[c] = std::min(lo[c], double(fv));
                    hi[c] = std::max(hi[c], double(fv));
                    if (out_exact) out_exact[3 * k + c] = rel[c];
                }
                out_nrm[3 * k] = float(nrm[k].x);
                out_nrm[3 * k + 1] = float(nrm[k].y);
                out_nrm[3 * k + 2] = float(nrm[k].z);
                out_emission[k] = float(m.absoluteTime(v));
                if (doppler) d->doppler[k] = float(m.doppler[v]);
                if (proper_time) d->proper_time[k] = float(m.proper_time[v]);
                if (shade) {
                    const std::array<double, 3> c =
                        look ? mesh4d::dopplerModulation(m.doppler[v]) : mesh4d::dopplerColour(base, m.doppler[v]);
                    for (int j = 0; j < 3; ++j) d->colors[3 * k + size_t(j)] = float(c[size_t(j)]);
                }
            }
            red.worst = w;
            for (int c = 0; c < 3; ++c) {
                red.lo[c] = lo[c];
                red.hi[c] = hi[c];
            }
            return red;
        },
        [](Reduced a, const Reduced& b) {
            a.worst = std::max(a.worst, b.worst);
            for (int c = 0; c < 3; ++c) {
                a.lo[c] = std::min(a.lo[c], b.lo[c]);
                a.hi[c] = std::max(a.hi[c], b.hi[c]);
            }
            return a;
        });
    *max_err = std::max(*max_err, reduced.worst);
    d->bounded = true;
    for (int c = 0; c < 3; ++c) {
        d->lo[c] = reduced.lo[c];
        d->hi[c] = reduced.hi[c];
    }
    d->indices.resize(3 * map->triangles.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, map->triangles.size(), 65536), [&](const tbb::blocked_range<size_t>& r) {
        std::memcpy(d->indices.data() + 3 * r.begin(), map->triangles.data() + r.begin(), r.size() * sizeof(map->triangles[0]));
    });
    d->texcoords.clear();
    d->texcoords1.clear();
    d->part_first.clear();
    d->part_material.clear();
    if (carriesLook(options, object) && object.rest && m.source_triangles.size() == m.triangles.size() &&
        m.rest_points.size() == m.positions.size())
        lookArrays(m, object, *map, shade, d);
    if (step > 0)
        *max_quant = std::max(*max_quant, packMeshopt(d, exact, step, MeshoptLayout(options), order,
                                                      &scratch->normals));
}

}  // namespace apparent::glb
