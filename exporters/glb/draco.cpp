// One primitive's KHR_draco_mesh_compression coding (encodeDraco, glb.h).
#include <algorithm>
#include <cmath>
#include <memory>

#include <draco/compression/decode.h>
#include <draco/compression/expert_encode.h>
#include <draco/mesh/mesh.h>

#include "exporters/glb/glb.h"

namespace apparent::glb {

namespace {

// Half a step of a grid spanning `range` in 2^bits - 1 steps (Draco's quantizer).
double halfStep(double range, int bits) { return 0.5 * range / double((1u << bits) - 1); }

// What one Draco mesh's coding gives: its bytes appended to `bytes`, its counts, position bounds and error bounds.
struct MeshCoded {
    uint64_t points = 0, faces = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double quantization_error = 0, texcoord_error = 0;
    int32_t ids[DracoCoded::kIds] = {-1, -1, -1, -1, -1, -1, -1, -1};
};

// Codes the vertices `vertices` of `d` (each once, in this order; all of them when `vertices` is
// null) with the `count` triangles at `tri` (in `d`'s numbering; `local` maps them to the mesh's).
bool encodeMesh(const PrimitiveData& d, const std::vector<uint32_t>* vertices, const uint32_t* tri, size_t count,
                const std::vector<uint32_t>* local, const GlbOptions& options, std::vector<char>* bytes,
                MeshCoded* out, std::string* error) {
    // Step: build the Draco mesh with identity point mapping.
    draco::Mesh dm;
    const size_t nv = vertices ? vertices->size() : d.vertexCount();
    auto vertex = [&](size_t i) { return vertices ? size_t((*vertices)[i]) : i; };
    dm.set_num_points(uint32_t(nv));
    auto addAttribute = [&](draco::GeometryAttribute::Type type, int components, const float* values) {
        draco::GeometryAttribute ga;
        ga.Init(type, nullptr, components, draco::DT_FLOAT32, false, 4 * components, 0);
        const int id = dm.AddAttribute(ga, /*identity_mapping=*/true, uint32_t(nv));
        for (size_t i = 0; i < nv; ++i)
            dm.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)),
                                                values + components * vertex(i));
        return id;
    };
    const int pos = addAttribute(draco::GeometryAttribute::POSITION, 3, d.positions.data());
    const int nrm = addAttribute(draco::GeometryAttribute::NORMAL, 3, d.normals.data());
    const int emt = addAttribute(draco::GeometryAttribute::GENERIC, 1, d.emission.data());
    const int dop = d.doppler.empty() ? -1 : addAttribute(draco::GeometryAttribute::GENERIC, 1, d.doppler.data());
    const int tau = d.proper_time.empty() ? -1 : addAttribute(draco::GeometryAttribute::GENERIC, 1, d.proper_time.data());
    const int col = d.colors.empty() ? -1 : addAttribute(draco::GeometryAttribute::COLOR, 3, d.colors.data());
    const int tex = d.texcoords.empty() ? -1 : addAttribute(draco::GeometryAttribute::TEX_COORD, 2, d.texcoords.data());
    const int tex1 = d.texcoords1.empty() ? -1 : addAttribute(draco::GeometryAttribute::TEX_COORD, 2, d.texcoords1.data());
    auto at = [&](uint32_t i) { return draco::PointIndex(local ? (*local)[i] : i); };
    for (size_t f = 0; f < 3 * count; f += 3) dm.AddFace({at(tri[f]), at(tri[f + 1]), at(tri[f + 2])});

    // Step: encode; the emission time and the colours stay unquantized (lossless).
    draco::ExpertEncoder enc(dm);
    enc.SetAttributeQuantization(pos, options.position_bits);
    enc.SetAttributeQuantization(nrm, options.normal_bits);
    if (tex >= 0) enc.SetAttributeQuantization(tex, options.texcoord_bits);
    if (tex1 >= 0) enc.SetAttributeQuantization(tex1, options.texcoord_bits);
    enc.SetSpeedOptions(5, 5);
    enc.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer buf;
    const draco::Status st = enc.EncodeToBuffer(&buf);
    if (!st.ok()) {
        *error = "Draco encoding failed: " + st.error_msg_string();
        return false;
    }
    // Step: the error bounds over the grids Draco spans (the largest range of the attribute's components).
    auto largestRange = [&](const std::vector<float>& values, size_t n) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < nv; ++i)
            for (size_t c = 0; c < n; ++c) {
                lo[c] = std::min(lo[c], double(values[n * vertex(i) + c]));
                hi[c] = std::max(hi[c], double(values[n * vertex(i) + c]));
            }
        double range = 0;
        for (size_t c = 0; c < n; ++c) range = std::max(range, hi[c] - lo[c]);
        return range;
    };
    out->quantization_error = halfStep(largestRange(d.positions, 3), options.position_bits);
    if (tex >= 0) out->texcoord_error = halfStep(largestRange(d.texcoords, 2), options.texcoord_bits);
    if (tex1 >= 0)
        out->texcoord_error = std::max(out->texcoord_error, halfStep(largestRange(d.texcoords1, 2), options.texcoord_bits));

    // Step: decode it again; the accessors must describe what a reader will get.
    draco::DecoderBuffer db;
    db.Init(buf.data(), buf.size());
    draco::Decoder dec;
    auto decoded = dec.DecodeMeshFromBuffer(&db);
    if (!decoded.ok()) {
        *error = "Draco could not decode its own output: " + decoded.status().error_msg_string();
        return false;
    }
    const std::unique_ptr<draco::Mesh> back = std::move(decoded).value();
    const draco::PointAttribute* bpos = back->GetAttributeByUniqueId(dm.attribute(pos)->unique_id());
    for (draco::PointIndex p(0); p < back->num_points(); ++p) {
        float v[3];
        bpos->GetMappedValue(p, v);
        for (int c = 0; c < 3; ++c) { out->lo[c] = std::min(out->lo[c], double(v[c])); out->hi[c] = std::max(out->hi[c], double(v[c])); }
    }
    out->points = back->num_points();
    out->faces = back->num_faces();
    const int ids[DracoCoded::kIds] = {pos, nrm, emt, dop, tau, col, tex, tex1};
    for (int a = 0; a < DracoCoded::kIds; ++a) out->ids[a] = ids[a] >= 0 ? int32_t(dm.attribute(ids[a])->unique_id()) : -1;
    bytes->insert(bytes->end(), buf.data(), buf.data() + buf.size());
    return true;
}

}  // namespace

