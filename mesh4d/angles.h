// The one pi of the project: angles in the scenes and the glTF camera are in degrees, the
// trigonometry in radians (deg * kPi / 180).
#pragma once

namespace mesh4d {

constexpr double kPi = 3.14159265358979323846;

}  // namespace mesh4d
