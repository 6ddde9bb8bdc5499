// Hints instead of blanks (issue 38): an object that no frame of a model shows in the camera's view
// gets one warning naming the object, the model and the likely cause, instead of an empty row.
//
// In view: the object's apparent bounding sphere (mesh4d/slice.h apparentBound, from its motion and
// its rest mesh's radius alone, without its 4D history) meets the camera's view (worlds.h
// inCameraView, the --cull-view test: a cone, or the orthographic camera's cylinder, wider than any
// picture), so a warned object is outside every picture of those frames; a motion that is not
// uniform is never warned about (no bound is derived for it). The cause named, in order:
//   - instant or contracted, while a light-speed model sees it at those frames: these models show
//     objects where they are at t - camera.instant_delay; the light delay of the object's origin at
//     the middle frame (the relativistic cut, or finite's when relativistic is refused) is what the
//     delay should be about;
//   - finite or relativistic, while the instant model sees it: the light takes that delay to arrive,
//     so it is seen that much later (move the frames);
//   - otherwise: outside the view at every frame time (camera.look_at, fov_deg or width, the frames).
#pragma once

#include <string>
#include <vector>

#include "pipeline/stage/stage.h"

namespace apparent {

// Whether object `object` of the stage is in the camera's view at global frame k under `model`.
bool objectInView(const Stage& stage, Model model, size_t object, long long k);

// One line per object that none of `frames` shows in view under `model` ("scene: objects[i]
// (name): ... in model M ...; cause"), in scene order. Mirror objects are left out.
std::vector<std::string> outOfViewWarnings(const Stage& stage, Model model, const std::vector<long long>& frames);

// The frames first..last_excl - 1.
std::vector<long long> frameRange(long long first, long long last_excl);

}  // namespace apparent
