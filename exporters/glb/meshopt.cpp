// Meshopt packing (packMeshopt, meshoptStep), a frame's index stream, and frame coherence's record
// arithmetic (runReference, morphRecords, encodeMorphRecords): glb.h.
#include <algorithm>
#include <cmath>
#include <cstring>

#include <meshoptimizer.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "exporters/glb/glb.h"

namespace apparent::glb {

namespace {

// The emission time as meshopt stores it: rounded (half away from zero) to a multiple of the
// largest power of two not above `step`, so that its low mantissa bits are zero and compress;
// it stays a float32 that readers use as it is, within step / 2 seconds of the plain file's.
double emissionStep(double step) { return std::ldexp(1.0, int(std::floor(std::log2(step)))); }
float emissionRounded(float t, double q) { return float(std::round(double(t) / q) * q); }

}  // namespace

double packMeshopt(PrimitiveData* d, const std::vector<double>& rel, double step, const MeshoptLayout& layout,
                   MeshoptOrder* order, std::vector<float>* normal_work) {
    const size_t nv = d->vertexCount();
    if (!order->ordered || order->vertices != nv || order->indices != d->indices || order->part_first != d->part_first) {
        order->indices = d->indices;
        order->part_first = d->part_first;
        order->vertices = nv;
        // A frame still held refers to the old order: a new vector then, else this one again.
        if (!order->ordered || order->ordered.use_count() > 1) order->ordered = std::make_shared<std::vector<uint32_t>>();
        std::vector<uint32_t>& ordered = *order->ordered;
        ordered.resize(d->indices.size());
        if (d->part_first.empty()) {
            meshopt_optimizeVertexCache(ordered.data(), d->indices.data(), d->indices.size(), nv);
        } else {
            // Each material part on its own: its triangles stay a contiguous range.
            for (size_t p = 0; p + 1 < d->part_first.size(); ++p) {
                const size_t at = 3 * size_t(d->part_first[p]), n = 3 * size_t(d->part_first[p + 1]) - at;
                meshopt_optimizeVertexCache(ordered.data() + at, d->indices.data() + at, n, nv);
            }
        }
        order->remap.resize(nv);
        order->used = meshopt_optimizeVertexFetchRemap(order->remap.data(), ordered.data(), ordered.size(), nv);
        meshopt_remapIndexBuffer(ordered.data(), ordered.data(), ordered.size(), order->remap.data());
    }
    d->ordered = order->ordered;
    const std::vector<unsigned int>& remap = order->remap;
    const size_t used = order->used;
    const size_t stride = layout.stride;
    d->packed.assign(used * stride, 0);
    d->packed_snorm.assign(used * 4, 0);
    std::vector<float>& normals = *normal_work;  // x, y, z, 0 per vertex in stream order, for the filter
    normals.assign(4 * used, 0.0f);
    const double time_step = emissionStep(step);
    // Vertices in parallel (each writes its own record); the largest error and the bounds reduced.
    struct Extremes {
        double worst = 0;
        int lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    };
    const Extremes e = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nv, 16384), Extremes{},
        [&](const tbb::blocked_range<size_t>& r, Extremes x) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                if (remap[i] == ~0u) continue;  // used by no triangle: dropped (a cut mesh has none)
                unsigned char* v = d->packed.data() + size_t(remap[i]) * stride;
                int16_t q[4] = {0, 0, 0, 0};
                for (int c = 0; c < 3; ++c) {
                    const double p = std::nearbyint(rel[3 * i + c] / step);
                    q[c] = int16_t(std::clamp(p, -32767.0, 32767.0));
                    x.worst = std::max(x.worst, std::fabs(double(q[c]) * step - rel[3 * i + c]));
                    x.lo[c] = std::min(x.lo[c], int(q[c]));
                    x.hi[c] = std::max(x.hi[c], int(q[c]));
                    normals[4 * size_t(remap[i]) + size_t(c)] = d->normals[3 * i + c];
                    d->packed_snorm[4 * size_t(remap[i]) + size_t(c)] =
                        static_cast<unsigned char>(int8_t(meshopt_quantizeSnorm(d->normals[3 * i + c], 8)));
                }
                std::memcpy(v, q, 8);
                const float t = emissionRounded(d->emission[i], time_step);
                std::memcpy(v + 8, &t, 4);
                if (layout.doppler >= 0 && !d->doppler.empty()) std::memcpy(v + layout.doppler, &d->doppler[i], 4);
                if (layout.proper_time >= 0 && !d->proper_time.empty()) std::memcpy(v + layout.proper_time, &d->proper_time[i], 4);
                if (layout.color >= 0 && !d->colors.empty()) {
                    uint16_t rgb[4] = {0, 0, 0, 0};
                    for (int c = 0; c < 3; ++c) rgb[c] = uint16_t(meshopt_quantizeUnorm(std::clamp(d->colors[3 * i + c], 0.0f, 1.0f), 16));
                    std::memcpy(v + layout.color, rgb, 8);
                }
                if (layout.texcoord >= 0 && !d->texcoords.empty()) std::memcpy(v + layout.texcoord, &d->texcoords[2 * i], 8);
                if (layout.texcoord1 >= 0 && !d->texcoords1.empty()) std::memcpy(v + layout.texcoord1, &d->texcoords1[2 * i], 8);
            }
            return x;
        },
        [](Extremes a, const Extremes& b) {
            a.worst = std::max(a.worst, b.worst);
            for (int c = 0; c < 3; ++c) { a.lo[c] = std::min(a.lo[c], b.lo[c]); a.hi[c] = std::max(a.hi[c], b.hi[c]); }
            return a;
        });
    const double worst = e.worst;
    for (int c = 0; c < 3; ++c) { d->qmin[c] = e.lo[c]; d->qmax[c] = e.hi[c]; }
    d->packed_normals.resize(used * kMeshoptNormalStride);
    if (used > 0)
        meshopt_encodeFilterOct(d->packed_normals.data(), used, kMeshoptNormalStride, kMeshoptNormalBits, normals.data());
    return worst;
}

