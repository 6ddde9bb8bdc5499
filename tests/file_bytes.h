// A whole file's bytes, for the tests that compare outputs byte for byte.
#pragma once

#include <array>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

namespace testio {

// The bytes of the file at `p` (empty when it cannot be opened).
inline std::string readBytes(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// The three coordinates of an OBJ "v x y z" line, read exactly (round to nearest); false when a
// number does not parse.
inline bool objVertex(const std::string& line, std::array<double, 3>* q) {
    const char* s = line.data() + 2;
    const char* const e = line.data() + line.size();
    for (double& x : *q) {
        const auto r = std::from_chars(s, e, x);
        if (r.ec != std::errc()) return false;
        s = r.ptr + (r.ptr < e ? 1 : 0);
    }
    return true;
}

}  // namespace testio
