// Elliptic integrals of the second kind by Carlson's duplication (elliptic.h).
#include "mesh4d/elliptic.h"

#include <algorithm>
#include <cmath>

#include "mesh4d/angles.h"

namespace mesh4d {

namespace {
constexpr double kUnitRoundoff = 0x1p-53;

// One duplication step (elliptic.h): lambda from the current x, y, z, then x, y, z and their mean
// a drawn to (value + lambda) / 4. Returns lambda and sqrt(z) before the step (R_D's sum uses them).
struct Duplication {
    double lambda, sqrt_z;
};
Duplication duplicate(double* x, double* y, double* z, double* a) {
    const double sx = std::sqrt(*x), sy = std::sqrt(*y), sz = std::sqrt(*z);
    const double lambda = sx * sy + sy * sz + sz * sx;
    *x = 0.25 * (*x + lambda);
    *y = 0.25 * (*y + lambda);
    *z = 0.25 * (*z + lambda);
    *a = 0.25 * (*a + lambda);
    return {lambda, sz};
}
}  // namespace

double carlsonRF(double x, double y, double z) {
    const double x0 = x, y0 = y, a0 = (x + y + z) / 3;
    const double q = std::pow(3 * kUnitRoundoff, -1.0 / 6) * std::max({std::fabs(a0 - x), std::fabs(a0 - y), std::fabs(a0 - z)});
    double a = a0, scale = 1;  // scale = 4^-m
    // Step: duplicate until the spread is below the series' reach.
    while (scale * q >= std::fabs(a)) {
        duplicate(&x, &y, &z, &a);
        scale *= 0.25;
    }
    // Step: the series.
    const double X = (a0 - x0) * scale / a, Y = (a0 - y0) * scale / a;
    const double Z = -(X + Y);
    const double e2 = X * Y - Z * Z, e3 = X * Y * Z;
    return (1 - e2 / 10 + e3 / 14 + e2 * e2 / 24 - 3 * e2 * e3 / 44) / std::sqrt(a);
}

double carlsonRD(double x, double y, double z) {
    const double x0 = x, y0 = y, a0 = (x + y + 3 * z) / 5;
    const double q = std::pow(0.25 * kUnitRoundoff, -1.0 / 6) * std::max({std::fabs(a0 - x), std::fabs(a0 - y), std::fabs(a0 - z)});
    double a = a0, scale = 1, sum = 0;
    // Step: duplicate, summing the terms each step leaves.
    while (scale * q >= std::fabs(a)) {
        const double z_before = z;
        const Duplication d = duplicate(&x, &y, &z, &a);
        sum += scale / (d.sqrt_z * (z_before + d.lambda));
        scale *= 0.25;
    }
    // Step: the series.
    const double X = (a0 - x0) * scale / a, Y = (a0 - y0) * scale / a;
    const double Z = -(X + Y) / 3;
    const double xy = X * Y, z2 = Z * Z;
    const double e2 = xy - 6 * z2, e3 = (3 * xy - 8 * z2) * Z, e4 = 3 * (xy - z2) * z2, e5 = xy * z2 * Z;
    const double series = 1 - 3 * e2 / 14 + e3 / 6 + 9 * e2 * e2 / 88 - 3 * e4 / 22 - 9 * e2 * e3 / 52 + 3 * e5 / 26;
    return scale * series / (a * std::sqrt(a)) + 3 * sum;
}

double ellipticE(double k) {
    const double k2 = k * k;
    if (k2 >= 1) return 1;
    return carlsonRF(0, 1 - k2, 1) - k2 / 3 * carlsonRD(0, 1 - k2, 1);
}

double ellipticE(double k, double phi) {
    // Step: phi = n pi + r, |r| <= pi/2.
    const double n = std::nearbyint(phi / kPi);
    const double r = phi - n * kPi;
    const double s = std::sin(r), c = std::cos(r), k2 = k * k;
    const double delta = 1 - k2 * s * s;
    // Step: E(r | k); at k = 1 and |r| = pi/2 both Carlson terms diverge, E = sin r.
    const double e = delta <= 0 ? s : s * carlsonRF(c * c, delta, 1) - k2 * s * s * s / 3 * carlsonRD(c * c, delta, 1);
    return n == 0 ? e : 2 * n * ellipticE(k) + e;
}

}  // namespace mesh4d