GlbOptions withMeshoptLooks(const GlbOptions& options, const SequenceInfo& info) {
    GlbOptions o = options;
    for (const ExportObject& object : info.objects)
        if (o.meshopt && carriesLook(o, object)) {
            o.meshopt_looks = true;
            o.meshopt_texcoord1 = o.meshopt_texcoord1 || object.look->has_texcoord1;
        }
    return o;
}

// In vertex mode at least 14 bits over E (Draco's and gltfpack's default): E / 16382 rounded down
// to a power of 2^(1/4) (at most 19% finer), so that frames of slightly different extents share
// the step and can be morph targets of one another (gltf.h; why a quarter octave: docs/GLTF.md,
// "meshopt: where the bytes go").
double meshoptStep(double extent, double tolerance, int bits, bool* clamped) {
    const double finest = extent / 65534.0;
    double step = bits > 0        ? extent / (std::ldexp(1.0, bits) - 2)
                  : tolerance > 0 ? tolerance / std::sqrt(3.0)
                                  : std::exp2(std::floor(4 * std::log2(extent / 16382.0)) / 4);
    *clamped = step < finest;  // only a tolerance can ask for more than int16 holds
    if (*clamped) step = finest;
    if (!(step > 0)) step = 1;  // every point at the origin: any step is exact
    return step;
}

void encodeFrameStreams(const std::vector<PrimitiveData>& data, size_t stride, MeshoptScratch* scratch,
                        MeshoptFrame* out) {
    MeshoptFrame& mf = *out;
    mf.first.assign(data.size(), 0);
    std::vector<unsigned char>& all = scratch->vertices;
    std::vector<unsigned char>& normals = scratch->normal_stream;
    all.clear();
    normals.clear();
    for (size_t o = 0; o < data.size(); ++o) {
        mf.first[o] = all.size() / stride;
        all.insert(all.end(), data[o].packed.begin(), data[o].packed.end());
        normals.insert(normals.end(), data[o].packed_normals.begin(), data[o].packed_normals.end());
    }
    mf.count = all.size() / stride;
    mf.encoded.resize(meshopt_encodeVertexBufferBound(mf.count, stride));
    mf.encoded.resize(meshopt_encodeVertexBuffer(mf.encoded.data(), mf.encoded.size(), all.data(), mf.count, stride));
    mf.encoded_normals.resize(meshopt_encodeVertexBufferBound(mf.count, kMeshoptNormalStride));
    mf.encoded_normals.resize(meshopt_encodeVertexBuffer(mf.encoded_normals.data(), mf.encoded_normals.size(),
                                                         normals.data(), mf.count, kMeshoptNormalStride));
    // Step: the records with the int8 normals at their end, encoded too; the smaller wins
    // (the separate view counted with its JSON).
    const size_t wide = stride + 4;
    std::vector<unsigned char>& records = scratch->inline_records;
    records.resize(mf.count * wide);
    size_t k = 0;
    for (size_t o = 0; o < data.size(); ++o) {
        const PrimitiveData& p = data[o];
        for (size_t i = 0; i < p.packed.size() / stride; ++i, ++k) {
            std::memcpy(&records[k * wide], &p.packed[i * stride], stride);
            std::memcpy(&records[k * wide + stride], &p.packed_snorm[4 * i], 4);
        }
    }
    std::vector<unsigned char>& encoded_inline = scratch->inline_encoded;
    encoded_inline.resize(meshopt_encodeVertexBufferBound(mf.count, wide));
    encoded_inline.resize(
        meshopt_encodeVertexBuffer(encoded_inline.data(), encoded_inline.size(), records.data(), mf.count, wide));
    mf.stride = stride;
    mf.normals_inline = encoded_inline.size() <= mf.encoded.size() + mf.encoded_normals.size() + kMeshoptViewJsonBytes;
    if (mf.normals_inline) {
        mf.encoded.swap(encoded_inline);
        mf.encoded_normals.clear();
        mf.stride = wide;
    }
}

