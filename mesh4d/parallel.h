// A loop over independent indices, run in parallel by TBB, or in order where TBB is absent (the
// WebAssembly build, APPARENT_NO_TBB: docs/DESIGN.md section 14). Every caller writes each index's
// result into its own slot, so the results do not depend on the scheduling.
#pragma once

#include <cstddef>

#if !defined(APPARENT_NO_TBB)
#include <tbb/parallel_for.h>
#endif

namespace mesh4d {

// body(i) for i = first, first + step, ... below last (tbb::parallel_for's index form).
template <class Body>
void parallelFor(size_t first, size_t last, size_t step, const Body& body) {
#if defined(APPARENT_NO_TBB)
    for (size_t i = first; i < last; i += step) body(i);
#else
    tbb::parallel_for(first, last, step, body);
#endif
}

template <class Body>
void parallelFor(size_t first, size_t last, const Body& body) {
    parallelFor(first, last, size_t(1), body);
}

}  // namespace mesh4d
