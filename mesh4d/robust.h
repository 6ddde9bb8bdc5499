// Small numerical kernels that keep cancellation out of the cone cut.
//
// - differenceOfProducts(a, b, c, d) = a*b - c*d with one rounding of error via an FMA
//   (Kahan's algorithm; pbrt-v4 util/math.h uses the same). Error <= 1.5 ulp of the result.
// - solveQuadratic: roots of a s^2 + 2 h s + k = 0 (note the halved linear coefficient), computed
//   with the sign-chosen form q = -(h + sign(h) sqrt(h^2 - a k)), s1 = q / a, s2 = k / q, which never
//   subtracts nearly equal numbers (Numerical Recipes 5.6; pbrt's Quadratic).
// - oneMinusSquare(b) = 1 - b^2 evaluated as (1 - b)(1 + b), exact to 1 ulp even for b near 1
//   (docs/DESIGN.md section 5: never 1 - b*b).
// - oneMinusNorm2(x, y, z) = 1 - (x^2 + y^2 + z^2) from the components of a velocity, for
//   oblique ones: taking |v| first rounds it (relative 1e-16), and 1 - |v| then carries that
//   rounding relative to itself (2.2e-11 relative at b = 0.999999 with three equal components).
//   Each square is split exactly into x*x + fma(x, x, -x*x) and the seven terms are summed with
//   error-free additions (Ogita, Rump, Oishi 2005, "Accurate sum and dot product", Sum2): error
//   <= eps |result| + gamma_6^2 (1 + x^2 + y^2 + z^2), i.e. within 1 ulp of the exact value for
//   any |v| <= 2 (the second term is below 1e-30).
#pragma once

#include <cmath>

namespace mesh4d {

inline double differenceOfProducts(double a, double b, double c, double d) {
    const double cd = c * d;
    const double err = std::fma(-c, d, cd);  // exact rounding error of c*d
    const double dop = std::fma(a, b, -cd);
    return dop + err;
}

inline double oneMinusSquare(double b) { return (1.0 - b) * (1.0 + b); }

// s + e = a + b exactly (Knuth's TwoSum; no branch, any order of magnitudes).
inline void twoSum(double a, double b, double* s, double* e) {
    *s = a + b;
    const double bb = *s - a;
    *e = (a - (*s - bb)) + (b - bb);
}

inline double oneMinusNorm2(double x, double y, double z) {
    const double hi[3] = {x * x, y * y, z * z};
    const double lo[3] = {std::fma(x, x, -hi[0]), std::fma(y, y, -hi[1]), std::fma(z, z, -hi[2])};
    // Step: large terms first, then the exact low parts; every rounding error is kept in c.
    const double terms[6] = {-hi[0], -hi[1], -hi[2], -lo[0], -lo[1], -lo[2]};
    double s = 1.0, c = 0.0;
    for (double t : terms) {
        double e;
        twoSum(s, t, &s, &e);
        c += e;
    }
    return s + c;
}

struct QuadraticRoots {
    int count = 0;       // 0, 1 or 2 real roots
    double r0 = 0, r1 = 0;  // r0 <= r1 when count == 2
};

// Real roots of a s^2 + 2 h s + k = 0. A degenerate a == 0 falls back to the linear equation.
// Returns count = 0 when there is no real root (or the equation is 0 = 0 or k = 0 with a = h = 0).
inline QuadraticRoots solveQuadratic(double a, double h, double k) {
    QuadraticRoots out;
    if (a == 0) {
        if (h == 0) return out;
        out.count = 1;
        out.r0 = out.r1 = -k / (2 * h);
        return out;
    }
    const double disc = differenceOfProducts(h, h, a, k);
    if (disc < 0) return out;
    const double root = std::sqrt(disc);
    const double q = -(h + std::copysign(root, h));
    double s0, s1;
    if (q == 0) {  // h == 0 and disc == 0: the double root s = 0
        s0 = s1 = 0;
    } else {
        s0 = q / a;
        s1 = k / q;
    }
    if (s0 > s1) std::swap(s0, s1);
    out.count = 2;
    out.r0 = s0;
    out.r1 = s1;
    return out;
}

}  // namespace mesh4d
