// Two doubles in one register (GCC and Clang vector extensions), for code that makes the same
// IEEE operations on two independent inputs at once: the refinement's bounds (chord_error.cpp:
// the whole-piece forms, two edge bounds) and the normals (normals.cpp). A lane gives the bits of
// the scalar code it stands for when that code's operations are written in the same order and the
// file is compiled without contraction (-ffp-contract=off, CMakeLists.txt): +, -, *, / and sqrt
// are correctly rounded either way. Comparisons give a Lanes2Mask (all ones where true); `m ? a : b`
// selects lane by lane. On a target without SSE2 the compiler lowers the operations to scalar ones.
#pragma once

#include <cmath>

namespace mesh4d {

typedef double Lanes2 __attribute__((vector_size(16)));
typedef long long Lanes2Mask __attribute__((vector_size(16)));

inline Lanes2 splatLanes(double a) { return Lanes2{a, a}; }
// std::max(a, b) and std::min(a, b) lane by lane, NaNs alike (the first operand unless the
// comparison holds).
inline Lanes2 maxLanes(Lanes2 a, Lanes2 b) { return a < b ? b : a; }
inline Lanes2 minLanes(Lanes2 a, Lanes2 b) { return b < a ? b : a; }
// The square root lane by lane: SSE2's sqrtpd where the target has it, else std::sqrt per lane.
inline Lanes2 sqrtLanes(Lanes2 a) {
#if defined(__SSE2__)
    return __builtin_ia32_sqrtpd(a);
#else
    return Lanes2{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}

}  // namespace mesh4d
