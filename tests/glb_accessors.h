// Reading a plain .glb's accessors back in the tests (tinygltf's model, no decoding of codecs).
#pragma once

#include <cstring>
#include <vector>

#include <tiny_gltf.h>

namespace testglb {

// Float values of a plain accessor (tightly packed), `comps` per element.
inline std::vector<float> floats(const tinygltf::Model& model, int accessor, int comps) {
    const tinygltf::Accessor& a = model.accessors[size_t(accessor)];
    const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
    std::vector<float> out(a.count * size_t(comps));
    std::memcpy(out.data(), model.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset, out.size() * 4);
    return out;
}

}  // namespace testglb
