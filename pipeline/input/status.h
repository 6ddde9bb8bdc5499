// The result of reading user input: ok, or one line naming the file, the field and the problem.
#pragma once

#include <string>
#include <utility>

namespace apparent {

struct Status {
    bool ok = true;
    std::string message;  // set when !ok: "file: field: problem"

    static Status success() { return {}; }
    static Status failure(std::string msg) { return {false, std::move(msg)}; }
};

}  // namespace apparent
