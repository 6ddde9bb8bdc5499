// What the light carries from each apparent point to the camera: the Doppler factor and the
// reading of the object's own clock at the emission event (issue 17's per-vertex attributes).
//
// Doppler factor D = received / emitted frequency, for light from a point moving at velocity w
// (b = |w|) in the frame the outputs are in, reaching the camera at rest in that frame; n is the
// unit vector from the emission event's position to the camera (the view's apex):
//     Lorentz (relativistic):   D = 1 / (g (1 - w.n)),   g = 1/sqrt(1 - b^2)
//     Galilean (finite; light at c in that frame, the camera at rest in it):  D = 1 / (1 - w.n)
//       (with a moving camera the frame is the lab and D = (1 - v.n) / (1 - u.n): dopplerFactor)
//     on a hyperplane (instant, contracted: no light travel): D = 1; on a tilted one (an
//     orthographic camera, lightcone.h) the light goes along -k: n = -k (addLightFactors).
// On the line of sight D = sqrt((1 + b)/(1 - b)) approaching and sqrt((1 - b)/(1 + b)) receding;
// at right angles to w in the camera's frame D = 1/g (the transverse Doppler effect).
// 1 - w.n is formed as (1 - b^2)/(1 + b) + b |u - n|^2 / 2 (u = w/b), a sum of two non-negative
// terms, so an approaching source at b = 1 - 1e-12 keeps full relative precision (1 - b cos t
// written directly would lose it to cancellation).
//
// Proper time: the rest-frame time coordinate of the emission event of rest point q (the object's
// clocks, synchronised in its rest frame, reading 0 at the origin's event): (t_e - t0)/g - w.q for
// Lorentz kinematics (motion.h properTimeAt); lab time since t0 for Galilean ones. For uniform
// motion it equals (t_e - t0)/g - g w.z, z the point's offset from the origin at t_e.
// A motion that is not uniform (worldline.h, spin) uses the point's own worldline: D =
// (d tau/ds) / (dt/ds - n.dx/ds) at its crossing (worldlineDoppler) and the clock of
// worldlineProperTime (a spinning point's reads s sqrt(1 - |w x q|^2), s the centre-frame time).
#pragma once

#include "slice.h"

namespace mesh4d {

// D for a source moving with `m` seen from `apex`, emitting at position x. `receiver`: the
// camera's velocity in the frame of m, x and apex, which only the finite model with a moving
// camera has (that frame is the lab, the light's medium, and the camera moves through it):
//     Galilean, moving receiver v:   D = (1 - v.n) / (1 - u.n),   n from x to the camera at reception,
// the classical factor with both velocities measured against the medium (1 - v.n formed as
// 1 - u.n is); Lorentz, moving receiver: D = g_v (1 - v.n) / (g (1 - u.n)) (the frame's
// frequency received by a moving observer). The pipeline's own cuts are in the camera's frame
// (receiver zero) except finite's and the reflections a moving camera sees (pipeline/stage/mirror.h).
double dopplerFactor(const Motion& m, ViewKind kind, const Vec3& apex, const Vec3& x, const Vec3& receiver = {0, 0, 0});

// Fills m->doppler and m->proper_time (one per apparent point) for a cut of `world` by `view`.
// A sheared view (the finite model with a moving camera, lightcone.h): m's points are in the
// camera's frame; each is taken back to the lab (x + shear t) and seen by a receiver moving at
// `shear` from `apex`, the camera's lab position at reception.
void addLightFactors(const World4D& world, const ViewSurface& view, ApparentMesh* m);

}  // namespace mesh4d
