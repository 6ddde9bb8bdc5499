// Motions: the closed list of the ways an object moves, and the questions asked of a motion. This
// folder (mesh4d/motion/) is the one home of the concept: every question the pipeline asks of a
// motion is asked here, of a Motion, and each dispatches once on kindOf (a switch over MotionKind,
// so that a new kind is a compile error, -Wswitch, wherever it still needs an answer).
//
// The kinds (MotionKind), each with its derivation in the header named and its code in the file:
//   Uniform     a boost of the rest frame (below; uniform.cpp); lightcone.h keeps its closed forms.
//   Spin        an angular velocity about the origin, in the centre frame (worldline.h; spin.cpp).
//   Hyperbolic  a constant proper acceleration from t0 on, Born-rigid (worldline.h; hyperbolic.cpp,
//               latest_crossing.h for the latest crossing of a body's triangles).
//   Keyed       a keyframed path carried in the frame of its mean velocity (keyed.h; keyed.cpp).
//   Orbit       a circular orbit at constant lab speed, the body fixed or locked (Orbit below;
//               orbit.cpp, its answers as one row of kinds.h).
// The camera frame (camera_frame.h): any of them seen from the rest frame of a moving camera.
//
// The questions, one line each (declared in the header named):
//   kindOf (here)                 which kind a Motion is; isUniform (worldline.h): kindOf == Uniform.
//   mixedKinds (here)             whether a Motion states two kinds at once (callers refuse it).
//   worldlineEvent (worldline.h)  the lab event of rest point q at the object's time s.
//   worldlineRate, worldlineVelocity, worldlineProperTime, worldlineDoppler (worldline.h): its
//                                 derivatives, lab velocity, own clock and Doppler factor there.
//   crossWorldline (worldline.h)  the crossing of q's worldline with a view surface.
//   spinVertexSpeed (worldline.h) the speed of a spinning rest point that must stay below light.
//   originTimeAtCrossing (worldline.h) the origin's own time at its crossing of a view.
//   paddedSpanSeen (seen.h)       the span of the object's time a range of views sees, padded for
//                                 the extrusion of its history.
//   slabSpanSeen (seen.h)         the span a range of views sees on the history's time slabs.
//   slabSpacing, SlabGrid (extrude.h) the slab step; pieceBound (worldline_bound.h) the rates bound.
//
// Adding a kind: a row of MotionKind and its test in kindOf and mixedKinds (here), its parameters
// in KindParams (here), its answers as one KindAnswers row in its own file (kinds.h: the own-frame
// event and rates, the clock, the fastest speed, the rates bound, the slab step and the stage's
// refusals), named in answersOf (kinds.cpp, the one switch a new kind must join), and its scene
// field as one row of pipeline/input/scene_fields.cpp's table (JSON and glTF extras alike). The
// questions' switches send every kind they do not name to its row (a `default:`).
//
// Uniform motion of an object: the map from its rest frame (tau, q) into the lab frame.
//
// Relativistic (Lorentz boost with velocity v, b = |v|, g = 1/sqrt(1 - b^2), u = v/b; docs/DESIGN.md section 3):
//     t = t0 + g (tau + v.q)
//     x = X0 + q + (g - 1)(q.u) u + g v tau
// Pre-relativistic (Galilean, finite light speed only):
//     t = t0 + tau,   x = X0 + q + v tau
// q is a mesh vertex after the object's rotation and scale, tau the object's proper time (its own
// clock, reading 0 at the origin event (t0, X0)). Both maps are affine, so prisms stay prisms.
// 1 - b^2 is computed as (1 - b)(1 + b) and gamma from it, so b up to 1 - 1e-15 keeps full
// relative precision in 1/g^2.
#pragma once

#include <memory>

#include "mesh4d/event.h"

