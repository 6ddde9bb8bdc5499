// Output files appear whole or not at all: each writer writes to a temporary name in the target's
// folder and renames it into place (rename(2) is atomic within a file system), so an interrupted
// run leaves the previous file or the new one, never a truncated one.
#pragma once

#include <cstddef>
#include <string>

namespace apparent {

class AtomicOutput {
public:
    // `final_path` is where the file should end up. The temporary name is hidden and keeps the
    // extension, so leftovers are easy to find and tell apart: "dir/.name.tmp-PID.ext".
    explicit AtomicOutput(std::string final_path);
    ~AtomicOutput();  // removes the temporary file unless commit() succeeded
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& tempPath() const { return temp_; }
    const std::string& finalPath() const { return final_; }
    // Renames the temporary file into place. Returns false (and keeps errno's message in `error`) on failure.
    bool commit(std::string* error);
    // Writes `bytes` to the temporary file, checking every write, fsync and close (a full disk or a
    // file size limit fails here, not later), then commits. Returns false with a message on failure;
    // the temporary file is then removed and the previous final file, if any, is untouched.
    bool commitBytes(const std::string& bytes, std::string* error);

private:
    std::string final_;
    std::string temp_;
    bool committed_ = false;
    int slot_ = -1;  // entry in the registry of temporary files the interrupt handler removes
};

// Writes all `n` bytes to `fd`, retrying short and interrupted writes. On failure: false, errno's
// message in `error` and the bytes written so far in `*written` (when given).
bool writeAll(int fd, const void* data, size_t n, std::string* error, size_t* written = nullptr);

// Installs handlers for SIGINT and SIGTERM (SIGINT only when it is not ignored) that remove every
// temporary file of a live AtomicOutput, print one line and exit with 128 + the signal number
// (130, 143). Files already renamed into place are complete and stay. SIGXFSZ is ignored, so a
// file size limit fails the write (exit 3) instead of killing the process. SIGKILL cannot be caught:
// it can leave one temporary file per writer, named ".NAME.tmp-PID.EXT", never a truncated final file.
void installInterruptCleanup();

}  // namespace apparent
