// The `apparent` command line. Kept apart from main() so tests can run it in-process.
#pragma once

#include <iosfwd>

namespace apparent {

// Parses argv and runs the command. Returns the process exit code: 0 success, 2 bad usage or bad
// input (one line on `err` naming the file, the field and the problem), 3 output error.
int runCommandLine(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace apparent
