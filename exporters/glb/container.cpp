// The glTF records of views, accessors and primitives, their bytes sent to the BIN chunk
// (GlbBuilder, glb.h).
#include <algorithm>
#include <cmath>

#include <tiny_gltf.h>

#include "exporters/glb/glb.h"

namespace apparent::glb {

namespace {

constexpr int kArray = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElements = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;

}  // namespace

template <class Write>
int GlbBuilder::newView(size_t n, int target, const Write& write) {
    if (sink_->size % 4) sink_->pad(4 - sink_->size % 4);
    gltfjson::BufferView& v = views.emplace_back();
    v.buffer = 0;
    v.offset = sink_->size;
    v.length = n;
    v.target = target;
    write();
    return int(views.size()) - 1;
}

int GlbBuilder::addView(const void* data, size_t n, int target) {
    return newView(n, target, [&] { sink_->write(data, n); });
}

int GlbBuilder::addView(const FileSpan& span, int target) {
    return newView(size_t(span.length), target, [&] { sink_->reference(span); });
}

template <class V>
int GlbBuilder::addView(const PrimitiveData& d, const V& local, const FileSpan& span, int target) {
    return d.remote.on ? addView(span, target) : addView(local.data(), local.size() * sizeof(local[0]), target);
}

int GlbBuilder::addAccessor(int view, int component, bool vec3, size_t count, size_t offset, const double* lo,
                            const double* hi, int n) {
    gltfjson::Accessor& a = accessors.emplace_back();
    a.view = view;
    a.component = component;
    a.vec3 = vec3;
    a.count = count;
    a.offset = offset;
    if (lo) {
        a.bounds = uint8_t(n);
        std::copy(lo, lo + n, a.min);
        std::copy(hi, hi + n, a.max);
    }
    return int(accessors.size()) - 1;
}

int GlbBuilder::addNormalized(int view, int component, bool vec3, size_t count, size_t offset) {
    const int a = addAccessor(view, component, vec3, count, offset);
    accessors.back().normalized = true;
    return a;
}

gltfjson::Primitive GlbBuilder::plainPrimitive(const PrimitiveData& d, int shared_indices, std::vector<int>* part_indices) {
    gltfjson::Primitive prim;
    double lo[3], hi[3];
    if (d.remote.on) {
        std::copy(d.remote.lo, d.remote.lo + 3, lo);
        std::copy(d.remote.hi, d.remote.hi + 3, hi);
    } else if (d.bounded) {
        std::copy(d.lo, d.lo + 3, lo);
        std::copy(d.hi, d.hi + 3, hi);
    } else {
        bounds(d.positions, lo, hi);
    }
    const PrimitiveData::Remote& r = d.remote;
    const size_t nv = d.vertexCount();
    auto& at = prim.attributes;
    at[gltfjson::kPosition] = addAccessor(addView(d, d.positions, r.positions, kArray), kFloat, true, nv, 0, lo, hi, 3);
    at[gltfjson::kNormal] = addAccessor(addView(d, d.normals, r.normals, kArray), kFloat, true, nv);
    at[gltfjson::kEmissionTime] = addAccessor(addView(d, d.emission, r.emission, kArray), kFloat, false, nv);
    if (d.has(d.doppler, r.doppler))
        at[gltfjson::kDoppler] = addAccessor(addView(d, d.doppler, r.doppler, kArray), kFloat, false, nv);
    if (d.has(d.proper_time, r.proper_time))
        at[gltfjson::kProperTime] = addAccessor(addView(d, d.proper_time, r.proper_time, kArray), kFloat, false, nv);
    if (d.has(d.colors, r.colors))
        at[gltfjson::kColor0] = addAccessor(addView(d, d.colors, r.colors, kArray), kFloat, true, nv);
    if (d.has(d.texcoords, r.texcoords)) {
        at[gltfjson::kTexcoord0] = addAccessor(addView(d, d.texcoords, r.texcoords, kArray), kFloat, false, nv);
        accessors.back().vec2 = true;
    }
    if (d.has(d.texcoords1, r.texcoords1)) {
        at[gltfjson::kTexcoord1] = addAccessor(addView(d, d.texcoords1, r.texcoords1, kArray), kFloat, false, nv);
        accessors.back().vec2 = true;
    }
    if (!d.part_first.empty() && part_indices) {
        // One index view, one accessor per material's part.
        const int view = addView(d, d.indices, r.indices, kElements);
        part_indices->clear();
        for (size_t p = 0; p + 1 < d.part_first.size(); ++p)
            part_indices->push_back(addAccessor(view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false,
                                                3 * size_t(d.part_first[p + 1] - d.part_first[p]),
                                                12 * size_t(d.part_first[p])));
        prim.indices = part_indices->front();
        return prim;
    }
    prim.indices = shared_indices >= 0 ? shared_indices
                                       : addAccessor(addView(d, d.indices, r.indices, kElements),
                                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false, d.indexCount());
    return prim;
}

gltfjson::Primitive GlbBuilder::meshoptPrimitive(const PrimitiveData& d, const MeshoptLayout& layout, size_t stride,
                                                 int vview, int nview, size_t first_vertex, int indices) {
    gltfjson::Primitive prim;
    const size_t nv = d.packedVertices(layout.stride);
    const size_t at0 = first_vertex * stride;
    auto& at = prim.attributes;
    const double lo[3] = {double(d.qmin[0]), double(d.qmin[1]), double(d.qmin[2])};
    const double hi[3] = {double(d.qmax[0]), double(d.qmax[1]), double(d.qmax[2])};
    at[gltfjson::kPosition] = addAccessor(vview, TINYGLTF_COMPONENT_TYPE_SHORT, true, nv, at0, lo, hi, 3);
    at[gltfjson::kNormal] =
        nview >= 0 ? addNormalized(nview, TINYGLTF_COMPONENT_TYPE_BYTE, true, nv, first_vertex * kMeshoptNormalStride)
                   : addNormalized(vview, TINYGLTF_COMPONENT_TYPE_BYTE, true, nv, at0 + layout.stride);
    at[gltfjson::kEmissionTime] = addAccessor(vview, kFloat, false, nv, at0 + 8);
    if (layout.doppler >= 0 && d.has(d.doppler, d.remote.doppler))
        at[gltfjson::kDoppler] = addAccessor(vview, kFloat, false, nv, at0 + size_t(layout.doppler));
    if (layout.proper_time >= 0 && d.has(d.proper_time, d.remote.proper_time))
        at[gltfjson::kProperTime] = addAccessor(vview, kFloat, false, nv, at0 + size_t(layout.proper_time));
    if (layout.color >= 0 && d.has(d.colors, d.remote.colors))
        at[gltfjson::kColor0] =
            addNormalized(vview, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true, nv, at0 + size_t(layout.color));
    if (layout.texcoord >= 0 && d.has(d.texcoords, d.remote.texcoords)) {
        at[gltfjson::kTexcoord0] = addAccessor(vview, kFloat, false, nv, at0 + size_t(layout.texcoord));
        accessors.back().vec2 = true;
    }
    if (layout.texcoord1 >= 0 && d.has(d.texcoords1, d.remote.texcoords1)) {
        at[gltfjson::kTexcoord1] = addAccessor(vview, kFloat, false, nv, at0 + size_t(layout.texcoord1));
        accessors.back().vec2 = true;
    }
    prim.indices = indices;
    return prim;
}

int GlbBuilder::addMeshoptView(const std::vector<unsigned char>& encoded, size_t count, size_t stride, bool indices,
                               bool octahedral) {
    return newMeshoptView(encoded.size(), count, stride, indices, octahedral,
                          [&] { sink_->write(encoded.data(), encoded.size()); });
}

int GlbBuilder::addMeshoptView(const FileSpan& encoded, size_t count, size_t stride, bool indices, bool octahedral) {
    return newMeshoptView(size_t(encoded.length), count, stride, indices, octahedral,
                          [&] { sink_->reference(encoded); });
}

template <class Write>
int GlbBuilder::newMeshoptView(size_t length, size_t count, size_t stride, bool indices, bool octahedral,
                               const Write& write) {
    if (sink_->size % 4) sink_->pad(4 - sink_->size % 4);
    gltfjson::BufferView& v = views.emplace_back();
    v.meshopt = true;
    v.ext = {sink_->size, length, stride, count, indices, octahedral};
    write();
    v.buffer = 1;
    v.offset = fallback_size;
    v.length = count * stride;
    v.stride = indices ? 0 : stride;
    v.target = indices ? kElements : kArray;
    fallback_size += (v.length + 3) / 4 * 4;
    return int(views.size()) - 1;
}

bool GlbBuilder::dracoPrimitive(const PrimitiveData& d, gltfjson::Primitive* prim, double* quantization_error,
                                std::string* error, int part) {
    const DracoCoded& c = d.draco;
    if (!c.error.empty()) {
        *error = c.error;
        return false;
    }
    *quantization_error = c.quantization_error;
    // The mesh's counts, bounds and bytes: the whole coding's, or the part's.
    const DracoCoded::Part* p = part >= 0 ? &c.parts[size_t(part)] : nullptr;
    const size_t n_points = size_t(p ? p->points : c.points);
    auto& at = prim->attributes;
    at[gltfjson::kPosition] = addAccessor(-1, kFloat, true, n_points, 0, p ? p->lo : c.lo, p ? p->hi : c.hi, 3);
    at[gltfjson::kNormal] = addAccessor(-1, kFloat, true, n_points);
    at[gltfjson::kEmissionTime] = addAccessor(-1, kFloat, false, n_points);
    if (c.ids[3] >= 0) at[gltfjson::kDoppler] = addAccessor(-1, kFloat, false, n_points);
    if (c.ids[4] >= 0) at[gltfjson::kProperTime] = addAccessor(-1, kFloat, false, n_points);
    if (c.ids[5] >= 0) at[gltfjson::kColor0] = addAccessor(-1, kFloat, true, n_points);
    if (c.ids[6] >= 0) {
        at[gltfjson::kTexcoord0] = addAccessor(-1, kFloat, false, n_points);
        accessors.back().vec2 = true;
    }
    if (c.ids[7] >= 0) {
        at[gltfjson::kTexcoord1] = addAccessor(-1, kFloat, false, n_points);
        accessors.back().vec2 = true;
    }
    prim->indices = addAccessor(-1, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false, size_t(p ? p->faces : c.faces) * 3);
    if (p) {
        const FileSpan& r = d.remote.draco;
        prim->draco_view = d.remote.on ? addView(FileSpan{r.source, r.offset + p->offset, p->length}, 0)
                                       : addView(c.bytes.data() + p->offset, size_t(p->length), 0);
    } else {
        prim->draco_view = d.remote.on ? addView(d.remote.draco, 0) : addView(c.bytes.data(), c.bytes.size(), 0);
    }
    // The Draco ids in DracoCoded's order: POSITION, NORMAL, _EMISSION_TIME, _DOPPLER, _PROPER_TIME,
    // COLOR_0, TEXCOORD_0, TEXCOORD_1.
    static constexpr int kOrder[DracoCoded::kIds] = {gltfjson::kPosition,   gltfjson::kNormal,    gltfjson::kEmissionTime,
                                                     gltfjson::kDoppler,    gltfjson::kProperTime, gltfjson::kColor0,
                                                     gltfjson::kTexcoord0, gltfjson::kTexcoord1};
    for (int i = 0; i < DracoCoded::kIds; ++i) prim->draco_ids[size_t(kOrder[i])] = c.ids[i];
    return true;
}

void GlbBuilder::bounds(const std::vector<float>& xyz, double* lo, double* hi) {
    double l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 3 <= xyz.size(); i += 3)
        for (int c = 0; c < 3; ++c) {
            l[c] = std::min(l[c], double(xyz[i + size_t(c)]));
            h[c] = std::max(h[c], double(xyz[i + size_t(c)]));
        }
    std::copy(l, l + 3, lo);
    std::copy(h, h + 3, hi);
}

}  // namespace apparent::glb
