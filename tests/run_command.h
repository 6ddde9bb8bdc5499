// Runs the `apparent` command line in-process for the end-to-end tests.
#pragma once

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "pipeline/commands/cli.h"

namespace testcli {

inline std::string source(const std::string& rel) { return std::string(APPARENT_SOURCE_DIR) + "/" + rel; }

struct CommandResult {
    int code = -1;
    std::string out, err;
};

// `apparent ARGS...`: exit code and what it printed.
inline CommandResult apparentRun(std::vector<std::string> args) {
    args.insert(args.begin(), "apparent");
    std::vector<const char*> argv;
    for (const auto& a : args) argv.push_back(a.c_str());
    std::ostringstream out, err;
    CommandResult r;
    r.code = apparent::runCommandLine(int(argv.size()), argv.data(), out, err);
    r.out = out.str();
    r.err = err.str();
    return r;
}

// A fresh folder under the system's temporary folder, removed with the object.
class TempDir {
public:
    TempDir() {
        path_ = std::filesystem::temp_directory_path() /
                ("apparent_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
        std::filesystem::remove_all(path_);
    }
    ~TempDir() { std::filesystem::remove_all(path_); }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::string str() const { return path_.string(); }
    std::filesystem::path operator/(const std::string& s) const { return path_ / s; }

private:
    std::filesystem::path path_;
    static inline int counter_ = 0;
};

}  // namespace testcli
