#include "exporters/ply.h"

#include <cstdint>
#include <cstring>
#include <utility>

#include "exporters/atomic_file.h"
#include "exporters/frame_files.h"

namespace apparent {

namespace {

// Little-endian bytes of a value, whatever the host's byte order.
template <class T>
void putLittleEndian(std::string* out, T value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    if (first == 1) {
        out->append(reinterpret_cast<const char*>(bytes), sizeof(T));
    } else {
        for (size_t i = sizeof(T); i-- > 0;) out->push_back(char(bytes[i]));
    }
}

}  // namespace

bool writePly(const std::string& path, const ExportFrame& frame, std::string* error) {
    const mesh4d::ApparentMesh m = mergeObjects(frame);
    std::vector<const std::array<uint32_t, 3>*> faces;  // without a repeated corner (zero area by construction)
    faces.reserve(m.triangles.size());
    for (const auto& t : m.triangles)
        if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) faces.push_back(&t);
    // Step: the header, then every vertex (x y z quality) and face, serialized in memory.
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(m.positions.size()) +
                        "\nproperty double x\nproperty double y\nproperty double z\nproperty double quality\n"
                        "element face " + std::to_string(faces.size()) +
                        "\nproperty list uchar int vertex_indices\nend_header\n";
    bytes.reserve(bytes.size() + 32 * m.positions.size() + 13 * faces.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        for (int c = 0; c < 3; ++c) putLittleEndian(&bytes, m.positions[i][c]);
        putLittleEndian(&bytes, m.emission_times[i]);
    }
    for (const auto* t : faces) {
        bytes.push_back(char(3));
        for (uint32_t v : *t) putLittleEndian(&bytes, int32_t(v));
    }
    // Step: written with every write, fsync and close checked, then renamed into place.
    AtomicOutput out(path);
    return out.commitBytes(bytes, error);
}

std::unique_ptr<FrameSink> plySink(std::string dir) {
    return std::make_unique<FrameFileSink>(std::move(dir), "ply", writePly);
}

}  // namespace apparent