namespace mesh4d {

enum class Kinematics { Galilean, Lorentz };

struct KeyedMotion;  // keyed.h

// The parameters of the kinds answered in their own file (kinds.h), as a scene states them: a scene
// field's row in pipeline/input/scene_fields.cpp's table reads them into ObjectSpec::kinds, and motionOf
// copies them whole into Motion::kinds. Empty: none of these kinds.
//
// A circular orbit (orbit.cpp; MotionKind::Orbit). The origin is at X0 at lab time t0 and moves
// on the circle about the axis through `center` along unit `axis` k that passes through X0, in the
// plane perpendicular to k, right-handed about k, at the constant lab speed v = `speed` (0 < v < 1),
// so with angular speed w = v / R, R the distance of X0 from the axis. With e0 the radial vector from
// the axis to X0 and f0 = k x e0, the origin at lab time t0 + T is
//     P(T) = X0 + f0 sin(w T) - e0 2 sin^2(w T / 2),   moving along u(T) = (f0 cos(w T) - e0 sin(w T)) / R.
// `velocity` must be zero (the orbit is the whole motion; the callers refuse others), so the
// object's own frame is the lab. How the body is carried about its origin: rest point q is at
//     x = P(T) + Q - alpha (Q.u) u,    alpha = 1 - 1/g, g = 1/sqrt(1 - v^2),
// Q = q when `locked` is false ("fixed": the body translates along the circle without turning) and
// Q = R_k(w T) q when true ("locked": it turns with the orbit, one face to the centre); alpha = 0
// (no contraction) for the Galilean carry. So in `relativistic` the body is contracted by 1/g along
// the instantaneous velocity at each lab instant, as a keyframed path's at its own (not Born-rigid:
// no rigid body can orbit so; the contraction is the origin's, the same for every point). s, the
// object's time: the origin's clock, s = T / g (relativistic, contracted), T (Galilean carry); at
// fixed s all events are at one lab time, affine in q (exists caps stay flat). Clocks (relativistic):
// a locked body turns rigidly, so q keeps its distance rho from the axis and reads T sqrt(1 - (w
// rho)^2); a fixed body's point at distance rho_p from the origin in the orbit's plane has the speed
// |V|^2 = v^2 - 2 v A sin(theta) + A^2 (A = alpha w rho_p, theta turning at -w), and reads
//     tau = (2 sqrt(c0 + c1) / w) (E(phi1 | m) - E(phi0 | m)),  c0 = 1 - v^2 - A^2, c1 = 2 v A,
// m = 2 c1 / (c0 + c1) (E the incomplete elliptic integral of the second kind, phi1 = phi0 + w T / 2);
// the origin reads T / g. Refused by the callers: a zero axis, v outside (0, 1), X0 on the axis, any
// vertex at or above c (a locked body's rim w rho; a fixed body's v + A), an orbit with a spin, an
// acceleration or a keyframed path, a moving camera.
struct Orbit {
    Vec3 center;         // a point of the axis (lab)
    Vec3 axis{0, 0, 1};  // unit
    double speed = 0;    // the origin's lab speed v
    bool locked = false; // "orientation": "locked" (true) or "fixed"
};
struct KindParams {
    std::shared_ptr<const Orbit> orbit;  // a circular orbit; null: none
};

struct Motion {
    Kinematics kinematics = Kinematics::Galilean;
    double t0 = 0;        // lab time of the origin event
    Vec3 origin;          // lab position X0 of the rest-frame origin at t0
    Vec3 velocity;        // lab velocity v, |v| < 1 for Lorentz
    double beta = 0;      // |v|
    double gamma = 1;     // 1/sqrt(1 - b^2) (Lorentz), 1 (Galilean)
    double inv_gamma2 = 1;  // 1/g^2 = 1 - b^2 without cancellation (Lorentz), 1 (Galilean)
    // 1 - b^2 for the light-delay quadratic, in both kinematics; exact when the speed was given
    // as gamma or rapidity (makeMotionExact), else 1 - |v|^2 from the components of v with a
    // compensated sum (robust.h oneMinusNorm2: within 1 ulp, oblique velocities included).
    double one_minus_beta2 = 1;
    // Motion beyond uniform (mesh4d/motion/worldline.h, the one concept of motion): a spin about the
    // origin at this angular velocity (rad/s, in the centre frame, whose time is tau above). Zero
    // (the default): the uniform motion above, with its closed forms.
    Vec3 angular_velocity;
    // Constant proper acceleration of the origin from t0 on (mesh4d/motion/worldline.h: Born-rigid
    // hyperbolic motion, uniform before t0), in the frame of `velocity`. Zero: uniform.
    Vec3 acceleration;
    // A keyframed path (mesh4d/motion/keyed.h: the centre and the turn interpolated between lab keys,
    // carried rigidly in the frame of `velocity`, the path's mean velocity). Null: none.
    std::shared_ptr<const KeyedMotion> keyed;
    // The kinds answered in their own file (kinds.h).
    KindParams kinds;
};

// The closed list of the kinds of motion (above).
enum class MotionKind { Uniform, Spin, Hyperbolic, Keyed, Orbit };

// Which kind `m` is: Keyed with a keyframed path, else Orbit with an orbit, else Hyperbolic with a non-zero acceleration, else
// Spin with a non-zero angular velocity, else Uniform (a Motion stating two is named by the first).
inline MotionKind kindOf(const Motion& m) {
    if (m.keyed) return MotionKind::Keyed;
    if (m.kinds.orbit) return MotionKind::Orbit;
    if (m.acceleration.x != 0 || m.acceleration.y != 0 || m.acceleration.z != 0) return MotionKind::Hyperbolic;
    if (m.angular_velocity.x != 0 || m.angular_velocity.y != 0 || m.angular_velocity.z != 0) return MotionKind::Spin;
    return MotionKind::Uniform;
}

// Whether `m` states more than one of a keyframed path, an orbit, an acceleration and a spin (not
// modelled together: callers refuse such a motion).
inline bool mixedKinds(const Motion& m) {
    const bool keyed = bool(m.keyed);
    const bool accelerated = m.acceleration.x != 0 || m.acceleration.y != 0 || m.acceleration.z != 0;
    const bool spinning = m.angular_velocity.x != 0 || m.angular_velocity.y != 0 || m.angular_velocity.z != 0;
    return int(keyed) + int(bool(m.kinds.orbit)) + int(accelerated) + int(spinning) > 1;
}

// Builds a Motion. Precondition: |velocity| < 1 when kinematics == Lorentz (callers validate).
Motion makeMotion(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& velocity);

// The lab event of rest-frame point q at proper time tau.
Event labFromRest(const Motion& m, double tau, const Vec3& q);

// Proper time of rest-frame point q at lab time t (the inverse of labFromRest's time equation).
double properTimeAt(const Motion& m, const Vec3& q, double t);

// Builds a Motion from a unit direction and a speed stated without rounding 1 - b^2: one of
// gamma (>= 1) or rapidity (>= 0). b = tanh(rapidity) = sqrt((g - 1)(g + 1)) / g, and
// 1 - b^2 = 1 / g^2 exactly as stated, so gamma = 1e7 (b = 1 - 5e-15) keeps full precision where
// a velocity written as three doubles could not. Precondition: |direction| = 1.
Motion makeMotionFromGamma(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& direction, double gamma);
Motion makeMotionFromRapidity(Kinematics kinematics, double t0, const Vec3& origin, const Vec3& direction,
                              double rapidity);

// Where rest-frame point q is at lab time t: X0 + v (t - t0) + q - (1 - 1/g)(q.u) u (Lorentz),
// X0 + v (t - t0) + q (Galilean). At a fixed lab time the shape is contracted by 1/g along u.
Vec3 labPositionAt(const Motion& m, const Vec3& q, double t);

// labPositionAt(m, q, t) minus X0 + v (t - t0): q itself (Galilean) or q contracted by 1/g along
// u (Lorentz). Affine pieces kept apart so callers can add the large terms last.
Vec3 shapeOffset(const Motion& m, const Vec3& q);

// The rest-frame point q whose worldline passes through lab position x at lab time t
// (the inverse of labPositionAt in q).
Vec3 restFromLab(const Motion& m, const Vec3& x, double t);

}  // namespace mesh4d
