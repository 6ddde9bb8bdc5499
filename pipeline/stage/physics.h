// The map from a scene's model and an object's entry to physics: which kinematics moves the
// object (Galilean or Lorentz), its motion (a worldline through (t0, position) with the stated
// velocity, or direction with gamma or rapidity), and the camera's view surface per frame (the past
// lightcone for finite and relativistic, the hyperplane t = t_c - instant_delay for instant and
// contracted). A new motion model starts here (CONTRIBUTING.md "Adding a motion model").
#pragma once

#include "mesh4d/motion/motion.h"
#include "mesh4d/motion/camera_frame.h"
#include "mesh4d/extrude.h"
#include "mesh4d/lightcone.h"
#include "pipeline/input/scene.h"
#include "pipeline/stage/prepared_object.h"

namespace apparent {

// Lorentz for relativistic and contracted, Galilean for instant and finite.
mesh4d::Kinematics kinematicsOf(Model model);

// The motion of `object` under `model` in the lab. Precondition: the scene passed
// checkSceneForModel.
mesh4d::Motion motionOf(const ObjectSpec& object, Model model);

// What an object's motion beyond uniform (angular_velocity or acceleration, mesh4d/motion/worldline.h)
// needs, one line naming file, field and problem when refused: not both; a camera at rest; a
// tolerance (mesh4d/refine/worldline_refine.h) only for an object that exists throughout the frames (no
// real cap) and in a scene without a mirror, else vertex mode (tolerance 0). Spin: |w| <= 1e12 rad/s, every vertex slower than light, |w x q| < 1 in the centre frame
// (relativistic, contracted), |velocity + w x q| < 1 in the lab at every angle (finite); instant
// has no limit. Acceleration: |a| in [1e-12, 1e12], every vertex ahead of the Born-rigid horizon
// (q.a/|a| > -1/|a|), and the origin's rapidity at frames first_frame and last_frame within
// kMaxRapidity (gamma 1e15, as the gamma field). A keyframed path (ObjectSpec::keys): no spin or
// acceleration with it, a camera at rest, the tolerance as above, and every vertex slower than light
// over every segment (not checked for instant), refused with the vertex, its speed and the lab time.
// With an orthographic camera (finite, relativistic): uniform motion only, no mirror, and for
// finite a camera at rest.
constexpr double kMaxRapidity = 35.2;
Status checkObjectMotion(const PreparedObject& object, Model model, const Scene& scene, double tolerance,
                         long long first_frame, long long last_frame);

// The camera's worldline (scene camera.position and camera.velocity).
mesh4d::CameraMotion cameraMotionOf(const Scene& scene);

// The motion of `object` in the camera's rest frame, where every output is (camera.velocity:
// mesh4d/motion/camera_frame.h), with the Thomas-Wigner rotation of its rest points; the lab motion,
// unchanged, for a camera at rest.
mesh4d::MotionInCameraFrame cameraFrameMotionOf(const ObjectSpec& object, Model model, const Scene& scene);

// The motion of `object` in the frame its cut is computed in (buildWorld): the camera's rest frame
// (cameraFrameMotionOf), except in the finite model, whose cut is always made in the lab, where its
// light is isotropic, and sheared into the camera's frame at output (viewAt): the lab motion then.
mesh4d::MotionInCameraFrame cutMotionOf(const ObjectSpec& object, Model model, const Scene& scene);

// `rest` with the rotation of `m` applied to its points (a copy only when m.rotated).
const mesh4d::RestMesh& restInCameraFrame(const mesh4d::RestMesh& rest, const mesh4d::MotionInCameraFrame& m,
                                          mesh4d::RestMesh* storage);

// The view surface at camera time t_c, and at global frame k (t_c = frameTime(scene.frames, k)).
// Finite with a moving camera (velocity v): the lab's past cone of the camera's lab event
// (t_c, position + v t_c), with shear v, so that cuts output the camera frame's x - v t
// (lightcone.h ViewSurface::shear). In the camera's frame the object moves at w = u - v, and the
// light delay d of a point now at e relative to the camera solves |e - u d| = d (the lab's quadratic
// with the lab velocity u), its image being e - w d: the same as cutting in the lab and shearing.
// The orthographic camera (camera.projection) in finite and relativistic: the hyperplane tilted by
// the unit view direction k, t = t_c - (x - C).k (lightcone.h); instant and contracted keep t = t_c
// (their rays are parallel too, but light takes no time).
mesh4d::ViewSurface viewAt(const Scene& scene, Model model, double t_c);
mesh4d::ViewSurface viewForFrame(const Scene& scene, Model model, long long k);

}  // namespace apparent
