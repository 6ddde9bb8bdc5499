// Worldlines: the one concept of an object's motion. A motion maps a rest point q and the
// object's own time s to a lab event, and back: the crossing of q's worldline with a view surface
// (lightcone.h) is the apparent point of q in that frame.
//
// Uniform motion (Motion::angular_velocity = 0 and acceleration = 0) is motion.h's affine map, s = tau, and keeps its
// closed forms (lightcone.h cutRestWorldline, cutRestLocal): the functions below send it there,
// bit for bit.
//
// Spin (issue 18, item 2): angular velocity w (rad/s) in the object's centre frame, about its
// origin, combined with the velocity v of the centre. The material point with rest coordinates q
// (after rotation_deg and scale) is at Y(s) = R(w s) q at centre-frame time s, where R(w s) turns
// about w/|w| by |w| s, and s = 0 at the origin's event (t0, X0): the centre-frame helix (s, Y(s)).
//   Lorentz (relativistic, contracted): the helix is boosted to the lab with v about the origin's
//     event, the standard boost of motion.h:  t = t0 + g (s + v.Y),  x = X0 + Y + (g - 1)(Y.u) u + g v s.
//   Galilean (instant, finite): carried,   t = t0 + s,  x = X0 + Y(s) + v s.
// (For both motions below, s is the centre's or start frame's time, which reads 0 at t0.)
// The point's own clock reads tau = s sqrt(1 - |w x q|^2) (Lorentz: d tau = ds sqrt(1 - |w x Y|^2),
// and |w x Y| = |w x q| is constant along the helix), s (Galilean: lab time since t0, as for
// uniform motion). A point moving at >= c has no worldline: callers refuse w with
// |w x q| >= 1 at any vertex (centre frame, Lorentz) or a lab speed >= 1 (finite; maxLabSpeed).
// At a fixed s the events of all rest points are an affine image of the rest mesh (Y is linear in
// q), so the caps where an object begins or ends existing (at s = exists bounds, the centre's
// clock) stay flat, and the straight cap edges of extrude.h lie on them exactly.
//
// Constant proper acceleration (issue 18, item 3): a = Motion::acceleration, the proper
// acceleration of the origin from t0 on, in the start frame (the rest frame of `velocity`, its axes
// the lab's carried by the boost, origin at the event (t0, X0)); before t0 the object moves
// uniformly with `velocity` (the engine starts at t0, so every past cone meets every worldline:
// pure hyperbolic motion has a horizon in the past too). The body is extended **Born-rigidly**
// along k = a/|a|: with xi = 1/|a| + q.k (q's distance to the horizon), q's start-frame worldline
// for s >= 0 is
//     T = xi sinh(|a| s),   Y = q + k xi (cosh(|a| s) - 1),
// a hyperbola of proper acceleration 1/xi, all about the same event (T, Y.k) = (0, -1/|a|). Why
// Born-rigid, not every point with the same proper acceleration (Bell's rockets): s is then the
// body's own time, the same for all its points; at each s the body has its rest shape in its
// momentary rest frame, the events at one s are that frame's simultaneity (so `exists` caps are
// flat, affine in q, and mean what they mean for uniform motion), whereas equal accelerations
// stretch the body in its own frame without bound. The price: a point at or behind the horizon
// (xi <= 0, q.k <= -1/|a|) cannot keep up; callers refuse such bodies (horizonDistance). q's
// clock reads s before t0 and xi |a| s after (a point nearer the horizon ages slower; the
// origin's reads s = asinh(|a| T)/|a| at start-frame time T). Lorentz: the start frame's events
// boosted with `velocity` about (t0, X0) (as for the spin); Galilean (instant, finite): every point
// carried along the origin's lab path, x = X0 + q + (origin's lab displacement at t), s = t - t0,
// the origin's proper time at lab time t from a quadratic in e^(|a| sigma) (closed form).
// The past-cone crossing after t0 has a closed form (relativistic): a quadratic in u = e^(|a| s)
// in the start frame (hyperbolic.cpp hyperbolicCrossing), polished by the search below; before t0
// the uniform closed form is exact. A body with both a spin and an acceleration is refused by the
// callers (not modelled).
//
// Keyframed paths (issue 18, item 4): mesh4d/motion/keyed.h, the body carried rigidly along the
// path in the frame of its mean velocity V = Motion::velocity (Lorentz: boosted about (t0, X0) as
// the spin; Galilean: carried in the lab). s is that frame's time (Lorentz) or lab time since t0;
// the clock integrates d tau = ds sqrt(1 - |dY/ds|^2) in closed form per segment. A keyframed
// path with a spin or an acceleration is refused by the callers.
//
// The crossing with a view surface (past cone t = t_c - |x - C| or hyperplane t = t_c) is the root
// of h(s) = (t_c - t(s)) - |x(s) - C| (cone) or t_c - t(s) (hyperplane). Along a timelike worldline
// with t(s) increasing, h decreases strictly (dh/ds <= -(dt/ds)(1 - speed) < 0), so the root is
// unique. crossWorldline finds it by a safeguarded Newton search: start at the closed-form crossing
// of q's worldline without the spin, bracket the root by steps that double, then Newton steps kept
// inside the bracket, with bisection whenever a step leaves it or fails to halve it. It stops when
// the Newton step is below 1e-15 max(|s|, d) (d the light delay, or 1 on a hyperplane at d = 0):
// the crossing's time is then within about 1e-14 of the delay (relative), the rounding of h at
// the root aside. At most 64 bracketing and 200 refining steps; if those run out (not seen; only
// for NaN or infinite input) the result has ok = false.
// The events are computed relative to the camera event, (X0 - C) and (t0 - t_c) summed first, so
// a spinning object near the camera keeps its shape to rounding; far ones lose
// |X0 - C| x 1e-16 absolute (the anchored forms of lightcone.h are for uniform motion only).
#pragma once

