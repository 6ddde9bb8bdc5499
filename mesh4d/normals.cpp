#include "normals.h"

#include <cmath>
#include <cstring>

#if !defined(APPARENT_NO_TBB)
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#endif

#include "angles.h"
#if !defined(APPARENT_NO_LANES)
#include "lanes.h"
#endif

namespace mesh4d {

namespace {
Vec3 unitOr(const Vec3& v, const Vec3& fallback) {
    const double len = norm(v);
    return len > 0 ? v / len : fallback;
}

constexpr size_t kGrain = 16384;  // elements per parallel task

// body(begin, end) over [0, n) in blocks of about kGrain, in parallel; without TBB (the WebAssembly
// build, APPARENT_NO_TBB) as one block. The blocks' work is independent: the same results.
template <class Body>
void forBlocks(size_t n, const Body& body) {
#if defined(APPARENT_NO_TBB)
    body(size_t(0), n);
#else
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain),
                      [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
#endif
}
// Whether body(begin, end, init) holds on every block (body returns init && its own test).
template <class Body>
bool allBlocks(size_t n, bool init, const Body& body) {
#if defined(APPARENT_NO_TBB)
    return body(size_t(0), n, init);
#else
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, n, kGrain), init,
        [&](const tbb::blocked_range<size_t>& r, bool all) { return body(r.begin(), r.end(), all); },
        [](bool a, bool b) { return a && b; });
#endif
}

// v / |v| and |v| (length), |v| as libstdc++'s std::hypot(x, y, z) computes norm(): a sqrt((x/a)^2 +
// (y/a)^2 + (z/a)^2) with a the largest magnitude (0 when a is 0; v / 1 then).
Vec3 unitOf(const Vec3& v, double* length) {
    const double ax = std::fabs(v.x), ay = std::fabs(v.y), az = std::fabs(v.z);
    const double a = ax < ay ? (ay < az ? az : ay) : (ax < az ? az : ax);
    const bool is_zero = a == 0;
    const double safe = is_zero ? 1 : a;
    const double qx = ax / safe, qy = ay / safe, qz = az / safe;
    const double len = safe * std::sqrt(qx * qx + qy * qy + qz * qz);
    *length = is_zero ? 0 : len;
    const double d = is_zero ? 1 : len;
    return {v.x / d, v.y / d, v.z / d};
}

#if !defined(APPARENT_NO_LANES)
// unitOf for two vectors at once, each lane unitOf's operations in its order (lanes.h).
void unitOfLanes(Lanes2 x, Lanes2 y, Lanes2 z, Lanes2* ux, Lanes2* uy, Lanes2* uz, Lanes2* length) {
    const Lanes2Mask sign = {(long long)0x8000000000000000ull, (long long)0x8000000000000000ull};
    auto abs = [&](Lanes2 v) { return (Lanes2)((Lanes2Mask)v & ~sign); };
    const Lanes2 ax = abs(x), ay = abs(y), az = abs(z);
    const Lanes2 t1 = ay < az ? az : ay, t2 = ax < az ? az : ax;
    const Lanes2 a = ax < ay ? t1 : t2;
    const Lanes2 zero = {0, 0}, one = {1, 1};
    const Lanes2Mask is_zero = a == zero;
    const Lanes2 safe = is_zero ? one : a;
    const Lanes2 qx = ax / safe, qy = ay / safe, qz = az / safe;
    const Lanes2 len = safe * sqrtLanes(qx * qx + qy * qy + qz * qz);
    *length = is_zero ? zero : len;
    const Lanes2 d = is_zero ? one : len;
    *ux = x / d;
    *uy = y / d;
    *uz = z / d;
}
#endif

// The per-vertex step of creaseSplitMap: whether a vertex's faces are all within the crease
// angle of one another (the vertex then has one normal), and the sum of their area vectors in CSR
// order (what every corner would sum). Raw pointers: through references every array would be
// reloaded after each store.
struct VertexPass {
    const Vec3* area;
    const uint32_t* start;
    const uint32_t* faces;
    double cos_crease;
    // Quick sufficient test: every face within half the crease angle (less a margin far above
    // rounding) of the first face, so every pair within the crease angle (angles obey the
    // triangle inequality); as squares, cos_half2 |a_f|^2 |a_0|^2 <= (a_f . a_0)^2 with a_f . a_0 > 0,
    // no square root and one pass with the sum. Only for squared areas in [kLeast, kMost], where
    // neither the squares nor their products leave the normal range of doubles; the exact
    // pairwise test decides the rest.
    double cos_half2;
    static constexpr double kLeast = 1e-100, kMost = 1e100;

