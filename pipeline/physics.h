// The map from a scene's model and an object's entry to physics: which kinematics moves the
// object (Galilean or Lorentz), its motion (a worldline through (t0, position) with the stated
// velocity, or direction with gamma or rapidity), and the camera's view surface per frame (the past
// lightcone for finite and relativistic, the hyperplane t = t_c - instant_delay for instant and
// contracted). A new motion model starts here (README "Adding a motion model").
#pragma once

#include "mesh4d/boost.h"
#include "mesh4d/lightcone.h"
#include "pipeline/scene.h"

namespace apparent {

// Lorentz for relativistic and contracted, Galilean for instant and finite.
mesh4d::Kinematics kinematicsOf(Model model);

// The motion of `object` under `model`. Precondition: the scene passed checkSceneForModel.
mesh4d::Motion motionOf(const ObjectSpec& object, Model model);

// The view surface at camera time t_c, and at global frame k (t_c = frameTime(scene.frames, k)).
mesh4d::ViewSurface viewAt(const Scene& scene, Model model, double t_c);
mesh4d::ViewSurface viewForFrame(const Scene& scene, Model model, long long k);

}  // namespace apparent
