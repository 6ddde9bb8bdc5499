// One primitive's KHR_draco_mesh_compression coding (encodeDraco, glb.h).
#include <algorithm>
#include <cmath>
#include <memory>

#include <draco/compression/decode.h>
#include <draco/compression/expert_encode.h>
#include <draco/mesh/mesh.h>

#include "exporters/glb/glb.h"

namespace apparent::glb {

void encodeDraco(const PrimitiveData& d, const GlbOptions& options, DracoCoded* out) {
    *out = DracoCoded();
    // Step: build the Draco mesh with identity point mapping.
    draco::Mesh dm;
    const size_t nv = d.vertexCount();
    dm.set_num_points(uint32_t(nv));
    auto addAttribute = [&](draco::GeometryAttribute::Type type, int components, const float* values) {
        draco::GeometryAttribute ga;
        ga.Init(type, nullptr, components, draco::DT_FLOAT32, false, 4 * components, 0);
        const int id = dm.AddAttribute(ga, /*identity_mapping=*/true, uint32_t(nv));
        for (size_t i = 0; i < nv; ++i)
            dm.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), values + components * i);
        return id;
    };
    const int pos = addAttribute(draco::GeometryAttribute::POSITION, 3, d.positions.data());
    const int nrm = addAttribute(draco::GeometryAttribute::NORMAL, 3, d.normals.data());
    const int emt = addAttribute(draco::GeometryAttribute::GENERIC, 1, d.emission.data());
    const int dop = d.doppler.empty() ? -1 : addAttribute(draco::GeometryAttribute::GENERIC, 1, d.doppler.data());
    const int tau = d.proper_time.empty() ? -1 : addAttribute(draco::GeometryAttribute::GENERIC, 1, d.proper_time.data());
    const int col = d.colors.empty() ? -1 : addAttribute(draco::GeometryAttribute::COLOR, 3, d.colors.data());
    for (size_t f = 0; f < d.indices.size(); f += 3)
        dm.AddFace({draco::PointIndex(d.indices[f]), draco::PointIndex(d.indices[f + 1]),
                    draco::PointIndex(d.indices[f + 2])});

    // Step: encode; the emission time stays unquantized (lossless).
    draco::ExpertEncoder enc(dm);
    enc.SetAttributeQuantization(pos, options.position_bits);
    enc.SetAttributeQuantization(nrm, options.normal_bits);
    enc.SetSpeedOptions(5, 5);
    enc.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer buf;
    const draco::Status st = enc.EncodeToBuffer(&buf);
    if (!st.ok()) {
        out->error = "Draco encoding failed: " + st.error_msg_string();
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < d.positions.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], double(d.positions[i]));
        hi[i % 3] = std::max(hi[i % 3], double(d.positions[i]));
    }
    double extent = 0;
    for (int c = 0; c < 3; ++c) extent = std::max(extent, hi[c] - lo[c]);
    out->quantization_error = 0.5 * extent / double((1u << options.position_bits) - 1);

    // Step: decode it again; the accessors must describe what a reader will get.
    draco::DecoderBuffer db;
    db.Init(buf.data(), buf.size());
    draco::Decoder dec;
    auto decoded = dec.DecodeMeshFromBuffer(&db);
    if (!decoded.ok()) {
        out->error = "Draco could not decode its own output: " + decoded.status().error_msg_string();
        return;
    }
    const std::unique_ptr<draco::Mesh> back = std::move(decoded).value();
    const draco::PointAttribute* bpos = back->GetAttributeByUniqueId(dm.attribute(pos)->unique_id());
    for (int c = 0; c < 3; ++c) {
        out->lo[c] = INFINITY;
        out->hi[c] = -INFINITY;
    }
    for (draco::PointIndex p(0); p < back->num_points(); ++p) {
        float v[3];
        bpos->GetMappedValue(p, v);
        for (int c = 0; c < 3; ++c) { out->lo[c] = std::min(out->lo[c], double(v[c])); out->hi[c] = std::max(out->hi[c], double(v[c])); }
    }
    out->points = back->num_points();
    out->faces = back->num_faces();
    const int ids[6] = {pos, nrm, emt, dop, tau, col};
    for (int a = 0; a < 6; ++a) out->ids[a] = ids[a] >= 0 ? int32_t(dm.attribute(ids[a])->unique_id()) : -1;
    out->bytes.assign(buf.data(), buf.data() + buf.size());
}

}  // namespace apparent::glb
