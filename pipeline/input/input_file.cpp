#include "pipeline/input/input_file.h"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace apparent {

namespace {

const char* kindOf(mode_t mode) {
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISDIR(mode)) return "a folder";
    return "not a regular file";
}

Status notRegular(const std::string& path, mode_t mode) {
    return Status::failure(path + ": is " + kindOf(mode) + ", not a regular file (refused)");
}

}  // namespace

Status checkRegularFile(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return Status::failure(path + ": cannot open: " + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) return notRegular(path, st.st_mode);
    return Status::success();
}

Status openRegularFile(const std::string& path, int* fd_out, uint64_t* size, const char* what) {
    *fd_out = -1;
    // The resolved path's type first (stat follows symlinks): a device is never even opened.
    struct stat before {};
    if (::stat(path.c_str(), &before) == 0 && !S_ISREG(before.st_mode)) return notRegular(path, before.st_mode);
    // Non-blocking: opening a FIFO without a writer returns at once instead of waiting; the
    // descriptor's own type is then checked, so a file swapped after the path check is caught too.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return Status::failure(path + ": cannot open " + what + ": " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const mode_t mode = st.st_mode;
        ::close(fd);
        return notRegular(path, mode);
    }
    *fd_out = fd;
    *size = uint64_t(st.st_size);
    return Status::success();
}

Status readRegularFile(const std::string& path, size_t max_bytes, std::string* out, const char* what) {
    out->clear();
    int fd = -1;
    uint64_t size = 0;
    if (Status s = openRegularFile(path, &fd, &size, what); !s.ok) return s;
    if (size > max_bytes) {
        ::close(fd);
        return Status::failure(path + ": " + std::to_string(size) + " bytes, larger than the limit of " +
                               std::to_string(max_bytes) + " bytes (raise with --max-file-bytes)");
    }
    out->resize(size_t(size));
    size_t done = 0;
    while (done < out->size()) {
        const ssize_t r = ::read(fd, &(*out)[done], out->size() - done);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;  // the file shrank while being read: keep what is there
        done += size_t(r);
    }
    ::close(fd);
    out->resize(done);
    return Status::success();
}

bool resolvesInside(const std::string& path, const std::string& root) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
    if (ec) return false;
    const fs::path r = fs::weakly_canonical(fs::absolute(root, ec), ec);
    if (ec) return false;
    auto pi = p.begin();
    for (auto ri = r.begin(); ri != r.end(); ++ri, ++pi) {
        if (ri->empty()) continue;  // a trailing separator
        if (pi == p.end() || *pi != *ri) return false;
    }
    return true;
}

}  // namespace apparent
