#include "exporters/atomic_file.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <mutex>
#include <random>
#include <vector>

#include <sys/stat.h>
#include <sys/uio.h>

#include <fcntl.h>
#include <pthread.h>
#include <unistd.h>

namespace apparent {

namespace {

// Temporary files in progress, readable from a signal handler: fixed storage, one flag per slot
// (std::atomic<bool> is lock-free, so reading it in the handler is async-signal-safe).
constexpr int kSlots = 64;
constexpr size_t kMaxPath = 4096;
char g_temp_paths[kSlots][kMaxPath];
std::atomic<bool> g_slot_used[kSlots];

int registerTemp(const std::string& path) {
    if (path.size() >= kMaxPath) return -1;
    for (int i = 0; i < kSlots; ++i) {
        bool expected = false;
        if (g_slot_used[i].load() || !g_slot_used[i].compare_exchange_strong(expected, true)) continue;
        // A handler running before the copy ends unlinks an older temporary name of ours, which no longer exists.
        std::memcpy(g_temp_paths[i], path.c_str(), path.size() + 1);
        return i;
    }
    return -1;  // more than 64 writers at once: not removed on an interrupt, still never a truncated final file
}

void unregisterTemp(int slot) {
    if (slot >= 0) g_slot_used[slot].store(false);
}

pthread_t g_main_thread;

void onInterrupt(int sig) {
    // A signal delivered to a worker thread (TBB) goes to the main thread, the only one that
    // creates files: cleaning up there leaves no file created after the cleanup.
    if (!pthread_equal(pthread_self(), g_main_thread)) {
        pthread_kill(g_main_thread, sig);
        return;
    }
    for (int i = 0; i < kSlots; ++i)
        if (g_slot_used[i].load() && g_temp_paths[i][0] != '\0') ::unlink(g_temp_paths[i]);
    const char* msg = sig == SIGINT   ? "apparent: interrupted (SIGINT): temporary files removed, written files are complete\n"
                      : sig == SIGHUP ? "apparent: hung up (SIGHUP): temporary files removed, written files are complete\n"
                                      : "apparent: terminated (SIGTERM): temporary files removed, written files are complete\n";
    ssize_t ignored = ::write(2, msg, std::strlen(msg));
    (void)ignored;
    ::_exit(128 + sig);
}

// 12 characters of [a-z0-9] from the kernel's random source: not guessable from the PID or time.
std::string randomSuffix() {
    static const char alphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    std::random_device rd;  // /dev/urandom (getrandom) with libstdc++
    std::string s;
    for (int i = 0; i < 12; ++i) s += alphabet[rd() % 36];
    return s;
}

// Creates `path_for(random)` exclusively, never following a symlink; retries on a name taken.
int createExclusive(const std::function<std::string(const std::string&)>& path_for, mode_t mode, std::string* path,
                    int* err) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        *path = path_for(randomSuffix());
        const int fd = ::open(path->c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
        if (fd >= 0) return fd;
        *err = errno;
        if (errno != EEXIST) return -1;
    }
    return -1;
}

}  // namespace

AtomicOutput::AtomicOutput(std::string final_path) : final_(std::move(final_path)) {
    const std::filesystem::path p(final_);
    const std::string prefix = "." + p.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-";
    const std::string ext = p.extension().string();
    int err = 0;
    // The interrupt signals wait while the file is created and its name registered: a handler
    // running in between would miss a file that exists under a name not yet registered.
    sigset_t block, previous;
    sigemptyset(&block);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&block, sig);
    pthread_sigmask(SIG_BLOCK, &block, &previous);
    fd_ = createExclusive([&](const std::string& r) { return (p.parent_path() / (prefix + r + ext)).string(); }, 0644,
                          &temp_, &err);
    if (fd_ >= 0) slot_ = registerTemp(temp_);
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    struct stat st {};
    if (fd_ < 0) {
        open_error_ = final_ + ": cannot create " + temp_ + ": " + std::strerror(err);
        temp_.clear();
    } else if (::fstat(fd_, &st) == 0) {
        dev_ = st.st_dev;
        ino_ = st.st_ino;
    }
}

AtomicOutput::~AtomicOutput() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_ && !temp_.empty()) std::remove(temp_.c_str());
    unregisterTemp(slot_);
}

