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
};

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
