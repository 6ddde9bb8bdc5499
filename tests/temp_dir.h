// A temporary folder of this test process's own: gtest's TempDir() (shared /tmp) plus
// "apparent-<pid>/", made on first use, so that tests writing fixed file names cannot meet another
// process's files (ctest -j runs each test as its own process; other checkouts' suites may run at
// the same time). Ends with '/'. Left in place: the names inside it are the tests' own.
#pragma once

#include <filesystem>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

namespace testio {

inline std::string processTempDir() {
    static const std::string dir = [] {
        const std::string d = ::testing::TempDir() + "apparent-" + std::to_string(::getpid()) + "/";
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

// processTempDir() as a path, for `testio::tempPath() / "name"`.
inline std::filesystem::path tempPath() { return processTempDir(); }

}  // namespace testio
