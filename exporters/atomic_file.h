// Output files appear whole or not at all: each writer writes to a temporary name in the target's
// folder and renames it into place (rename(2) is atomic within a file system), so an interrupted
// run leaves the previous file or the new one, never a truncated one.
#pragma once

#include <string>

namespace apparent {

class AtomicOutput {
public:
    // `final_path` is where the file should end up. The temporary name keeps its extension, because
    // OpenMesh picks the format from it: "dir/.name.tmp-PID.ext".
    explicit AtomicOutput(std::string final_path);
    ~AtomicOutput();  // removes the temporary file unless commit() succeeded
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& tempPath() const { return temp_; }
    const std::string& finalPath() const { return final_; }
    // Renames the temporary file into place. Returns false (and keeps errno's message in `error`) on failure.
    bool commit(std::string* error);

private:
    std::string final_;
    std::string temp_;
    bool committed_ = false;
};

}  // namespace apparent
