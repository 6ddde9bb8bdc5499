#include "exporters/ply.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

#include <unistd.h>


#include "exporters/atomic_file.h"
#include "exporters/frame_files.h"
#include "mesh4d/parallel.h"

namespace apparent {

namespace {

bool littleEndianHost() {
    const uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    return first == 1;
}

// Stores the little-endian bytes of `value` at `dst`, whatever the host's byte order.
template <class T>
char* storeLittleEndian(char* dst, T value, bool little_host) {
    std::memcpy(dst, &value, sizeof(T));
    if (!little_host) std::reverse(dst, dst + sizeof(T));
    return dst + sizeof(T);
}

bool keptFace(const std::array<uint32_t, 3>& t) { return t[0] != t[1] && t[1] != t[2] && t[0] != t[2]; }

constexpr size_t kBlock = size_t(1) << 16;  // triangles or vertices serialized by one task
constexpr size_t kVertexBytes = 32;         // double x y z quality
constexpr size_t kFactorBytes = 16;         // double doppler proper_time (when every object has them)
constexpr size_t kFaceBytes = 13;           // uchar 3, int i j k

// A run of one object's triangles, with the kept faces before it in the whole frame.
struct FaceBlock {
    size_t object = 0, begin = 0, end = 0;
    size_t faces_before = 0;
    uint32_t vertex_base = 0;
};

}  // namespace

void serializePly(const ExportFrame& frame, const SequenceInfo& info, std::string* out) {
    const bool little = littleEndianHost();
    // Step: counts, per block of triangles (faces with a repeated corner are left out: zero area by
    // construction), so that every block knows where its bytes go.
    std::vector<FaceBlock> blocks;
    size_t vertices = 0;
    for (size_t o = 0; o < frame.objects.size(); ++o) {
        const auto& tris = frame.objects[o].triangles;
        for (size_t b = 0; b < tris.size(); b += kBlock)
            blocks.push_back({o, b, std::min(tris.size(), b + kBlock), 0, uint32_t(vertices)});
        vertices += frame.objects[o].positions.size();
    }
    std::vector<size_t> kept(blocks.size(), 0);
    mesh4d::parallelFor(size_t(0), blocks.size(), [&](size_t i) {
        const auto& tris = frame.objects[blocks[i].object].triangles;
        size_t n = 0;
        for (size_t f = blocks[i].begin; f < blocks[i].end; ++f) n += keptFace(tris[f]);
        kept[i] = n;
    });
    size_t faces = 0;
    for (size_t i = 0; i < blocks.size(); ++i) {
        blocks[i].faces_before = faces;
        faces += kept[i];
    }

    // Step: the header (comments, frameFileComments), then every vertex (x y z quality, absolute
    // lab values; doppler and proper_time when the frame loop computed them,
    // mesh4d/light_factors.h; the object's index) and face, each block
    // written in place in parallel: the bytes do not depend on the thread count.
    const bool factors = std::all_of(frame.objects.begin(), frame.objects.end(), [](const mesh4d::ApparentMesh& o) {
        return o.doppler.size() == o.positions.size() && o.proper_time.size() == o.positions.size();
    });
    // The object index's type from the sequence's object count, the same in every frame of it.
    const size_t objects = frameObjectCount(frame, info);
    const size_t object_bytes = objects <= 256 ? 1 : objects <= 65536 ? 2 : 4;
    const char* const object_type = object_bytes == 1 ? "uchar" : object_bytes == 2 ? "ushort" : "int";
    const size_t vertex_bytes = kVertexBytes + (factors ? kFactorBytes : 0) + object_bytes;
    std::string header = "ply\nformat binary_little_endian 1.0\n";
    for (const std::string& line : frameFileComments(frame, info)) header += "comment " + line + "\n";
    header += "element vertex " + std::to_string(vertices) +
              "\nproperty double x\nproperty double y\nproperty double z\nproperty double quality\n" +
              (factors ? "property double doppler\nproperty double proper_time\n" : "") + "property " + object_type +
              " object\nelement face " + std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
    std::string& bytes = *out;
    bytes.resize(header.size() + vertex_bytes * vertices + kFaceBytes * faces);
    std::memcpy(&bytes[0], header.data(), header.size());
    char* const vertex_start = &bytes[0] + header.size();
    char* const face_start = vertex_start + vertex_bytes * vertices;
    size_t base = 0;
    for (size_t o = 0; o < frame.objects.size(); ++o) {
        const mesh4d::ApparentMesh& part = frame.objects[o];
        char* const dst = vertex_start + vertex_bytes * base;
        mesh4d::parallelFor(size_t(0), part.positions.size(), kBlock, [&](size_t first) {
            const size_t last = std::min(part.positions.size(), first + kBlock);
            char* p = dst + vertex_bytes * first;
            for (size_t i = first; i < last; ++i) {
                const mesh4d::Vec3 q = part.absolutePosition(i);
                p = storeLittleEndian(p, q.x, little);
                p = storeLittleEndian(p, q.y, little);
                p = storeLittleEndian(p, q.z, little);
                p = storeLittleEndian(p, part.absoluteTime(i), little);
                if (factors) {
                    p = storeLittleEndian(p, part.doppler[i], little);
                    p = storeLittleEndian(p, part.proper_time[i], little);
                }
                if (object_bytes == 1)
                    *p++ = char(uint8_t(o));
                else if (object_bytes == 2)
                    p = storeLittleEndian(p, uint16_t(o), little);
                else
                    p = storeLittleEndian(p, int32_t(o), little);
            }
        });
        base += part.positions.size();
    }
    mesh4d::parallelFor(size_t(0), blocks.size(), [&](size_t i) {
        const FaceBlock& b = blocks[i];
        const auto& tris = frame.objects[b.object].triangles;
        char* p = face_start + kFaceBytes * b.faces_before;
        for (size_t f = b.begin; f < b.end; ++f) {
            const auto& t = tris[f];
            if (!keptFace(t)) continue;
            *p++ = char(3);
            for (uint32_t v : t) p = storeLittleEndian(p, int32_t(v + b.vertex_base), little);
        }
    });
}

bool writePly(const std::string& path, const ExportFrame& frame, const SequenceInfo& info, std::string* error) {
    return writeFrameFile(serializePly, path, frame, info, error);
}

std::unique_ptr<FrameSink> plySink(std::string dir) {
    return std::make_unique<FrameFileSink>(std::move(dir), "ply", serializePly);
}

}  // namespace apparent
