#include "exporters/obj.h"

#include <algorithm>
#include <charconv>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include "exporters/atomic_file.h"
#include "exporters/frame_files.h"

namespace apparent {

namespace {

// `value` with 17 significant digits, shortest form of "%.17g" (std::to_chars: no locale).
void putNumber(std::string* out, double value) {
    char buffer[32];
    const auto r = std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::general, 17);
    out->append(buffer, r.ptr);
}

void putIndex(std::string* out, uint64_t value) {
    char buffer[24];
    const auto r = std::to_chars(buffer, buffer + sizeof(buffer), value);
    out->append(buffer, r.ptr);
}

bool keptFace(const std::array<uint32_t, 3>& t) { return t[0] != t[1] && t[1] != t[2] && t[0] != t[2]; }

constexpr size_t kBlock = size_t(1) << 15;  // vertices or triangles formatted by one task

// A run of one object's vertices or triangles, formatted into its own text.
struct Block {
    size_t object = 0, begin = 0, end = 0;
    bool faces = false;
    uint64_t vertex_base = 0;  // vertices of the objects before (faces)
};

}  // namespace

void serializeObj(const ExportFrame& frame, const SequenceInfo& info, std::string* out) {
    // Step: the blocks in file order, per object its vertices, then its faces (its `o` group).
    std::vector<Block> blocks;
    std::vector<size_t> first_block(frame.objects.size() + 1, 0);
    uint64_t vertices = 0;
    for (size_t o = 0; o < frame.objects.size(); ++o) {
        first_block[o] = blocks.size();
        const size_t n = frame.objects[o].positions.size();
        for (size_t b = 0; b < n; b += kBlock) blocks.push_back({o, b, std::min(n, b + kBlock), false, 0});
        const size_t m = frame.objects[o].triangles.size();
        for (size_t b = 0; b < m; b += kBlock) blocks.push_back({o, b, std::min(m, b + kBlock), true, vertices});
        vertices += n;
    }
    first_block[frame.objects.size()] = blocks.size();
    // Step: each block formatted in parallel into its own text (kept between frames), then joined
    // in order: the bytes do not depend on the thread count.
    thread_local std::vector<std::string> kept_texts;
    std::vector<std::string>& texts = kept_texts;  // the calling thread's, for every task
    if (texts.size() < blocks.size()) texts.resize(blocks.size());
    std::vector<size_t> faces_in(blocks.size(), 0);
    tbb::parallel_for(size_t(0), blocks.size(), [&](size_t i) {
        const Block& b = blocks[i];
        const mesh4d::ApparentMesh& part = frame.objects[b.object];
        std::string& text = texts[i];
        text.clear();
        if (!b.faces) {
            for (size_t v = b.begin; v < b.end; ++v) {
                const mesh4d::Vec3 p = part.absolutePosition(v);
                text += "v ";
                putNumber(&text, p.x);
                text += ' ';
                putNumber(&text, p.y);
                text += ' ';
                putNumber(&text, p.z);
                text += '\n';
            }
            return;
        }
        for (size_t f = b.begin; f < b.end; ++f) {
            const auto& t = part.triangles[f];
            if (!keptFace(t)) continue;  // zero area by construction
            ++faces_in[i];
            text += 'f';
            for (uint32_t v : t) {
                text += ' ';
                putIndex(&text, b.vertex_base + v + 1);
            }
            text += '\n';
        }
    });
    size_t faces = 0, size = 0;
    for (size_t i = 0; i < blocks.size(); ++i) {
        faces += faces_in[i];
        size += texts[i].size();
    }
    // Step: the counts and comments (frameFileComments), then per object its `o` line and blocks.
    std::string& all = *out;
    all = "# " + std::to_string(vertices) + " vertices, " + std::to_string(faces) + " faces\n";
    for (const std::string& line : frameFileComments(frame, info)) all += "# " + line + "\n";
    all.reserve(all.size() + size);
    for (size_t o = 0; o < frame.objects.size(); ++o) {
        all += "o " + frameObjectName(info, o) + "\n";
        for (size_t i = first_block[o]; i < first_block[o + 1]; ++i) all += texts[i];
    }
}

bool writeObj(const std::string& path, const ExportFrame& frame, const SequenceInfo& info, std::string* error) {
    return writeFrameFile(serializeObj, path, frame, info, error);
}

std::unique_ptr<FrameSink> objSink(std::string dir) {
    return std::make_unique<FrameFileSink>(std::move(dir), "obj", serializeObj, /*light_factors=*/false);
}

}  // namespace apparent
