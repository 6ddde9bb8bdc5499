// The linear value of an 8-bit sRGB level and back (IEC 61966-2-1's transfer function), written
// here independently of pipeline/trace/raytrace.cpp's encoder, for the tests that read picture colours.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace testio {

inline double srgbToLinear(int v) {
    const double s = v / 255.0;
    return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

inline int linearToSrgb8(double c) {
    c = std::clamp(c, 0.0, 1.0);
    return int(std::lround(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055)));
}

// Whether an 8-bit sRGB level shows the linear value `expect`: within one level of quantisation, or
// within 1 % of the linear value.
inline bool levelShows(int level, double expect) {
    return std::abs(level - linearToSrgb8(expect)) <= 1 || std::fabs(srgbToLinear(level) - expect) <= 0.01 * expect;
}

}  // namespace testio
