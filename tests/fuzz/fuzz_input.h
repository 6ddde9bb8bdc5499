// Shared by the libFuzzer harnesses: the readers take paths (tinygltf reads files), so
// each input is written to one file in a per-process folder on tmpfs (/dev/shm when present,
// else the temporary folder) and read back from there. The folder holds nothing else, so a glTF
// buffer URI can only name the input itself or fail.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace apparent_fuzz {

// Writes data to "<tmpfs>/apparent-fuzz-PID/input<ext>" and returns that path.
inline std::string writeInput(const uint8_t* data, size_t size, const char* ext) {
    static const std::string dir = [] {
        std::error_code ec;
        std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm")
                                                                                  : std::filesystem::temp_directory_path();
        const auto d = base / ("apparent-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d, ec);
        return d.string();
    }();
    const std::string path = dir + "/input" + ext;
    if (FILE* f = std::fopen(path.c_str(), "wb")) {
        if (size) std::fwrite(data, 1, size, f);
        std::fclose(f);
    }
    return path;
}

// Removes the per-process folder at exit (registered once by each harness).
inline void removeInputFolderAtExit() {
    static bool registered = false;
    if (registered) return;
    registered = true;
    std::atexit([] {
        std::error_code ec;
        std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm")
                                                                                  : std::filesystem::temp_directory_path();
        std::filesystem::remove_all(base / ("apparent-fuzz-" + std::to_string(::getpid())), ec);
    });
}

}  // namespace apparent_fuzz
