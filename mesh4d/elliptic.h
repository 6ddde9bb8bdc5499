// Elliptic integrals of the second kind, for the proper time of keyframed and orbiting bodies
// (mesh4d/motion/keyed.h, orbit.cpp): one implementation for every build, the native program's and
// the WebAssembly one's, whose C++ library (libc++) has no std::ellint_2 (docs/DESIGN.md section 14).
//
//   E(phi | k) = integral_0^phi sqrt(1 - k^2 sin^2 t) dt,   E(k) = E(pi/2 | k),   |k| <= 1.
//
// Through Carlson's symmetric integrals (B. C. Carlson, "Numerical computation of real or complex
// elliptic integrals", Numerical Algorithms 10 (1995) 13-26; DLMF 19.16, 19.36):
//   R_F(x, y, z) = 1/2 integral_0^inf dt / sqrt((t + x)(t + y)(t + z)),
//   R_D(x, y, z) = 3/2 integral_0^inf dt / ((t + z) sqrt((t + x)(t + y)(t + z))),
// for |phi| <= pi/2, with s = sin phi, c = cos phi (DLMF 19.25.9):
//   E(phi | k) = s R_F(c^2, 1 - k^2 s^2, 1) - (k^2 s^3 / 3) R_D(c^2, 1 - k^2 s^2, 1),
// and any phi from E(phi + n pi | k) = E(phi | k) + 2 n E(k) (E is odd in phi).
//
// The duplication theorem: with lambda = sqrt(x y) + sqrt(y z) + sqrt(z x),
//   R_F(x, y, z) = R_F((x + lambda)/4, (y + lambda)/4, (z + lambda)/4),
//   R_D(x, y, z) = R_D(...)/4 + 3 / (sqrt(z) (z + lambda)),
// which draws x, y, z together; once they lie within a relative spread e of their mean A, a fifth- or
// sixth-order series in the spreads finishes (Carlson's (2.2) and (2.28)):
//   R_F = A^(-1/2) (1 - E2/10 + E3/14 + E2^2/24 - 3 E2 E3/44),  X = (A0 - x0)/(4^m A), Y likewise, Z = -X - Y,
//         E2 = X Y - Z^2, E3 = X Y Z;
//   R_D = 4^-m A^(-3/2) (1 - 3 E2/14 + E3/6 + 9 E2^2/88 - 3 E4/22 - 9 E2 E3/52 + 3 E5/26)
//         + 3 sum_{j<m} 4^-j / (sqrt(z_j) (z_j + lambda_j)),
//         X = (A0 - x0)/(4^m A), Y = (A0 - y0)/(4^m A), Z = -(X + Y)/3 (x0, y0 the arguments),
//         E2 = X Y - 6 Z^2, E3 = (3 X Y - 8 Z^2) Z, E4 = 3 (X Y - Z^2) Z^2, E5 = X Y Z^3.
// The loop stops when 4^-m Q < |A_m|, Q = (3 r)^(-1/6) max|A0 - x| for R_F and (r/4)^(-1/6) max|A0 - x|
// for R_D, r = 2^-53: Carlson's bound then puts the truncation below r relative.
#pragma once

namespace mesh4d {

double carlsonRF(double x, double y, double z);  // x, y, z >= 0, at most one of them 0
double carlsonRD(double x, double y, double z);  // x, y >= 0 (not both 0), z > 0
double ellipticE(double k, double phi);          // E(phi | k), any finite phi, |k| <= 1
double ellipticE(double k);                      // E(k), |k| <= 1

}  // namespace mesh4d
