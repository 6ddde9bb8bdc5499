// libextern_draco.so, the Draco decoder Blender's glTF importer loads (decoder half only), built from
// Debian's libdraco for Blender builds that ship the importer without it, such as Debian 12's blender 3.4.
// scripts/blender_import.py points the importer at it (BLENDER_EXTERN_DRACO_LIBRARY_PATH, set inside
// Blender's Python before the import); docs/VIEWERS.md "Blender".
//
// The C interface is the one io_scene_gltf2/blender/imp/gltf2_io_draco_compression_extension.py (Blender
// 3.4) loads with ctypes, per primitive: decoderCreate; decoderDecode(bytes, length), false on a bad
// buffer; decoderGetVertexCount and decoderGetIndexCount, compared with the accessors' counts (the
// importer takes ours when they differ); decoderReadIndices(glTF component type of the indices
// accessor); per attribute decoderReadAttribute(Draco unique id from the extension's "attributes",
// glTF component type, accessor type such as "VEC3"), then the byte lengths and copies (the importer
// allocates the length we report, so a copy writes exactly that many bytes); decoderRelease (skipped
// by the importer after an error: the decoder then leaks, as with Blender's own library).
// The layout it expects: tightly packed, one element per Draco point, indices three per face. Values
// are converted by Draco's ConvertValue with the accessor's component count (Blender's own library
// uses the attribute's count, which overruns the buffer when the two differ); normalized integer
// attributes read as float are scaled to [0, 1] or [-1, 1] by Draco. No C++ exception leaves a
// function (ctypes would abort Blender): an allocation failure reads as a failed call.
// Nothing here knows about apparent: the decoding is Google's libdraco, as in Blender's own build.
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

struct Decoder {
    std::unique_ptr<draco::Mesh> mesh;
    std::vector<uint8_t> indices;
    std::map<uint32_t, std::vector<uint8_t>> attributes;  // by Draco unique id
};

// glTF component types (glTF 2.0 section 3.6.2.2).
constexpr size_t kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125,
                 kFloat = 5126;

int componentsOf(const char* type) {
    const std::string t = type ? type : "";
    if (t == "SCALAR") return 1;
    if (t == "VEC2") return 2;
    if (t == "VEC3") return 3;
    if (t == "VEC4" || t == "MAT2") return 4;
    if (t == "MAT3") return 9;
    if (t == "MAT4") return 16;
    return 0;
}

template <typename T>
bool readAttribute(const draco::PointAttribute& a, const draco::Mesh& m, int n, std::vector<uint8_t>& out) {
    out.assign(size_t(m.num_points()) * size_t(n) * sizeof(T), 0);
    T* dst = reinterpret_cast<T*>(out.data());
    for (draco::PointIndex p(0); p < m.num_points(); ++p) {
        if (!a.ConvertValue<T>(a.mapped_index(p), int8_t(n), dst + size_t(p.value()) * size_t(n))) return false;
    }
    return true;
}

template <typename T>
void readIndices(const draco::Mesh& m, std::vector<uint8_t>& out) {
    out.assign(size_t(m.num_faces()) * 3 * sizeof(T), 0);
    T* dst = reinterpret_cast<T*>(out.data());
    for (draco::FaceIndex f(0); f < m.num_faces(); ++f) {
        const auto& face = m.face(f);
        for (int c = 0; c < 3; ++c) dst[size_t(f.value()) * 3 + c] = T(face[c].value());
    }
}

}  // namespace

