// The scene's units (scene field `units`, docs/SCENES.md "Units"): "ls", light-seconds and seconds
// (the default: c = 1), or "m", lengths in metres and times in seconds, speeds as fractions of c.
// Inside, everything is in light-seconds and seconds: a metre scene's lengths are divided by
// kSpeedOfLight as it is read (toLightSeconds) and its outputs' lengths multiplied by it
// (toSceneUnits), so the physics and its tests are the light-second ones. Times are seconds in
// both and are shown with a prefix that fits them (timeText).
#pragma once

#include <string>

namespace apparent {

constexpr double kSpeedOfLight = 299792458.0;  // metres per second (SI, exact)

enum class LengthUnit { LightSecond, Metre };

// Light-seconds per scene unit of length (1, or 1 / c for metres).
inline double lightSecondsPer(LengthUnit u) { return u == LengthUnit::Metre ? 1 / kSpeedOfLight : 1; }
// Scene units of length per light-second (1, or c).
inline double unitsPerLightSecond(LengthUnit u) { return u == LengthUnit::Metre ? kSpeedOfLight : 1; }
// "ls" or "m": lengths in messages and summaries.
inline const char* lengthName(LengthUnit u) { return u == LengthUnit::Metre ? "m" : "ls"; }
// The outputs' units, as the .glb's scene extras and the PLY and OBJ comments state them.
inline const char* unitsText(LengthUnit u) {
    return u == LengthUnit::Metre ? "metres, seconds, speeds as fractions of c" : "light-seconds, seconds, c = 1";
}

// A prefix for times of at most `largest` seconds in magnitude: s (from 1 s, and for 0), ms, us
// (microseconds, in ASCII for the labels' Latin-1 font) or ns, and its seconds.
struct TimePrefix {
    const char* name = "s";
    double seconds = 1;
};
TimePrefix timePrefixFor(double largest);

// "32.0 ns": `t` seconds in `prefix`, with `decimals` decimals (fixed).
std::string timeText(double t, const TimePrefix& prefix, int decimals);

}  // namespace apparent
