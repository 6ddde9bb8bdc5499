#include "exporters/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <unistd.h>

namespace apparent {

AtomicOutput::AtomicOutput(std::string final_path) : final_(std::move(final_path)) {
    const std::filesystem::path p(final_);
    const std::string name = "." + p.stem().string() + ".tmp-" + std::to_string(::getpid()) + p.extension().string();
    temp_ = (p.parent_path() / name).string();
}

AtomicOutput::~AtomicOutput() {
    if (!committed_) std::remove(temp_.c_str());
}

bool AtomicOutput::commit(std::string* error) {
    if (std::rename(temp_.c_str(), final_.c_str()) != 0) {
        *error = final_ + ": cannot rename from " + temp_ + ": " + std::strerror(errno);
        return false;
    }
    committed_ = true;
    return true;
}

}  // namespace apparent