bool AtomicOutput::commit(std::string* error) {
    if (fd_ < 0 && !open_error_.empty()) {
        *error = open_error_;
        return false;
    }
    if (fd_ >= 0) {
        const int fd = fd_;
        fd_ = -1;
        if (::close(fd) != 0) {
            *error = final_ + ": cannot write: " + std::strerror(errno);
            return false;
        }
    }
    // The name must still be the file created: not replaced (by a symlink or anything else).
    struct stat st {};
    if (::lstat(temp_.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_dev != dev_ || st.st_ino != ino_) {
        *error = final_ + ": the temporary file " + temp_ + " was replaced while writing (not renamed into place)";
        return false;
    }
    // Unregistered after the rename: an interrupt in between unlinks a name that no longer exists.
    if (std::rename(temp_.c_str(), final_.c_str()) != 0) {
        *error = final_ + ": cannot rename from " + temp_ + ": " + std::strerror(errno);
        return false;
    }
    committed_ = true;
    unregisterTemp(slot_);
    slot_ = -1;
    return true;
}

bool AtomicOutput::commitBytes(const std::string& bytes, std::string* error) {
    if (fd_ < 0) {
        *error = open_error_.empty() ? final_ + ": already committed" : open_error_;
        return false;
    }
    size_t done = 0;
    std::string why;
    if (!writeAll(fd_, bytes.data(), bytes.size(), &why, &done)) {
        *error = final_ + ": cannot write (" + std::to_string(done) + " of " + std::to_string(bytes.size()) +
                 " bytes written): " + why;
        return false;
    }
    if (::fsync(fd_) != 0) {
        *error = final_ + ": cannot write: " + std::strerror(errno);
        return false;
    }
    return commit(error);
}

int registerTemporary(const std::string& path) { return registerTemp(path); }

void unregisterTemporary(int slot) { unregisterTemp(slot); }

int openAnonymousFile(const std::string& dir, std::string* error) {
    const std::string folder = dir.empty() ? "." : dir;
    int fd = ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_EXCL | O_CLOEXEC, 0600);
    if (fd >= 0) return fd;
    // No O_TMPFILE here (some file systems): a random name, unlinked as soon as it exists.
    std::string path;
    int err = errno;
    fd = createExclusive([&](const std::string& r) { return folder + "/.apparent-spill.tmp-" + r; }, 0600, &path, &err);
    if (fd < 0) {
        *error = "cannot create a scratch file in " + folder + ": " + std::strerror(err);
        return -1;
    }
    ::unlink(path.c_str());
    return fd;
}

bool writeAll(int fd, const void* data, size_t n, std::string* error, size_t* written) {
    const char* p = static_cast<const char*>(data);
    size_t done = 0;
    while (done < n) {
        const ssize_t w = ::write(fd, p + done, n - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            *error = std::strerror(w < 0 ? errno : EIO);
            if (written) *written = done;
            return false;
        }
        done += size_t(w);
    }
    if (written) *written = done;
    return true;
}

namespace {

// writeWhole's page-aligned buffers of kDirectChunk + kPage bytes (room for a staging offset
// below a page, detail::writeWholeStaged), kept by the process (one per writer running at once).
struct DirectBuffers {
    std::mutex mutex;
    std::vector<void*> free;
};
DirectBuffers& directBuffers() {
    static DirectBuffers* buffers = new DirectBuffers;  // never destroyed: writers may run at exit
    return *buffers;
}
constexpr size_t kPage = 4096;

// All of `n` bytes at `offset`; once O_DIRECT is refused (EINVAL), the flag is dropped (*direct
// false) and the rest is written through the page cache.
// *done counts the bytes written.
bool putAt(int fd, const char* p, size_t n, uint64_t offset, int flags, bool* direct, std::string* error,
           size_t* done) {
    while (n > 0) {
        const ssize_t w = ::pwrite(fd, p, n, off_t(offset));
        if (w < 0 && errno == EINTR) continue;
        if (w < 0 && errno == EINVAL && *direct) {
            *direct = false;
            if (::fcntl(fd, F_SETFL, flags) != 0) {
                *error = std::strerror(errno);
                return false;
            }
            continue;
        }
        if (w <= 0) {
            *error = std::strerror(w < 0 ? errno : EIO);
            return false;
        }
        p += w;
        n -= size_t(w);
        offset += uint64_t(w);
        *done += size_t(w);
    }
    return true;
}

// Buffered: the file's blocks reserved, then writev, retrying short and interrupted writes.
bool writeBuffered(int fd, const iovec* pieces, size_t count, size_t total, std::string* error, size_t* written) {
    (void)::fallocate(fd, 0, 0, off_t(total));
    size_t i = 0, skip = 0;  // the first piece not yet written whole, and its bytes written
    std::vector<iovec> batch;
    for (;;) {
        while (i < count && skip == pieces[i].iov_len) {
            ++i;
            skip = 0;
        }
        if (i == count) return true;
        batch.clear();
        batch.push_back({static_cast<char*>(pieces[i].iov_base) + skip, pieces[i].iov_len - skip});
        for (size_t k = i + 1; k < count && batch.size() < size_t(IOV_MAX); ++k) batch.push_back(pieces[k]);
        const ssize_t w = ::writev(fd, batch.data(), int(batch.size()));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            *error = std::strerror(w < 0 ? errno : EIO);
            return false;
        }
        *written += size_t(w);
        size_t done = size_t(w) + skip;  // from the start of piece i
        while (i < count && done >= pieces[i].iov_len) done -= pieces[i++].iov_len;
        skip = done;
    }
}

}  // namespace