void encodeIndexStream(const std::vector<unsigned int>& all, size_t most_vertices, std::vector<unsigned char>* out) {
    out->resize(meshopt_encodeIndexBufferBound(all.size(), most_vertices));
    out->resize(meshopt_encodeIndexBuffer(out->data(), out->size(), all.data(), all.size()));
}

bool appendOrdered(const PrimitiveData& d, std::vector<unsigned int>* all, std::string* error) {
    if (!d.remote.on) {
        all->insert(all->end(), d.ordered->begin(), d.ordered->end());
        return true;
    }
    if (d.remote.ordered.length != 4 * d.remote.ordered_count) {
        *error = "internal: a partly shared index stream without the objects' lists";
        return false;
    }
    const size_t at = all->size();
    all->resize(at + size_t(d.remote.ordered_count));
    return readSpan(d.remote.ordered, all->data() + at, error);
}

bool runReference(const std::vector<const PrimitiveData*>& shown, size_t count, bool normals_inline,
                  bool decoded_normals, std::vector<unsigned char>* records, std::vector<unsigned char>* normals) {
    size_t record_bytes = 0, normal_bytes = 0;
    for (const PrimitiveData* d : shown) {
        const std::vector<unsigned char>& n = decoded_normals && !normals_inline ? d->packed_normals : d->packed_snorm;
        record_bytes += d->packed.size();
        normal_bytes += n.size();
    }
    if (record_bytes != count * 12 || normal_bytes != count * 4) return false;
    if (!records) return true;
    records->clear();
    normals->clear();
    for (const PrimitiveData* d : shown) {
        records->insert(records->end(), d->packed.begin(), d->packed.end());
        const std::vector<unsigned char>& n = decoded_normals && !normals_inline ? d->packed_normals : d->packed_snorm;
        normals->insert(normals->end(), n.begin(), n.end());
    }
    if (decoded_normals && !normals_inline) meshopt_decodeFilterOct(normals->data(), count, kMeshoptNormalStride);
    return true;
}

bool morphRecords(const std::vector<const PrimitiveData*>& shown, const std::vector<unsigned char>& records,
                  const std::vector<unsigned char>& normals, size_t count, std::vector<unsigned char>* rec,
                  std::vector<size_t>* first, int lo[3], int hi[3]) {
    for (const PrimitiveData* d : shown)
        if (d->packed.size() != d->packed_snorm.size() * 3) return false;
    if (records.size() != count * 12 || normals.size() != count * 4) return false;
    rec->assign(count * kMorphStride, 0);
    first->clear();
    for (int c = 0; c < 3; ++c) {
        lo[c] = INT32_MAX;
        hi[c] = INT32_MIN;
    }
    size_t v = 0;
    for (const PrimitiveData* d : shown) {
        first->push_back(v);
        for (size_t i = 0; i < d->packed.size() / 12; ++i, ++v) {
            if (v >= count) return false;
            int16_t now[4], before[4], dq[4] = {0, 0, 0, 0};
            std::memcpy(now, &d->packed[12 * i], 8);
            std::memcpy(before, &records[12 * v], 8);
            int8_t dn[4] = {0, 0, 0, 0};
            for (int c = 0; c < 3; ++c) {
                const int dd = int(now[c]) - int(before[c]);
                if (dd < -32767 || dd > 32767) return false;
                dq[c] = int16_t(dd);
                lo[c] = std::min(lo[c], dd);
                hi[c] = std::max(hi[c], dd);
                const int dnc = int(int8_t(d->packed_snorm[4 * i + size_t(c)])) - int(int8_t(normals[4 * v + size_t(c)]));
                if (dnc < -127 || dnc > 127) return false;
                dn[c] = int8_t(dnc);
            }
            float t_now, t_before;
            std::memcpy(&t_now, &d->packed[12 * i + 8], 4);
            std::memcpy(&t_before, &records[12 * v + 8], 4);
            const double dt = double(t_now) - double(t_before);
            const float dt32 = float(dt);
            if (double(dt32) != dt) return false;
            unsigned char* r = &(*rec)[kMorphStride * v];
            std::memcpy(r, dq, 8);
            std::memcpy(r + 8, &dt32, 4);
            std::memcpy(r + 12, dn, 4);
        }
    }
    return v == count;
}

std::vector<unsigned char> encodeMorphRecords(const std::vector<unsigned char>& rec, size_t count) {
    std::vector<unsigned char> encoded(meshopt_encodeVertexBufferBound(count, kMorphStride));
    encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), rec.data(), count, kMorphStride));
    return encoded;
}

}  // namespace apparent::glb
