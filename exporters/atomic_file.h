// Output files appear whole or not at all: each writer writes to a temporary name in the target's
// folder and renames it into place (rename(2) is atomic within a file system), so an interrupted
// run leaves the previous file or the new one, never a truncated one.
#pragma once

#include <cstddef>
#include <string>

#include <sys/uio.h>

namespace apparent {

//
// The temporary file is created by the constructor, exclusively (O_CREAT | O_EXCL | O_NOFOLLOW)
// under an unguessable name: a file or symlink planted at any name in the folder is never opened,
// written through or truncated (a new random name is drawn while the name exists). Before the
// rename, the name is checked to still be the file created (same device and inode, lstat: not a
// symlink put in its place), so the final name never becomes a planted link.
class AtomicOutput {
public:
    // `final_path` is where the file should end up. The temporary name is hidden and keeps the
    // extension, so leftovers are easy to find and tell apart: "dir/.name.tmp-PID-RANDOM.ext"
    // (RANDOM: 12 characters from /dev/urandom).
    explicit AtomicOutput(std::string final_path);
    ~AtomicOutput();  // closes and removes the temporary file unless commit() succeeded
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& tempPath() const { return temp_; }
    const std::string& finalPath() const { return final_; }
    // The temporary file, open for reading and writing; -1 when it could not be created (then
    // openError() says why, starting with the final path). Owned: closed by commit() or the destructor.
    int fd() const { return fd_; }
    const std::string& openError() const { return open_error_; }
    // Closes the temporary file (a failed close is an error), checks that its name is still the
    // file created and renames it into place. Returns false with a message on failure.
    bool commit(std::string* error);
    // Writes `bytes` to the temporary file, checking every write, fsync and close (a full disk or a
    // file size limit fails here, not later), then commits. Returns false with a message on failure;
    // the temporary file is then removed and the previous final file, if any, is untouched.
    bool commitBytes(const std::string& bytes, std::string* error);

private:
    std::string final_;
    std::string temp_;
    std::string open_error_;
    int fd_ = -1;
    unsigned long long dev_ = 0, ino_ = 0;  // identity of the file created
    bool committed_ = false;
    int slot_ = -1;  // entry in the registry of temporary files the interrupt handler removes
};

// Writes all `n` bytes to `fd`, retrying short and interrupted writes. On failure: false, errno's
// message in `error` and the bytes written so far in `*written` (when given).
bool writeAll(int fd, const void* data, size_t n, std::string* error, size_t* written = nullptr);

// Writes the `count` pieces one after another from the start of the empty file `fd` (the caller
// then fsyncs and commits). A file of at least kDirectLeast bytes goes past the page cache where
// the file system allows it: the pieces are copied, kDirectChunk bytes at a time, into a
// page-aligned buffer of the process (kept for the next file: no fresh pages to fault in) and
// written with O_DIRECT in whole pages, the file then cut to its length. That spares the kernel's
// copy into the page cache, fsync's writeback of it and the freeing of those pages when the file
// is later replaced: about half the CPU of writing a 26 MB file buffered (docs/PERFORMANCE.md),
// the same bytes and the same durability (the caller's fsync). Where O_DIRECT is refused (the flag
// or a write fails with EINVAL), and for smaller files, buffered writes after fallocate reserves
// the file's blocks in one call (only a hint). False with errno's message on failure, and the
// bytes written by then in `*written` (when given).
constexpr size_t kDirectLeast = size_t(4) << 20;
constexpr size_t kDirectChunk = size_t(8) << 20;
bool writeWhole(int fd, const iovec* pieces, size_t count, std::string* error, size_t* written = nullptr);
namespace detail {
// writeWhole with its staging buffer `stage_offset` bytes (below a page) past a page boundary;
// writeWhole is this with 0. The seam of the fallback's test (tests/atomic_file_test.cpp): a file
// system that checks O_DIRECT's memory alignment (ext4 on a block device: 512 bytes here) then
// fails the first direct write with EINVAL, the kernel's own refusal, as where O_DIRECT is refused.
bool writeWholeStaged(int fd, const iovec* pieces, size_t count, size_t stage_offset, std::string* error,
                      size_t* written = nullptr);
}  // namespace detail

// A file for scratch data in `dir` that has no name from the start (O_TMPFILE; where the file
// system lacks it, created exclusively under a random name and unlinked at once): nothing is left
// behind whatever ends the process, SIGKILL and the OOM killer included. -1 with a message on failure.
int openAnonymousFile(const std::string& dir, std::string* error);

// Names the interrupt cleanup below removes besides AtomicOutput's own temporaries: temporary
// files another process writes for this one to rename (frames across processes,
// exporters/frame_files.h). Returns the slot for unregisterTemporary, or -1 when the 64 slots are
// all taken (the name is then not removed on an interrupt; never a truncated final file either way).
int registerTemporary(const std::string& path);
void unregisterTemporary(int slot);

// Installs handlers for SIGINT, SIGTERM and SIGHUP (SIGINT and SIGHUP only when not ignored) that
// remove every temporary file of a live AtomicOutput, print one line and exit with 128 + the
// signal number (130, 143, 129). Files already renamed into place are complete and stay. SIGXFSZ is ignored, so a
// file size limit fails the write (exit 3) instead of killing the process. SIGKILL cannot be caught:
// it can leave one temporary file per writer, named ".NAME.tmp-PID.EXT", never a truncated final file.
void installInterruptCleanup();

}  // namespace apparent
