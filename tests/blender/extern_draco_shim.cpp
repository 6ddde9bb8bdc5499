// Stand-in for Blender's libextern_draco.so (decoder half only), for Blender builds that ship the glTF importer
// without it, such as Debian's blender 3.4. Built by tests/blender/run.sh --draco-shim against Debian's libdraco,
// then handed to the importer through BLENDER_EXTERN_DRACO_LIBRARY_PATH.
//
// Written from the C interface that io_scene_gltf2/blender/imp/gltf2_io_draco_compression_extension.py loads with
// ctypes: decoderCreate/Release, decoderDecode(buffer), decoderGetVertexCount/GetIndexCount,
// decoderReadIndices(glTF component type), decoderReadAttribute(Draco unique id, glTF component type, accessor
// type such as "VEC3"), then the byte lengths and copies of what was read. Nothing here knows about apparent:
// the decoding is Google's libdraco, as in Blender's own build.
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Decoder {
  std::unique_ptr<draco::Mesh> mesh;
  std::vector<uint8_t> indices;
  std::map<uint32_t, std::vector<uint8_t>> attributes;  // by Draco unique id
};

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
  out.assign(size_t(m.num_points()) * n * sizeof(T), 0);
  T* dst = reinterpret_cast<T*>(out.data());
  for (draco::PointIndex p(0); p < m.num_points(); ++p) {
    if (!a.ConvertValue<T>(a.mapped_index(p), int8_t(n), dst + size_t(p.value()) * n)) return false;
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

void* decoderCreate() { return new Decoder; }

void decoderRelease(void* d) { delete static_cast<Decoder*>(d); }

bool decoderDecode(void* d, const void* data, size_t size) {
  auto* dec = static_cast<Decoder*>(d);
  draco::DecoderBuffer buf;
  buf.Init(static_cast<const char*>(data), size);
  draco::Decoder decoder;
  auto res = decoder.DecodeMeshFromBuffer(&buf);
  if (!res.ok()) return false;
  dec->mesh = std::move(res).value();
  return dec->mesh != nullptr;
}

uint32_t decoderGetVertexCount(void* d) {
  auto* dec = static_cast<Decoder*>(d);
  return dec->mesh ? dec->mesh->num_points() : 0;
}

uint32_t decoderGetIndexCount(void* d) {
  auto* dec = static_cast<Decoder*>(d);
  return dec->mesh ? dec->mesh->num_faces() * 3 : 0;
}

bool decoderAttributeIsNormalized(void* d, uint32_t id) {
  auto* dec = static_cast<Decoder*>(d);
  const draco::PointAttribute* a = dec->mesh ? dec->mesh->GetAttributeByUniqueId(id) : nullptr;
  return a && a->normalized();
}

bool decoderReadAttribute(void* d, uint32_t id, size_t componentType, const char* dataType) {
  auto* dec = static_cast<Decoder*>(d);
  if (!dec->mesh) return false;
  const draco::PointAttribute* a = dec->mesh->GetAttributeByUniqueId(id);
  const int n = componentsOf(dataType);
  if (!a || n == 0) return false;
  std::vector<uint8_t>& out = dec->attributes[id];
  switch (componentType) {
    case 5120: return readAttribute<int8_t>(*a, *dec->mesh, n, out);
    case 5121: return readAttribute<uint8_t>(*a, *dec->mesh, n, out);
    case 5122: return readAttribute<int16_t>(*a, *dec->mesh, n, out);
    case 5123: return readAttribute<uint16_t>(*a, *dec->mesh, n, out);
    case 5125: return readAttribute<uint32_t>(*a, *dec->mesh, n, out);
    case 5126: return readAttribute<float>(*a, *dec->mesh, n, out);
    default: return false;
  }
}

size_t decoderGetAttributeByteLength(void* d, uint32_t id) {
  auto* dec = static_cast<Decoder*>(d);
  auto it = dec->attributes.find(id);
  return it == dec->attributes.end() ? 0 : it->second.size();
}

void decoderCopyAttribute(void* d, uint32_t id, void* out) {
  auto* dec = static_cast<Decoder*>(d);
  auto it = dec->attributes.find(id);
  if (it != dec->attributes.end()) std::memcpy(out, it->second.data(), it->second.size());
}

bool decoderReadIndices(void* d, size_t componentType) {
  auto* dec = static_cast<Decoder*>(d);
  if (!dec->mesh) return false;
  switch (componentType) {
    case 5121: readIndices<uint8_t>(*dec->mesh, dec->indices); return true;
    case 5123: readIndices<uint16_t>(*dec->mesh, dec->indices); return true;
    case 5125: readIndices<uint32_t>(*dec->mesh, dec->indices); return true;
    default: return false;
  }
}

size_t decoderGetIndicesByteLength(void* d) { return static_cast<Decoder*>(d)->indices.size(); }

void decoderCopyIndices(void* d, void* out) {
  auto* dec = static_cast<Decoder*>(d);
  std::memcpy(out, dec->indices.data(), dec->indices.size());
}

}  // extern "C"