void encodeDraco(const PrimitiveData& d, const GlbOptions& options, DracoCoded* out) {
    *out = DracoCoded();
    // Step: one mesh of every vertex and triangle.
    MeshCoded m;
    if (d.part_first.empty()) {
        if (!encodeMesh(d, nullptr, d.indices.data(), d.indices.size() / 3, nullptr, options, &out->bytes, &m,
                        &out->error))
            return;
        out->points = m.points;
        out->faces = m.faces;
        std::copy(m.lo, m.lo + 3, out->lo);
        std::copy(m.hi, m.hi + 3, out->hi);
        std::copy(m.ids, m.ids + DracoCoded::kIds, out->ids);
        out->quantization_error = m.quantization_error;
        out->texcoord_error = m.texcoord_error;
        return;
    }
    // Step: or one mesh per material part, of the vertices its triangles use (in increasing order).
    std::vector<uint32_t> vertices, local(d.vertexCount(), ~0u);
    for (size_t p = 0; p + 1 < d.part_first.size(); ++p) {
        const uint32_t* tri = d.indices.data() + 3 * size_t(d.part_first[p]);
        const size_t count = size_t(d.part_first[p + 1] - d.part_first[p]);
        vertices.assign(tri, tri + 3 * count);
        std::sort(vertices.begin(), vertices.end());
        vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
        for (size_t i = 0; i < vertices.size(); ++i) local[vertices[i]] = uint32_t(i);
        DracoCoded::Part& part = out->parts.emplace_back();
        part.offset = out->bytes.size();
        if (!encodeMesh(d, &vertices, tri, count, &local, options, &out->bytes, &m, &out->error)) return;
        part.length = out->bytes.size() - part.offset;
        part.points = m.points;
        part.faces = m.faces;
        std::copy(m.lo, m.lo + 3, part.lo);
        std::copy(m.hi, m.hi + 3, part.hi);
        std::copy(m.ids, m.ids + DracoCoded::kIds, out->ids);
        out->quantization_error = std::max(out->quantization_error, m.quantization_error);
        out->texcoord_error = std::max(out->texcoord_error, m.texcoord_error);
        out->points += m.points;
        out->faces += m.faces;
        m = MeshCoded();
    }
}

}  // namespace apparent::glb
