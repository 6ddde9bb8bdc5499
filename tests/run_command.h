// Runs the `apparent` command line in-process for the end-to-end tests.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "pipeline/cli.h"

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

}  // namespace testcli
