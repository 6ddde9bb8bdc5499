#include "exporters/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>

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
    const char* msg = sig == SIGINT ? "apparent: interrupted (SIGINT): temporary files removed, written files are complete\n"
                                    : "apparent: terminated (SIGTERM): temporary files removed, written files are complete\n";
    ssize_t ignored = ::write(2, msg, std::strlen(msg));
    (void)ignored;
    ::_exit(128 + sig);
}

}  // namespace

AtomicOutput::AtomicOutput(std::string final_path) : final_(std::move(final_path)) {
    const std::filesystem::path p(final_);
    const std::string name = "." + p.stem().string() + ".tmp-" + std::to_string(::getpid()) + p.extension().string();
    temp_ = (p.parent_path() / name).string();
    slot_ = registerTemp(temp_);
}

AtomicOutput::~AtomicOutput() {
    if (!committed_) std::remove(temp_.c_str());
    unregisterTemp(slot_);
}

bool AtomicOutput::commit(std::string* error) {
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
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        *error = final_ + ": cannot create " + temp_ + ": " + std::strerror(errno);
        return false;
    }
    size_t done = 0;
    std::string why;
    if (!writeAll(fd, bytes.data(), bytes.size(), &why, &done)) {
        *error = final_ + ": cannot write (" + std::to_string(done) + " of " + std::to_string(bytes.size()) +
                 " bytes written): " + why;
        ::close(fd);
        return false;
    }
    // Always close, keeping the first failure's errno.
    int failed = ::fsync(fd) != 0 ? errno : 0;
    if (::close(fd) != 0 && failed == 0) failed = errno;
    if (failed != 0) {
        *error = final_ + ": cannot write: " + std::strerror(failed);
        return false;
    }
    return commit(error);
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

void installInterruptCleanup() {
    g_main_thread = pthread_self();
    struct sigaction sa {};
    sa.sa_handler = &onInterrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    ::sigaction(SIGTERM, &sa, nullptr);
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