    // Face f's unit normal (zero for a face of zero area, which is within no angle of another):
    // area / sqrt(area . area), the same bits wherever it is taken.
    Vec3 unit(uint32_t f) const {
        const double length = std::sqrt(dot(area[f], area[f]));
        return length > 0 ? area[f] / length : Vec3{0, 0, 0};
    }

    bool allWithin(uint32_t v, Vec3* sum_out) const {
        const uint32_t first = start[v], end = start[v + 1];
        const Vec3 a0 = area[faces[first]];
        const double n0 = dot(a0, a0);
        bool quick = n0 >= kLeast && n0 <= kMost;
        const double bound = cos_half2 * n0;
        Vec3 sum{0, 0, 0};
        for (uint32_t k = first; k < end; ++k) {
            const Vec3 a = area[faces[k]];
            sum += a;
            const double d = dot(a, a0), n = dot(a, a);
            quick &= (d > 0) & (d * d >= bound * n) & (n >= kLeast) & (n <= kMost);
        }
        *sum_out = sum;
        if (quick) return true;
        for (uint32_t a = first; a < end; ++a) {
            const uint32_t f = faces[a];
            const Vec3 uf = unit(f);
            for (uint32_t b = first; b < end; ++b) {
                const uint32_t g = faces[b];
                if (g != f && !(dot(unit(g), uf) >= cos_crease)) return false;
            }
        }
        return true;
    }

    // Vertices order[i] (i itself without `order`) for i in [lo, hi): uniform[v] set where every
    // pair of v's faces is within the crease angle and their sum is not zero, and then
    // normal[i] = sum / norm(sum) (norm(): std::hypot, bit for bit, two vertices at a time).
    void run(size_t lo, size_t hi, const uint32_t* order, unsigned char* uniform, Vec3* normal) const {
        for (size_t i = lo; i < hi; ++i) {
            const uint32_t v = order ? order[i] : uint32_t(i);
            if (start[v] == start[v + 1]) continue;
            Vec3 sum;
            if (!allWithin(v, &sum)) continue;
            uniform[v] = 1;
            normal[i] = sum;  // normalized below
        }
#if defined(APPARENT_NO_LANES)
        for (size_t i = lo; i < hi; ++i) {
            const uint32_t v = order ? order[i] : uint32_t(i);
            if (!uniform[v]) continue;
            double len;
            const Vec3 u = unitOf(normal[i], &len);
            if (!(len > 0)) uniform[v] = 0;  // a zero sum: each corner falls back to its own face
            else normal[i] = u;
        }
#else
        for (size_t i = lo; i < hi; i += 2) {
            const size_t j = std::min(i + 1, hi - 1);  // an odd end repeats its last vertex
            const Vec3 s0 = normal[i], s1 = normal[j];
            Lanes2 x = {s0.x, s1.x}, y = {s0.y, s1.y}, z = {s0.z, s1.z}, ux, uy, uz, len;
            unitOfLanes(x, y, z, &ux, &uy, &uz, &len);
            for (int k = 0; k < 2; ++k) {
                const size_t at = k == 0 ? i : j;
                const uint32_t v = order ? order[at] : uint32_t(at);
                if (!uniform[v]) continue;
                if (!(len[k] > 0)) uniform[v] = 0;  // a zero sum: each corner falls back to its own face
                else normal[at] = {ux[k], uy[k], uz[k]};
            }
        }
#endif
    }
};
}  // namespace

