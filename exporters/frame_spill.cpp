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

namespace {
std::string& runToken() {
    static std::string token;
    return token;
}
}  // namespace

void setFrameRunToken(const std::string& token) { runToken() = token; }

const std::string& frameRunToken() { return runToken(); }

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

bool placeHere(const std::string& path, const std::vector<Placement>& placements, std::string* error) {
    if (placements.empty()) return true;
    const int out = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOFOLLOW);
    if (out < 0) {
        *error = "cannot open " + path + ": " + std::strerror(errno);
        return false;
    }
    std::string why;
    std::vector<char> chunk;
    for (const Placement& p : placements) {
        const int in = p.from.source == spill().source && spill().fd >= 0 ? spill().fd : frameSource(p.from.source);
        if (in < 0) {
            why = "frame data of an unknown process (" + std::to_string(p.from.source) + ")";
            break;
        }
        // Step: copy_file_range at both offsets; what it leaves (another file system), by pread and pwrite.
        uint64_t done = 0;
        while (done < p.from.length) {
            loff_t from = loff_t(p.from.offset + done), to = loff_t(p.to + done);
            const ssize_t r = ::copy_file_range(in, &from, out, &to, size_t(p.from.length - done), 0);
            if (r < 0 && errno == EINTR) continue;
            if (r <= 0) break;
            done += uint64_t(r);
        }
        if (done < p.from.length && chunk.empty()) chunk.resize(size_t(1) << 20);
        while (why.empty() && done < p.from.length) {
            const ssize_t r = ::pread(in, chunk.data(), size_t(std::min<uint64_t>(chunk.size(), p.from.length - done)),
                                      off_t(p.from.offset + done));
            if (r < 0 && errno == EINTR) continue;
            if (r <= 0) {
                why = std::string("cannot read back frame data: ") + (r < 0 ? std::strerror(errno) : "end of file");
                break;
            }
            size_t put = 0;
            while (why.empty() && put < size_t(r)) {
                const ssize_t w = ::pwrite(out, chunk.data() + put, size_t(r) - put, off_t(p.to + done + put));
                if (w < 0 && errno == EINTR) continue;
                if (w <= 0) why = std::string("cannot write: ") + (w < 0 ? std::strerror(errno) : "nothing written");
                else put += size_t(w);
            }
            done += put;
        }
        if (!why.empty()) break;
    }
    if (why.empty() && ::fsync(out) != 0) why = std::string("cannot write: ") + std::strerror(errno);
    if (::close(out) != 0 && why.empty()) why = std::string("cannot write: ") + std::strerror(errno);
    if (!why.empty()) *error = why;
    return why.empty();
}

namespace {
FramePlacer& placer() {
    static FramePlacer p;
    return p;
}
}  // namespace

void setFramePlacer(FramePlacer p) { placer() = std::move(p); }

bool placeFrameData(const std::string& path, const std::vector<Placement>& placements, std::string* error) {
    return placer() ? placer()(path, placements, error) : placeHere(path, placements, error);
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
