// Line scanning shared by our own text readers (OBJ and its .mtl libraries): tokens separated by
// blanks within one line, no allocation (views into the file's bytes).
#pragma once

#include <cstddef>
#include <string_view>

namespace apparent {

// A blank within a line (not '\n', which ends it).
inline bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// The next blank-separated token of [*p, end), advancing *p past it; empty at the line's end.
inline std::string_view nextToken(const char** p, const char* end) {
    const char* s = *p;
    while (s < end && isBlank(*s)) ++s;
    const char* e = s;
    while (e < end && !isBlank(*e)) ++e;
    *p = e;
    return std::string_view(s, size_t(e - s));
}

}  // namespace apparent