void creaseSplitMap(const ApparentMesh& mesh, double crease_deg, CreaseMap* out, CreaseWork* w) {
    const double cos_crease = std::cos(crease_deg * kPi / 180.0);
    const size_t nf = mesh.triangles.size(), nv = mesh.positions.size();

    // Step: face area vectors (parallel); faces around each vertex (CSR layout). The same pass
    // compares the triangles with the last call's (adjacency reuse), when the counts match.
    w->area.resize(nf);
    const bool may_be_same = w->vertices == nv && w->triangles.size() == nf && w->start.size() == nv + 1;
    const bool same = allBlocks(nf, may_be_same, [&](size_t begin, size_t end, bool equal) {
        const std::array<uint32_t, 3>* const tri = mesh.triangles.data();
        const Vec3* const pos = mesh.positions.data();
        Vec3* const area = w->area.data();
        for (size_t f = begin; f < end; ++f) {
            const auto& t = tri[f];
            area[f] = cross(pos[t[1]] - pos[t[0]], pos[t[2]] - pos[t[0]]);
        }
        return equal && std::memcmp(w->triangles.data() + begin, tri + begin, (end - begin) * sizeof(tri[0])) == 0;
    });
    if (!same) {
        w->unsplit = false;
        w->vertices = nv;
        w->triangles = mesh.triangles;
        w->start.assign(nv + 1, 0);
        w->faces.resize(3 * nf);
        for (const auto& t : mesh.triangles)
            for (uint32_t v : t) ++w->start[v + 1];
        for (size_t v = 0; v < nv; ++v) w->start[v + 1] += w->start[v];
        w->fill.assign(w->start.begin(), w->start.end() - 1);
        for (size_t f = 0; f < nf; ++f)
            for (uint32_t v : mesh.triangles[f]) w->faces[w->fill[v]++] = uint32_t(f);
    }
    const VertexPass pass{w->area.data(), w->start.data(), w->faces.data(), cos_crease,
                          std::pow(std::cos(0.5 * crease_deg * kPi / 180.0 - 1e-6), 2)};

    // Step (parallel): a vertex whose faces are all within the crease angle of one another gives
    // every corner the same sum, so one normal (the sum of all its faces, in the same order);
    // unless that sum is zero, where each corner falls back to its own face.
    // When the last call on the same triangles split no vertex, the vertices are taken in `out`'s
    // numbering and their normals written straight into `out` (no vertex split then or now: the
    // numbering and triangles stand, only the normals change); a vertex split now sends the
    // normals back to vertex order for the numbering below.
    w->uniform.assign(nv, 0);
    unsigned char* const uniform = w->uniform.data();
    const bool renumbered = !(same && w->unsplit && out->source.size() == nv);
    const uint32_t* const order = renumbered ? nullptr : out->source.data();
    Vec3* normal;
    if (renumbered) {
        w->vertex_normal.resize(nv);
        normal = w->vertex_normal.data();
    } else {
        out->normals.resize(nv);
        normal = out->normals.data();
    }
    forBlocks(nv, [&](size_t begin, size_t end) { pass.run(begin, end, order, uniform, normal); });
    size_t used = 0;
    for (size_t v = 0; v < nv; ++v) used += uniform[v];
    const bool unsplit = used == nv;
    if (!renumbered) {
        if (unsplit) return;
        w->vertex_normal.resize(nv);
        for (size_t k = 0; k < nv; ++k) w->vertex_normal[out->source[k]] = out->normals[k];
    }
    w->unsplit = unsplit;

    // The normal of the corner of face f at vertex v: the faces around v within the crease angle
    // of f, summed in CSR order.
    const std::vector<Vec3>& area = w->area;
    auto cornerNormal = [&](size_t f, uint32_t v) {
        Vec3 sum{0, 0, 0};
        const Vec3 uf = pass.unit(uint32_t(f));
        for (uint32_t k = w->start[v]; k < w->start[v + 1]; ++k) {
            const uint32_t g = w->faces[k];
            if (g == f || dot(pass.unit(g), uf) >= cos_crease) sum += area[g];
        }
        return unitOr(sum, unitOr(area[f], {0, 0, 1}));
    };

    // Step: split vertices numbered in order of their first corner (faces in order); corners of a
    // vertex with bit-identical normals share one split vertex.
    out->source.clear();
    out->normals.clear();
    out->source.reserve(nv);
    out->normals.reserve(nv);
    out->triangles.resize(nf);
    w->first_copy.assign(nv, UINT32_MAX);
    w->next_copy.clear();
    w->next_copy.reserve(nv);
    for (size_t f = 0; f < nf; ++f) {
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = mesh.triangles[f][c];
            uint32_t id = UINT32_MAX;
            Vec3 n;
            if (w->uniform[v]) {
                id = w->first_copy[v];
                n = w->vertex_normal[v];
            } else {
                n = cornerNormal(f, v);
                for (uint32_t o = w->first_copy[v]; o != UINT32_MAX; o = w->next_copy[o])
                    if (out->normals[o] == n) id = o;
            }
            if (id == UINT32_MAX) {
                id = uint32_t(out->source.size());
                out->source.push_back(v);
                out->normals.push_back(n);
                w->next_copy.push_back(w->first_copy[v]);  // prepend: the list's order does not matter
                w->first_copy[v] = id;
            }
            out->triangles[f][c] = id;
        }
    }
}

CreasedMesh creaseSplit(const ApparentMesh& mesh, double crease_deg) {
    CreaseMap map;
    CreaseWork work;
    creaseSplitMap(mesh, crease_deg, &map, &work);
    CreasedMesh out;
    out.mesh.positions.reserve(map.source.size());
    out.mesh.emission_times.reserve(map.source.size());
    for (uint32_t v : map.source) {
        out.mesh.positions.push_back(mesh.positions[v]);
        out.mesh.emission_times.push_back(mesh.emission_times[v]);
    }
    out.normals = std::move(map.normals);
    out.mesh.triangles = std::move(map.triangles);
    out.mesh.clipped_triangles = mesh.clipped_triangles;
    out.mesh.origin = mesh.origin;
    out.mesh.time_origin = mesh.time_origin;
    return out;
}

}  // namespace mesh4d
