// The colour a moving surface shows: its base colour shifted by the Doppler factor D and
// brightened or dimmed by the searchlight effect (`--shade doppler` of `render` and `raytrace`).
//
// Model (one home for both commands):
// - Emitted spectrum. The base colour's linear R, G, B are the amplitudes a_R, a_G, a_B of three
//   Gaussian bands of the specific intensity per unit frequency, written over wavelength l:
//       I_emit(l) = sum_c a_c g(l - l_c),  g(x) = exp(-x^2 / (2 s^2)),
//   centres l_R = 610 nm, l_G = 550 nm, l_B = 465 nm, width s = kBandWidthNm = 40 nm.
// - Observed spectrum. A source with Doppler factor D (received over emitted frequency,
//   mesh4d/light_factors.h) is seen with I_obs(l) = D^3 I_emit(l D): light observed at l left
//   the source at l D, and I_nu / nu^3 is invariant. Integrated over frequency the brightness
//   scales as D^4 (the searchlight effect); per band sample as D^3.
// - Channels. The observed spectrum is sampled at the three band centres, s_k = I_obs(l_k), and
//   unmixed by the inverse of the bands' overlap matrix M_kc = g(l_k - l_c), so that D = 1 gives
//   the base colour exactly: colour = M^-1 s (M^-1 s = a when D = 1). The bands overlap
//   (g(60 nm) = 0.32 between R and G) so that a shift glides from one band into the next.
// - Tone map into [0, 1]: negative channels (the unmixing of a spectrum that is not a sum of the
//   three bands) are set to 0, then the colour is divided by its largest channel when that
//   exceeds 1 (the hue kept, brightness above white saturates). Colours within [0, 1] pass
//   unchanged, so D = 1 returns the base colour.
// Bounds: D > 0 and finite (anything else gives black); a colour's channels are read as given
// (linear, normally in [0, 1]). Far outside 0.5 < D < 2 every band has left the samples and the
// colour goes to black (red shift) or saturates to the hue of what remains (blue shift).
//
// The shift as a matrix. I_obs is linear in a, and so are the samples and the unmixing:
//     dopplerChannels(a, D) = A(D) a,  A(D) = D^3 M^-1 G(D),  G_kc = g(l_k D - l_c),
// a 3x3 matrix that mixes the channels (A(1) = I). A texel t of a texture is seen as
// toneMap(A(D) t): what the web viewer computes per fragment (exporters/web/doppler.mjs).
//
// The modulation for glTF viewers. A vertex colour multiplies the material (glTF: COLOR_0 times
// baseColorFactor times the texture), so it can only apply a diagonal. `--shade doppler` on an
// object that keeps its input's look writes COLOR_0 = W(D) * c per channel, with
//     W(D) = toneMap(A(D) (1, 1, 1))  (the shaded colour of white),
// c the input's COLOR_0 (1 without one), and keeps the input's materials. Against the exact
// E(a) = toneMap(A(D) a) of the material's colour a (factor times texel times c, in [0, 1]^3),
// the modulation P(a) = W(D) * a per channel errs as follows, w = A(D) (1, 1, 1):
// - Grey a = (g, g, g): where white does not saturate (max_i w_i <= 1), P = E exactly. Where it
//   does (m = max_i w_i > 1), P = E max(1/m, g): the hue is E's, the brightness of a grey darker
//   than 1/m is E's divided by m (a vertex colour cannot brighten past the material).
// - Any a, where neither saturates (max_i w_i <= 1 and max_i (A a)_i <= 1): per channel
//       |P_i - E_i| <= |sum_{j != i} A_ij (a_j - a_i)|
//   (P_i = max(0, w_i a_i) as a_i >= 0, the clamp at 0 widens no difference, and
//   (A a)_i - w_i a_i is that sum): the shift's mixing of the channels' differences, 0 for a grey.
// docs/DOPPLER.md gives its size over the colour cube at the D a scene meets.
#pragma once

#include <array>

namespace mesh4d {

constexpr double kBandCentreNm[3] = {610.0, 550.0, 465.0};  // R, G, B
constexpr double kBandWidthNm = 40.0;                         // Gaussian s (standard deviation)

// I_obs at wavelength l (nm) for band amplitudes `a` (linear R, G, B) and Doppler factor D.
double observedSpectrum(const std::array<double, 3>& a, double doppler, double wavelength_nm);

// M^-1 s before the tone map: the observed channels, unbounded (D = 1: exactly `a`).
std::array<double, 3> dopplerChannels(const std::array<double, 3>& a, double doppler);

// The tone map above: negatives to 0, then divided by the largest channel when it exceeds 1.
std::array<double, 3> toneMap(const std::array<double, 3>& c);

// The shaded colour: toneMap(dopplerChannels(base, D)).
std::array<double, 3> dopplerColour(const std::array<double, 3>& base, double doppler);

// A(D) above, row-major (A[i][j]: channel i from amplitude j); zero where D is not > 0 and finite.
std::array<std::array<double, 3>, 3> dopplerMatrix(double doppler);

// W(D) above, the per-channel modulation of a material: the shaded colour of white, in [0, 1].
std::array<double, 3> dopplerModulation(double doppler);

}  // namespace mesh4d
