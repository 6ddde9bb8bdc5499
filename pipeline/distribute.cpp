#include "pipeline/distribute.h"

#include <cstdint>
#include <cstring>

namespace apparent {

namespace {

constexpr uint32_t kFrameMagic = 0x31524641;  // "AFR1": apparent frame, version 1

void putU64(std::string* out, uint64_t v) {
    for (int i = 0; i < 8; ++i) out->push_back(char((v >> (8 * i)) & 0xff));  // little-endian
}

bool getU64(const std::string& in, size_t* at, uint64_t* v) {
    if (in.size() - *at < 8) return false;
    *v = 0;
    for (int i = 0; i < 8; ++i) *v |= uint64_t(uint8_t(in[*at + size_t(i)])) << (8 * i);
    *at += 8;
    return true;
}

}  // namespace

std::string serializeFrame(const EncodedFrame& frame) {
    size_t size = 6 * 8;
    for (const EncodedOutput& s : frame.sinks) size += 3 * 8 + s.bytes.size();
    std::string out;
    out.reserve(size);
    putU64(&out, kFrameMagic);
    putU64(&out, uint64_t(frame.index));
    putU64(&out, frame.triangles);
    putU64(&out, frame.limited_triangles);
    putU64(&out, frame.over_budget ? 1 : 0);
    putU64(&out, frame.sinks.size());
    for (const EncodedOutput& s : frame.sinks) {
        putU64(&out, uint64_t(s.least));
        putU64(&out, uint64_t(s.estimate));
        putU64(&out, s.bytes.size());
        out += s.bytes;
    }
    return out;
}

bool deserializeFrame(const std::string& bytes, EncodedFrame* frame, std::string* error) {
    size_t at = 0;
    uint64_t magic = 0, index = 0, over = 0, sinks = 0;
    bool ok = getU64(bytes, &at, &magic) && magic == kFrameMagic && getU64(bytes, &at, &index) &&
              getU64(bytes, &at, &frame->triangles) && getU64(bytes, &at, &frame->limited_triangles) &&
              getU64(bytes, &at, &over) && getU64(bytes, &at, &sinks) && sinks <= bytes.size();
    frame->index = (long long)index;
    frame->over_budget = over != 0;
    if (ok) frame->sinks.resize(size_t(sinks));
    for (EncodedOutput& s : frame->sinks) {
        uint64_t least = 0, estimate = 0, n = 0;
        ok = ok && getU64(bytes, &at, &least) && getU64(bytes, &at, &estimate) && getU64(bytes, &at, &n) &&
             n <= bytes.size() - at;
        if (!ok) break;
        s.least = (long long)least;
        s.estimate = (long long)estimate;
        s.bytes.assign(bytes, at, size_t(n));
        at += size_t(n);
    }
    if (!ok || at != bytes.size()) {
        *error = "internal: a frame from another process is malformed (frame " + std::to_string(frame->index) + ")";
        return false;
    }
    return true;
}

namespace {

std::unique_ptr<FrameGroup>& installed() {
    static std::unique_ptr<FrameGroup> group = std::make_unique<FrameGroup>();
    return group;
}

}  // namespace

FrameGroup& frameGroup() { return *installed(); }

void setFrameGroup(std::unique_ptr<FrameGroup> group) { installed() = std::move(group); }

}  // namespace apparent