extern "C" {

void* decoderCreate() { return new (std::nothrow) Decoder; }

void decoderRelease(void* d) { delete static_cast<Decoder*>(d); }

bool decoderDecode(void* d, const void* data, size_t size) {
    auto* dec = static_cast<Decoder*>(d);
    if (!dec) return false;
    dec->mesh.reset();
    try {
        draco::DecoderBuffer buf;
        buf.Init(static_cast<const char*>(data), size);
        draco::Decoder decoder;
        auto res = decoder.DecodeMeshFromBuffer(&buf);
        if (!res.ok()) return false;
        dec->mesh = std::move(res).value();
    } catch (const std::exception&) {
        dec->mesh.reset();
    }
    return dec->mesh != nullptr;
}

uint32_t decoderGetVertexCount(void* d) {
    auto* dec = static_cast<Decoder*>(d);
    return dec && dec->mesh ? dec->mesh->num_points() : 0;
}

uint32_t decoderGetIndexCount(void* d) {
    auto* dec = static_cast<Decoder*>(d);
    return dec && dec->mesh ? dec->mesh->num_faces() * 3 : 0;
}

bool decoderAttributeIsNormalized(void* d, uint32_t id) {
    auto* dec = static_cast<Decoder*>(d);
    const draco::PointAttribute* a = dec && dec->mesh ? dec->mesh->GetAttributeByUniqueId(id) : nullptr;
    return a && a->normalized();
}

bool decoderReadAttribute(void* d, uint32_t id, size_t component_type, const char* data_type) {
    auto* dec = static_cast<Decoder*>(d);
    if (!dec || !dec->mesh) return false;
    const draco::PointAttribute* a = dec->mesh->GetAttributeByUniqueId(id);
    const int n = componentsOf(data_type);
    if (!a || n == 0) return false;
    try {
        std::vector<uint8_t>& out = dec->attributes[id];
        switch (component_type) {
            case kByte: return readAttribute<int8_t>(*a, *dec->mesh, n, out);
            case kUnsignedByte: return readAttribute<uint8_t>(*a, *dec->mesh, n, out);
            case kShort: return readAttribute<int16_t>(*a, *dec->mesh, n, out);
            case kUnsignedShort: return readAttribute<uint16_t>(*a, *dec->mesh, n, out);
            case kUnsignedInt: return readAttribute<uint32_t>(*a, *dec->mesh, n, out);
            case kFloat: return readAttribute<float>(*a, *dec->mesh, n, out);
            default: return false;
        }
    } catch (const std::exception&) {
        dec->attributes.erase(id);
        return false;
    }
}

size_t decoderGetAttributeByteLength(void* d, uint32_t id) {
    auto* dec = static_cast<Decoder*>(d);
    if (!dec) return 0;
    auto it = dec->attributes.find(id);
    return it == dec->attributes.end() ? 0 : it->second.size();
}

void decoderCopyAttribute(void* d, uint32_t id, void* out) {
    auto* dec = static_cast<Decoder*>(d);
    if (!dec) return;
    auto it = dec->attributes.find(id);
    if (it != dec->attributes.end() && !it->second.empty()) std::memcpy(out, it->second.data(), it->second.size());
}

// Indices are unsigned in glTF (accessor.componentType 5121, 5123 or 5125); anything else fails.
bool decoderReadIndices(void* d, size_t component_type) {
    auto* dec = static_cast<Decoder*>(d);
    if (!dec || !dec->mesh) return false;
    try {
        switch (component_type) {
            case kUnsignedByte: readIndices<uint8_t>(*dec->mesh, dec->indices); return true;
            case kUnsignedShort: readIndices<uint16_t>(*dec->mesh, dec->indices); return true;
            case kUnsignedInt: readIndices<uint32_t>(*dec->mesh, dec->indices); return true;
            default: return false;
        }
    } catch (const std::exception&) {
        dec->indices.clear();
        return false;
    }
}

size_t decoderGetIndicesByteLength(void* d) {
    auto* dec = static_cast<Decoder*>(d);
    return dec ? dec->indices.size() : 0;
}

void decoderCopyIndices(void* d, void* out) {
    auto* dec = static_cast<Decoder*>(d);
    if (dec && !dec->indices.empty()) std::memcpy(out, dec->indices.data(), dec->indices.size());
}

}  // extern "C"
