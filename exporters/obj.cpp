#include "exporters/obj.h"

#include <charconv>
#include <utility>

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

}  // namespace

bool writeObj(const std::string& path, const ExportFrame& frame, std::string* error) {
    const mesh4d::ApparentMesh m = mergeObjects(frame);
    size_t faces = 0;
    for (const auto& t : m.triangles) faces += t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    // Step: serialized in memory, then written with every error checked (exporters/atomic_file.h).
    std::string text = "# " + std::to_string(m.positions.size()) + " vertices, " + std::to_string(faces) + " faces\n";
    text.reserve(text.size() + 60 * m.positions.size() + 24 * faces);
    for (const mesh4d::Vec3& p : m.positions) {
        text += "v ";
        putNumber(&text, p.x);
        text += ' ';
        putNumber(&text, p.y);
        text += ' ';
        putNumber(&text, p.z);
        text += '\n';
    }
    for (const auto& t : m.triangles) {
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;  // zero area by construction
        text += "f " + std::to_string(t[0] + 1) + ' ' + std::to_string(t[1] + 1) + ' ' + std::to_string(t[2] + 1) + '\n';
    }
    AtomicOutput out(path);
    return out.commitBytes(text, error);
}

std::unique_ptr<FrameSink> objSink(std::string dir) {
    return std::make_unique<FrameFileSink>(std::move(dir), "obj", writeObj);
}

}  // namespace apparent