#include "mesh4d/motion/motion.h"
#include "mesh4d/event.h"
#include "mesh4d/lightcone.h"

namespace mesh4d {

// True for uniform motion (no spin, no acceleration, no keyframed path): motion.h's closed forms apply.
inline bool isUniform(const Motion& m) { return kindOf(m) == MotionKind::Uniform; }

// R(w s) q: the rest point q at centre-frame time s, relative to the origin (q itself for uniform motion).
Vec3 spunPoint(const Motion& m, double s, const Vec3& q);

// The lab event of rest point q at the object's time s (labFromRest for uniform motion).
Event worldlineEvent(const Motion& m, double s, const Vec3& q);

// The derivatives of q's worldline with respect to s at s: lab time, lab position, own clock.
struct WorldlineRate {
    double dt = 1;
    Vec3 dx;
    double dtau = 1;
};
WorldlineRate worldlineRate(const Motion& m, double s, const Vec3& q);

// The lab velocity dx/dt of rest point q at the object's time s.
Vec3 worldlineVelocity(const Motion& m, double s, const Vec3& q);

// The reading of q's own clock at the object's time s (see above).
double worldlineProperTime(const Motion& m, double s, const Vec3& q);

// The centre-frame speed of rest point q, |w x q|.
double spinSpeed(const Motion& m, const Vec3& q);

// The speed of rest point q that must stay below light for a spin: spinSpeed (Lorentz, centre
// frame), maxGalileanSpeed (Galilean carry, lab).
double spinVertexSpeed(const Motion& m, const Vec3& q);

// xi = 1/|a| + q.a/|a|: rest point q's distance to the horizon of a Born-rigid acceleration
// (infinite without one); q has a worldline only where it is > 0.
double horizonDistance(const Motion& m, const Vec3& q);

// The origin's proper time (rapidity / |a|) at lab time t0 + dt on the lab path of an accelerated
// motion (either kinematics: the path is the relativistic one), closed form; dt itself for dt <= 0.
double originProperTime(const Motion& m, double dt);

// The largest lab speed of rest point q over a turn, Galilean carry: |v + w x R q| maximised over
// the angle, sqrt(v_par^2 + (|v_perp| + |w x q|)^2) with v_par the part of v along w.
double maxGalileanSpeed(const Motion& m, const Vec3& q);

struct WorldlineCrossing {
    Event event;       // the crossing (lab)
    double s = 0;      // the object's time there
    bool ok = true;    // false only when the search ran out of steps (NaN or infinite input)
};

// The origin's own time at c, its crossing of a view (crossWorldline of q = 0): c.s (Lorentz),
// originProperTime at c's lab time (Galilean carry, whose clock is the relativistic path's).
double originTimeAtCrossing(const Motion& m, const WorldlineCrossing& c);

// The crossing of rest point q's worldline with the view surface. Uniform motion: the closed form
// (cutRestWorldline) and s from properTimeAt. Otherwise the safeguarded search above.
// Precondition: the worldline is timelike (see above).
WorldlineCrossing crossWorldline(const ViewSurface& view, const Motion& m, const Vec3& q);

// Doppler factor (received over emitted frequency) of light from q's worldline at time s, emitted
// at lab position x, reaching the camera at rest at `apex`: d tau / d t_received =
// (d tau/ds) / (dt/ds - n.dx/ds), n the unit vector from x to the camera; 1 on a hyperplane. For
// uniform motion it equals dopplerFactor of light_factors.h (1 / (g (1 - v.n))).
double worldlineDoppler(const Motion& m, ViewKind kind, const Vec3& apex, double s, const Vec3& q, const Vec3& x);

}  // namespace mesh4d