bool writeWhole(int fd, const iovec* pieces, size_t count, std::string* error, size_t* written) {
    return detail::writeWholeStaged(fd, pieces, count, 0, error, written);
}

bool detail::writeWholeStaged(int fd, const iovec* pieces, size_t count, size_t stage_offset, std::string* error,
                              size_t* written) {
    size_t ignored = 0;
    if (!written) written = &ignored;
    *written = 0;
    size_t total = 0;
    for (size_t k = 0; k < count; ++k) total += pieces[k].iov_len;
    const int flags = ::fcntl(fd, F_GETFL);
    if (total < kDirectLeast || flags < 0 || ::fcntl(fd, F_SETFL, flags | O_DIRECT) != 0)
        return writeBuffered(fd, pieces, count, total, error, written);
    DirectBuffers& pool = directBuffers();
    void* buffer = nullptr;
    {
        std::lock_guard<std::mutex> lock(pool.mutex);
        if (!pool.free.empty()) {
            buffer = pool.free.back();
            pool.free.pop_back();
        }
    }
    if (!buffer && ::posix_memalign(&buffer, kPage, kDirectChunk + kPage) != 0) buffer = nullptr;
    if (!buffer) {
        (void)::fcntl(fd, F_SETFL, flags);
        return writeBuffered(fd, pieces, count, total, error, written);
    }
    // Chunks of kDirectChunk bytes (the last padded with zeros to a whole page, cut off below).
    char* const stage = static_cast<char*>(buffer) + stage_offset % kPage;
    bool direct = true, ok = true;
    uint64_t offset = 0;
    size_t fill = 0;
    for (size_t k = 0; k < count && ok; ++k) {
        const char* p = static_cast<const char*>(pieces[k].iov_base);
        size_t left = pieces[k].iov_len;
        while (left > 0 && ok) {
            const size_t take = std::min(left, kDirectChunk - fill);
            std::memcpy(stage + fill, p, take);
            fill += take;
            p += take;
            left -= take;
            if (fill == kDirectChunk) {
                ok = putAt(fd, stage, fill, offset, flags, &direct, error, written);
                offset += fill;
                fill = 0;
            }
        }
    }
    if (ok && fill > 0) {
        const size_t padded = (fill + kPage - 1) / kPage * kPage;
        std::memset(stage + fill, 0, padded - fill);
        ok = putAt(fd, stage, padded, offset, flags, &direct, error, written) &&
             (padded == fill || ::ftruncate(fd, off_t(offset + fill)) == 0 || (*error = std::strerror(errno), false));
        *written = std::min(*written, total);  // not the padding
    }
    if (direct && ::fcntl(fd, F_SETFL, flags) != 0 && ok) {
        *error = std::strerror(errno);
        ok = false;
    }
    std::lock_guard<std::mutex> lock(pool.mutex);
    pool.free.push_back(buffer);
    return ok;
}

void installInterruptCleanup() {
    g_main_thread = pthread_self();
    struct sigaction sa {};
    sa.sa_handler = &onInterrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    ::sigaction(SIGTERM, &sa, nullptr);
    // A closed terminal or a lost SSH session: the same as SIGTERM (a nohup'ed run keeps SIG_IGN).
    struct sigaction old_hup {};
    if (::sigaction(SIGHUP, nullptr, &old_hup) == 0 && old_hup.sa_handler != SIG_IGN) ::sigaction(SIGHUP, &sa, nullptr);
    // A file size limit (ulimit -f) would kill the process mid-write with SIGXFSZ: ignored, the
    // write fails with EFBIG instead and is reported like a full disk (exit 3, temporary removed).
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    ::sigaction(SIGXFSZ, &ignore, nullptr);
    struct sigaction old {};
    // A background job of a non-interactive shell starts with SIGINT ignored: keep it so.
    if (::sigaction(SIGINT, nullptr, &old) == 0 && old.sa_handler != SIG_IGN) ::sigaction(SIGINT, &sa, nullptr);
}

}  // namespace apparent
