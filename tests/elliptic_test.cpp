// Elliptic integrals of the second kind (mesh4d/elliptic.h) against Carlson's published values,
// closed forms, the complete integral by the arithmetic-geometric mean, values computed to 40 digits
// by mpmath, and libstdc++'s std::ellint_2 (an implementation of its own).
#include <gtest/gtest.h>

#include <cmath>

#include "mesh4d/angles.h"
#include "mesh4d/elliptic.h"

using mesh4d::kPi;

// Carlson (1995), section 3: test values to 13 digits.
TEST(Elliptic, CarlsonsTestValues) {
    EXPECT_NEAR(mesh4d::carlsonRF(1, 2, 0), 1.3110287771461, 1e-13);
    EXPECT_NEAR(mesh4d::carlsonRF(2, 3, 4), 0.58408284167715, 1e-13);
    EXPECT_NEAR(mesh4d::carlsonRD(0, 2, 1), 1.7972103521034, 1e-13);
    EXPECT_NEAR(mesh4d::carlsonRD(2, 3, 4), 0.16510527294261, 1e-13);
}

// E(phi | 0) = phi, E(phi | 1) = sin phi on |phi| <= pi/2, E odd and E(phi + pi) = E(phi) + 2 E(k).
TEST(Elliptic, ClosedFormsAndSymmetries) {
    for (double phi : {-1.5, -0.3, 0.0, 0.2, 1.0, kPi / 2}) {
        EXPECT_NEAR(mesh4d::ellipticE(0, phi), phi, 4e-16 * (1 + std::fabs(phi))) << phi;
        EXPECT_NEAR(mesh4d::ellipticE(1, phi), std::sin(phi), 1e-15) << phi;
    }
    EXPECT_DOUBLE_EQ(mesh4d::ellipticE(1), 1.0);
    EXPECT_NEAR(mesh4d::ellipticE(0), kPi / 2, 4e-16);
    for (double k : {0.1, 0.5, 0.9, 0.999})
        for (double phi : {0.3, 1.2, 2.9, 7.5}) {
            EXPECT_NEAR(mesh4d::ellipticE(k, -phi), -mesh4d::ellipticE(k, phi), 1e-15 * (1 + phi));
            EXPECT_NEAR(mesh4d::ellipticE(k, phi + kPi), mesh4d::ellipticE(k, phi) + 2 * mesh4d::ellipticE(k),
                        2e-15 * (1 + phi));
        }
}

// The complete integral by the arithmetic-geometric mean (DLMF 19.8.6 and 19.8.1): a0 = 1,
// b0 = sqrt(1 - k^2), c0 = k; a, b -> (a + b)/2, sqrt(a b), c_{n+1} = (a_n - b_n)/2;
// K = pi / (2 AGM), E = K (1 - sum_n 2^(n-1) c_n^2).
TEST(Elliptic, CompleteIntegralAgainstTheArithmeticGeometricMean) {
    for (double k : {0.0, 0.1, 0.5, 0.8, 0.95, 0.999}) {
        double a = 1, b = std::sqrt(1 - k * k), c = k, sum = 0.5 * c * c, power = 0.5;
        for (int n = 0; n < 40 && c != 0; ++n) {
            const double an = 0.5 * (a + b), bn = std::sqrt(a * b);
            c = 0.5 * (a - b);
            a = an;
            b = bn;
            power *= 2;
            sum += power * c * c;
        }
        const double K = kPi / (2 * a);
        EXPECT_NEAR(mesh4d::ellipticE(k), K * (1 - sum), 2e-15) << k;
    }
}

// E(phi | k) from mpmath 1.x (`mp.dps = 40; ellipe(phi, k**2)`), printed to 20 digits.
TEST(Elliptic, AgainstArbitraryPrecision) {
    const double cases[][3] = {{0.3, 0.7, 0.69530899833306636566},   {0.9, 1.4, 1.0957417516212684111},
                               {0.98, -1.84, -1.1165238106049543506}, {0.999, 2.5, 1.4094244450560874691},
                               {0.6, 10.0, 9.0728536194856441001},   {0.9999, 1.5707, 1.0005131378407089504}};
    for (const auto& c : cases)
        EXPECT_NEAR(mesh4d::ellipticE(c[0], c[1]), c[2], 2e-15 * std::max(1.0, std::fabs(c[2]))) << c[0] << " " << c[1];
    EXPECT_NEAR(mesh4d::ellipticE(0.98), 1.0500922613894988966, 2e-15);  // mpmath ellipe(0.98**2)
}

// libstdc++'s std::ellint_2 (its own implementation of Carlson's forms) over the moduli and
// amplitudes the proper times use. It is the less accurate of the two near k = 1: its E(0.98) is
// 1.6e-13 from mpmath's (the test above holds this one to 2e-15), so the bound here is 5e-13.
TEST(Elliptic, AgreesWithTheStandardLibrary) {
    double worst = 0;
    for (int i = 0; i <= 50; ++i)
        for (int j = -40; j <= 40; ++j) {
            const double k = i / 50.0, phi = j * 0.23;
            const double want = std::ellint_2(k, phi);
            const double got = mesh4d::ellipticE(k, phi);
            worst = std::max(worst, std::fabs(got - want) / std::max(1.0, std::fabs(want)));
        }
    for (int i = 0; i < 50; ++i) {
        const double k = i / 50.0;
        worst = std::max(worst, std::fabs(mesh4d::ellipticE(k) - std::comp_ellint_2(k)));
    }
    std::printf("[ elliptic ] largest difference from std::ellint_2: %.3g (relative)\n", worst);
    EXPECT_LT(worst, 5e-13);
}
