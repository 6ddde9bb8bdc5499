// The BIN chunk while frames arrive (BinSink, glb.h), and frame data read from frame sources and
// copied between files.
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "exporters/atomic_file.h"
#include "exporters/glb/glb.h"

#include <fcntl.h>
#include <unistd.h>

namespace apparent::glb {

void BinSink::write(const void* data, size_t n) {
    size += n;
    if (counting || n == 0) return;
    if (holding) {
        const char* p = static_cast<const char*>(data);
        for (const auto& [lo, hi] : borrowable)
            if (p >= lo && p + n <= hi) {
                held.push_back({p, 0, n});
                return;
            }
        held.push_back({nullptr, own.size(), n});
        own.append(p, n);
        return;
    }
    toSpill(data, n);
}

void BinSink::toSpill(const void* data, size_t n) {
    // The spill file has no name (atomic_file.h): nothing is left behind, even after SIGKILL.
    if (fd < 0 && error.empty()) fd = openAnonymousFile(dir, &error);
    if (fd >= 0 && error.empty() && !writeAll(fd, data, n, &error)) error = "cannot write: " + error;
    if (in_pieces) piece({kLocal, local, n});
    local += n;
}

void BinSink::spill() {
    if (!holding) return;
    holding = false;
    for (const Held& h : held) toSpill(h.data ? h.data : own.data() + h.offset, h.n);
    held = {};
    own = {};
    borrowable.clear();
    pinned.reset();
}

void BinSink::heldPieces(std::vector<iovec>* out) const {
    for (const Held& h : held) out->push_back({const_cast<char*>(h.data ? h.data : own.data() + h.offset), h.n});
}

void BinSink::pad(size_t n) {
    static const char zeros[4] = {0, 0, 0, 0};
    if (!in_pieces) return write(zeros, n);
    piece({kZeros, 0, n});
    size += n;
}

void BinSink::reference(const FileSpan& s) {
    if (!counting) {
        spill();
        if (!in_pieces) startPieces();
        piece(s);
    }
    size += s.length;
}

void BinSink::startPieces() {
    in_pieces = true;
    if (local > 0) pieces.push_back({kLocal, 0, local});
}

void BinSink::piece(const FileSpan& s) {
    if (s.length == 0) return;
    FileSpan* last = pieces.empty() ? nullptr : &pieces.back();
    if (last && last->source == s.source && (s.source == kZeros || last->offset + last->length == s.offset))
        last->length += s.length;
    else
        pieces.push_back(s);
}

bool readSpan(const FileSpan& span, void* out, std::string* error) {
    const int fd = frameSource(span.source);
    size_t done = 0;
    while (fd >= 0 && done < span.length) {
        const ssize_t r = ::pread(fd, static_cast<char*>(out) + done, size_t(span.length) - done, off_t(span.offset + done));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;
        done += size_t(r);
    }
    if (done == span.length) return true;
    *error = "cannot read frame data of process " + std::to_string(span.source) +
             (fd < 0 ? std::string(": not known") : ": " + std::string(std::strerror(errno)));
    return false;
}

bool copyRange(int in, uint64_t offset, uint64_t n, int out, std::string* error) {
    if (n == 0) return true;
    if (in < 0) {
        *error = "internal: frame data from an unknown process";
        return false;
    }
    uint64_t off = 0;
    while (off < n) {
        loff_t at = loff_t(offset + off);
        const ssize_t r = ::copy_file_range(in, &at, out, nullptr, size_t(n - off), 0);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;  // the fallback below takes over from `off`
        off += uint64_t(r);
    }
    std::vector<char> chunk(off < n ? size_t(1) << 20 : 0);
    while (off < n) {
        const ssize_t r = ::pread(in, chunk.data(), size_t(std::min<uint64_t>(chunk.size(), n - off)), off_t(offset + off));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) {
            *error = std::string("cannot read back the spill file: ") + std::strerror(r < 0 ? errno : EIO);
            return false;
        }
        if (!writeAll(out, chunk.data(), size_t(r), error)) return false;
        off += uint64_t(r);
    }
    return true;
}

}  // namespace apparent::glb
