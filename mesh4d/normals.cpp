#include "normals.h"

#include <cmath>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "angles.h"

namespace mesh4d {

namespace {
Vec3 unitOr(const Vec3& v, const Vec3& fallback) {
    const double len = norm(v);
    return len > 0 ? v / len : fallback;
}

constexpr size_t kGrain = 16384;  // elements per parallel task

// v / norm(v) for two vectors at once, bit for bit what the scalar code gives: norm() is
// std::hypot(x, y, z), which libstdc++ computes as a * sqrt((x/a)^2 + (y/a)^2 + (z/a)^2) with a
// the largest magnitude (0 when a is 0), and every step here is the same IEEE operation in the
// same order on SSE2 lanes (no contraction: the build has no FMA). `length` receives the norms.
typedef double Pair __attribute__((vector_size(16)));
typedef long long PairMask __attribute__((vector_size(16)));
void unitPair(Pair x, Pair y, Pair z, Pair* ux, Pair* uy, Pair* uz, Pair* length) {
    const PairMask sign = {(long long)0x8000000000000000ull, (long long)0x8000000000000000ull};
    auto abs = [&](Pair v) { return (Pair)((PairMask)v & ~sign); };
    const Pair ax = abs(x), ay = abs(y), az = abs(z);
    const Pair t1 = ay < az ? az : ay, t2 = ax < az ? az : ax;
    const Pair a = ax < ay ? t1 : t2;
    const Pair zero = {0, 0}, one = {1, 1};
    const PairMask is_zero = a == zero;
    const Pair safe = is_zero ? one : a;
    const Pair qx = ax / safe, qy = ay / safe, qz = az / safe;
    const Pair len = safe * __builtin_ia32_sqrtpd(qx * qx + qy * qy + qz * qz);
    *length = is_zero ? zero : len;
    const Pair d = is_zero ? one : len;
    *ux = x / d;
    *uy = y / d;
    *uz = z / d;
}
}  // namespace

void creaseSplitMap(const ApparentMesh& mesh, double crease_deg, CreaseMap* out, CreaseWork* w) {
    const double cos_crease = std::cos(crease_deg * kPi / 180.0);
    const size_t nf = mesh.triangles.size(), nv = mesh.positions.size();

    // Step: face area vectors and their lengths (parallel); faces around each vertex (CSR layout).
    // The direction only feeds the crease tests: sqrt of the dot product, not norm()'s hypot (the
    // output normals below still use norm()); unit() gives it where needed, the same bits each time.
    // The same pass compares the triangles with the last call's (adjacency reuse), when the counts match.
    w->area.resize(nf);
    w->length.resize(nf);
    const bool may_be_same = w->vertices == nv && w->triangles.size() == nf && w->start.size() == nv + 1;
    const bool same = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nf, kGrain), may_be_same,
        [&](const tbb::blocked_range<size_t>& r, bool equal) {
            const std::array<uint32_t, 3>* const tri = mesh.triangles.data();
            const Vec3* const pos = mesh.positions.data();
            Vec3* const area = w->area.data();
            double* const length = w->length.data();
            for (size_t f = r.begin(); f < r.end(); ++f) {
                const auto& t = tri[f];
                const Vec3 a = cross(pos[t[1]] - pos[t[0]], pos[t[2]] - pos[t[0]]);
                area[f] = a;
                length[f] = std::sqrt(dot(a, a));
            }
            return equal && std::memcmp(w->triangles.data() + r.begin(), tri + r.begin(), r.size() * sizeof(tri[0])) == 0;
        },
        [](bool a, bool b) { return a && b; });
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
    const std::vector<Vec3>& area = w->area;
    const std::vector<double>& length = w->length;
    const std::vector<uint32_t>& start = w->start;
    const std::vector<uint32_t>& faces = w->faces;
    // Face f's unit normal (zero for a face of zero area, which is within no angle of another).
    auto unit = [&](size_t f) { return length[f] > 0 ? area[f] / length[f] : Vec3{0, 0, 0}; };

    // The normal of the corner of face f at vertex v: the faces around v within the crease angle
    // of f, summed in CSR order.
    auto cornerNormal = [&](size_t f, uint32_t v) {
        Vec3 sum{0, 0, 0};
        const Vec3 uf = unit(f);
        for (uint32_t k = start[v]; k < start[v + 1]; ++k) {
            const uint32_t g = faces[k];
            if (g == f || dot(unit(g), uf) >= cos_crease) sum += area[g];
        }
        return unitOr(sum, unitOr(area[f], {0, 0, 1}));
    };

    // Step (parallel): a vertex whose faces are all within the crease angle of one another gives
    // every corner the same sum, so one normal (the sum of all its faces, in the same order);
    // unless that sum is zero, where each corner falls back to its own face.
    // Quick sufficient test first: when every face is within half the crease angle (less a margin
    // far above rounding) of one direction, every pair is within the crease angle (angles obey the
    // triangle inequality); otherwise every pair is tested. The direction is the sum of the area
    // vectors (what the vertex's normal is made of), so the test reads each face's area vector and
    // length once: dot(a_f, s) >= cos_half |a_f| |s|.
    const double cos_half_ = std::cos(0.5 * crease_deg * kPi / 180.0 - 1e-6);
    w->uniform.assign(nv, 0);
    w->vertex_normal.resize(nv);
    // Raw pointers: the stores to `uniform` (bytes, which may alias anything) would otherwise
    // reload every vector's data pointer in the inner loops.
    const Vec3* const area_p_ = area.data();
    const double* const length_p_ = length.data();
    const uint32_t* const start_p_ = start.data();
    const uint32_t* const faces_p_ = faces.data();
    unsigned char* const uniform_p_ = w->uniform.data();
    Vec3* const vertex_normal_p_ = w->vertex_normal.data();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, kGrain), [&](const tbb::blocked_range<size_t>& r) {
        // Local copies: the captures are references, reloaded through the closure after every store.
        const Vec3* const area_p = area_p_;
        const double* const length_p = length_p_;
        const uint32_t* const start_p = start_p_;
        const uint32_t* const faces_p = faces_p_;
        unsigned char* const uniform_p = uniform_p_;
        Vec3* const vertex_normal_p = vertex_normal_p_;
        const double cos_half = cos_half_;
        for (size_t v = r.begin(); v < r.end(); ++v) {
            const uint32_t first = start_p[v], end = start_p[v + 1];
            if (first == end) continue;
            // The sum of the area vectors in CSR order (what every corner would sum).
            Vec3 sum{0, 0, 0};
            for (uint32_t a = first; a < end; ++a) sum += area_p[faces_p[a]];
            const double bound = cos_half * std::sqrt(dot(sum, sum));  // the sufficient test alone (margin above)
            bool all = bound > 0;
            for (uint32_t a = first; a < end && all; ++a) {
                const uint32_t f = faces_p[a];
                all = length_p[f] > 0 && dot(area_p[f], sum) >= bound * length_p[f];
            }
            if (!all) {
                all = true;
                for (uint32_t a = start[v]; a < start[v + 1] && all; ++a) {
                    const uint32_t f = faces[a];
                    const Vec3 uf = unit(f);
                    for (uint32_t b = start[v]; b < start[v + 1]; ++b) {
                        const uint32_t g = faces[b];
                        if (g != f && !(dot(unit(g), uf) >= cos_crease)) {
                            all = false;
                            break;
                        }
                    }
                }
            }
            if (!all) continue;
            uniform_p[v] = 1;
            vertex_normal_p[v] = sum;  // normalized below, two at a time
        }
        // sum / norm(sum), or not uniform after all where the sum is zero (each corner then
        // falls back to its own face).
        for (size_t v = r.begin(); v < r.end(); v += 2) {
            const size_t b = std::min(v + 1, r.end() - 1);  // an odd end repeats its last vertex
            const Vec3 s0 = vertex_normal_p[v], s1 = vertex_normal_p[b];
            Pair x = {s0.x, s1.x}, y = {s0.y, s1.y}, z = {s0.z, s1.z}, ux, uy, uz, len;
            unitPair(x, y, z, &ux, &uy, &uz, &len);
            for (int k = 0; k < 2; ++k) {
                const size_t i = k == 0 ? v : b;
                if (!uniform_p[i]) continue;
                if (!(len[k] > 0)) uniform_p[i] = 0;
                else vertex_normal_p[i] = {ux[k], uy[k], uz[k]};
            }
        }
    });
    // No vertex split (every used vertex uniform, none unused), as in the last call on the same
    // triangles: the numbering and triangles in `out` stand; only the normals change.
    size_t used = 0;
    for (size_t v = 0; v < nv; ++v) used += w->uniform[v];
    const bool unsplit = used == nv;
    if (same && unsplit && w->unsplit && out->source.size() == nv) {
        out->normals.resize(nv);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, kGrain), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t k = r.begin(); k < r.end(); ++k) out->normals[k] = w->vertex_normal[out->source[k]];
        });
        return;
    }
    w->unsplit = unsplit;

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
