#include "doppler_colour.h"

#include <algorithm>
#include <cmath>

namespace mesh4d {

namespace {

double band(double x) { return std::exp(-x * x / (2 * kBandWidthNm * kBandWidthNm)); }

// M^-1 of the overlap matrix M_kc = g(l_k - l_c) (symmetric), by the adjugate; computed once.
std::array<std::array<double, 3>, 3> unmixing() {
    double m[3][3];
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) m[k][c] = band(kBandCentreNm[k] - kBandCentreNm[c]);
    std::array<std::array<double, 3>, 3> inv{};
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            // Cofactor of m[j][i] (transposed: the adjugate).
            const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
            inv[size_t(i)][size_t(j)] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
        }
    return inv;
}

}  // namespace

double observedSpectrum(const std::array<double, 3>& a, double doppler, double wavelength_nm) {
    const double emitted = wavelength_nm * doppler;
    double sum = 0;
    for (int c = 0; c < 3; ++c) sum += a[size_t(c)] * band(emitted - kBandCentreNm[c]);
    return doppler * doppler * doppler * sum;
}

std::array<double, 3> dopplerChannels(const std::array<double, 3>& a, double doppler) {
    static const std::array<std::array<double, 3>, 3> inv = unmixing();
    if (!(doppler > 0) || !std::isfinite(doppler)) return {0, 0, 0};
    double s[3];
    for (int k = 0; k < 3; ++k) s[k] = observedSpectrum(a, doppler, kBandCentreNm[k]);
    std::array<double, 3> out{};
    for (int i = 0; i < 3; ++i) out[size_t(i)] = inv[size_t(i)][0] * s[0] + inv[size_t(i)][1] * s[1] + inv[size_t(i)][2] * s[2];
    return out;
}

std::array<std::array<double, 3>, 3> dopplerMatrix(double doppler) {
    // Column j: the channels of amplitude e_j (dopplerChannels is linear).
    std::array<std::array<double, 3>, 3> a{};
    for (size_t j = 0; j < 3; ++j) {
        std::array<double, 3> e{0, 0, 0};
        e[j] = 1;
        const std::array<double, 3> column = dopplerChannels(e, doppler);
        for (size_t i = 0; i < 3; ++i) a[i][j] = column[i];
    }
    return a;
}

std::array<double, 3> dopplerModulation(double doppler) { return dopplerColour({1, 1, 1}, doppler); }

std::array<double, 3> toneMap(const std::array<double, 3>& c) {
    std::array<double, 3> out{};
    for (size_t k = 0; k < 3; ++k) out[k] = std::isfinite(c[k]) ? std::max(0.0, c[k]) : 0.0;
    const double top = std::max({out[0], out[1], out[2]});
    if (top > 1)
        for (double& v : out) v /= top;
    return out;
}

std::array<double, 3> dopplerColour(const std::array<double, 3>& base, double doppler) {
    return toneMap(dopplerChannels(base, doppler));
}

}  // namespace mesh4d
