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

}  // namespace mesh4d
