// Internal invariants: APPARENT_CHECK(a, op, b) states a relation the code relies on, such as
// APPARENT_CHECK(objects.size(), >=, scene_objects). When it does not hold, it throws
// std::logic_error naming the file, the line, the expression and both operands' values
// ("pipeline/stage/mirror.cpp:212: check failed: objects->size() >= scene_objects_ (2 >= 4)"); the
// command turns that into "error: internal: ..." and exit code 1 (pipeline/commands/cli.cpp).
//
// For broken invariants only: bad input is reported with a Status naming the file and field, never
// with a check. Operands are evaluated once; they need an operator<< (numbers, strings).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace mesh4d {

// The message of a failed check (out of line from the macro so that the fast path stays small).
template <class A, class B>
[[noreturn]] void failCheck(const char* file, int line, const char* expression, const A& a, const char* op,
                            const B& b) {
    std::ostringstream os;
    os.precision(17);
    os << file << ":" << line << ": check failed: " << expression << " (" << a << " " << op << " " << b << ")";
    throw std::logic_error(os.str());
}

}  // namespace mesh4d

#define APPARENT_CHECK(a, op, b)                                                                 \
    do {                                                                                         \
        const auto& apparent_check_a_ = (a);                                                     \
        const auto& apparent_check_b_ = (b);                                                     \
        if (!(apparent_check_a_ op apparent_check_b_))                                           \
            ::mesh4d::failCheck(__FILE__, __LINE__, #a " " #op " " #b, apparent_check_a_, #op,   \
                                apparent_check_b_);                                              \
    } while (false)
