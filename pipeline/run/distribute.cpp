#include "pipeline/run/distribute.h"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>

#include <fcntl.h>
#include <unistd.h>

#include "exporters/frame_files.h"
#include "exporters/frame_spill.h"

namespace apparent {

namespace {

constexpr uint32_t kFrameMagic = 0x31524641;  // "AFR1": apparent frame, version 1
// From how many processes meshopt frames that may be morph targets travel by reference.
constexpr int kMorphTargetsByReferenceFrom = 10;

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

std::string frameHeader(const EncodedFrame& frame) {
    std::string out;
    out.reserve((6 + 3 * frame.sinks.size()) * 8);
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
    }
    return out;
}

std::vector<std::string_view> frameParts(const EncodedFrame& frame, const std::string& header) {
    std::vector<std::string_view> parts{header};
    for (const EncodedOutput& s : frame.sinks) parts.emplace_back(s.bytes);
    return parts;
}

bool frameFromParts(std::vector<std::string>* parts, EncodedFrame* frame, std::string* error) {
    size_t at = 0;
    uint64_t magic = 0, index = 0, over = 0, sinks = 0;
    const std::string empty;
    const std::string& head = parts->empty() ? empty : parts->front();
    bool ok = getU64(head, &at, &magic) && magic == kFrameMagic && getU64(head, &at, &index) &&
              getU64(head, &at, &frame->triangles) && getU64(head, &at, &frame->limited_triangles) &&
              getU64(head, &at, &over) && getU64(head, &at, &sinks) && sinks + 1 == parts->size() &&
              head.size() - at == 3 * 8 * sinks;
    frame->index = (long long)index;
    frame->over_budget = over != 0;
    frame->sinks.clear();
    if (ok) frame->sinks.resize(size_t(sinks));
    for (size_t i = 0; ok && i < frame->sinks.size(); ++i) {
        EncodedOutput& s = frame->sinks[i];
        uint64_t least = 0, estimate = 0, n = 0;
        ok = getU64(head, &at, &least) && getU64(head, &at, &estimate) && getU64(head, &at, &n) &&
             n == (*parts)[i + 1].size();
        s.least = (long long)least;
        s.estimate = (long long)estimate;
        if (ok) s.bytes = std::move((*parts)[i + 1]);
    }
    if (!ok) {
        *error = "internal: a frame from another process is malformed (frame " + std::to_string(frame->index) + ")";
        return false;
    }
    return true;
}

bool FrameGroup::receiveFrame(int from, std::string* bytes, int* code, std::string* error) {
    std::vector<std::string> parts;
    if (!receiveParts(from, &parts, code, error)) return false;
    if (parts.size() != 1) {
        *code = 1;
        *error = "internal: rank " + std::to_string(from) + " sent " + std::to_string(parts.size()) +
                 " parts where one picture was due";
        return false;
    }
    *bytes = std::move(parts.front());
    return true;
}

bool shareFrameSpills(const std::string& dir, const std::vector<std::string>& frame_folders, std::string* why) {
    FrameGroup& group = frameGroup();
    // Step: one name per rank, from a token rank 0 draws (names of other runs cannot clash).
    std::string token;
    if (group.rank() == 0) {
        std::random_device random;
        const char* hex = "0123456789abcdef";
        for (int i = 0; i < 16; ++i) token.push_back(hex[random() % 16]);
    }
    token = group.broadcast(token);
    auto name = [&](int rank) {
        return (std::filesystem::path(dir) / (".apparent-frames-" + token + "." + std::to_string(rank))).string();
    };
    // Step: every rank its own file; and from now on, before any rank can make a frame file (they
    // make them after the agreements below), an interrupt on any rank removes every rank's.
    const std::string mine = name(group.rank());
    const int fd = ::open(mine.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    std::string error = fd < 0 ? mine + ": cannot create: " + std::strerror(errno) : std::string();
    if (fd >= 0 && !removeFrameTemporariesOnInterrupt(token, frame_folders))
        error = dir + ": too many frame folders or too long a path for the interrupt cleanup";
    int code = group.agree(error.empty() ? 0 : 1, &error);
    // Step: rank 0 opens them all, then no name is left.
    if (code == 0 && group.rank() == 0) {
        for (int r = 0; r < group.size(); ++r) {
            const std::string path = name(r);
            const int other = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
            if (other >= 0) {
                addFrameSource(r, other);
            } else if (code == 0) {
                code = 1;
                error = path + ": rank " + std::to_string(r) + "'s frame file is not visible on rank 0 (" +
                        std::strerror(errno) + "): the output folder is not shared by every rank";
            }
        }
        for (int r = 0; r < group.size(); ++r) ::unlink(name(r).c_str());
    }
    code = group.agree(code, &error);
    if (code != 0) {
        if (fd >= 0) {
            ::close(fd);
            ::unlink(mine.c_str());  // a rank whose file rank 0 never opened
        }
        *why = error;
        return false;
    }
    installFrameSpill(fd, group.rank());
    // Meshopt morph targets by reference cost every process about 2.5 times its work per frame (it
    // cuts the frame before again and encodes two forms) and save rank 0 about 4 ms of a frame's 16:
    // measured faster than whole frames only from about 10 processes (docs/PERFORMANCE.md).
    setMorphTargetsByReference(group.size() >= kMorphTargetsByReferenceFrom);
    setFrameRunToken(token);
    if (group.rank() == 0)
        setFramePlacer([](const std::string& path, const std::vector<Placement>& placements, std::string* e) {
            return frameGroup().placeOnRanks(path, placements, e);
        });
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
