#include "exporters/frame_spill.h"

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <map>
#include <mutex>

#include <fcntl.h>
#include <unistd.h>

namespace apparent {

namespace {

struct Spill {
    int fd = -1;
    int source = -1;
    std::atomic<uint64_t> end{0};
};
Spill& spill() {
    static Spill s;
    return s;
}

struct Sources {
    std::mutex mutex;
    std::map<int, int> fds;
};
Sources& sources() {
    static Sources s;
    return s;
}

}  // namespace

void installFrameSpill(int fd, int source) {
    spill().fd = fd;
    spill().source = source;
    spill().end = 0;
}

bool frameSpillInstalled() { return spill().fd >= 0; }

bool spillFrameData(const std::vector<iovec>& pieces, std::vector<FileSpan>* spans, std::string* error) {
    Spill& s = spill();
    uint64_t total = 0;
    for (const iovec& p : pieces) total += p.iov_len;
    // Step: the range, reserved at once (frames written at the same time never overlap).
    const uint64_t start = s.end.fetch_add(total);
    spans->clear();
    uint64_t at = start;
    for (const iovec& p : pieces) {
        spans->push_back({int32_t(s.source), at, uint64_t(p.iov_len)});
        at += p.iov_len;
    }
    // Step: pwritev, IOV_MAX pieces at a time, resumed after short writes.
    std::vector<iovec> left(pieces);
    size_t first = 0;
    uint64_t offset = start;
    while (first < left.size()) {
        if (left[first].iov_len == 0) {
            ++first;
            continue;
        }
        const int count = int(std::min<size_t>(left.size() - first, IOV_MAX));
        const ssize_t r = ::pwritev(s.fd, &left[first], count, off_t(offset));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) {
            *error = r < 0 ? std::strerror(errno) : "nothing written";
            return false;
        }
        offset += uint64_t(r);
        size_t n = size_t(r);
        while (n > 0 && first < left.size()) {
            const size_t take = std::min(n, left[first].iov_len);
            left[first].iov_base = static_cast<char*>(left[first].iov_base) + take;
            left[first].iov_len -= take;
            n -= take;
            if (left[first].iov_len == 0) ++first;
        }
    }
    return true;
}

void addFrameSource(int source, int fd) {
    std::lock_guard<std::mutex> lock(sources().mutex);
    auto [it, added] = sources().fds.emplace(source, fd);
    if (!added && it->second != fd) {
        ::close(it->second);
        it->second = fd;
    }
}

int frameSource(int source) {
    std::lock_guard<std::mutex> lock(sources().mutex);
    const auto it = sources().fds.find(source);
    return it == sources().fds.end() ? -1 : it->second;
}

void releaseFrameData(const FileSpan& span) {
    const int fd = frameSource(span.source);
    if (fd < 0 || span.length == 0) return;
    // Where the file system cannot punch holes the space comes back when the process ends.
    (void)::fallocate(fd, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, off_t(span.offset), off_t(span.length));
}

}  // namespace apparent
