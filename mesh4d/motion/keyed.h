// Keyframed paths (issue 18, item 4): an object's centre and orientation given at lab times (keys),
// interpolated linearly between them, as a glTF animation's LINEAR translation and rotation
// channels describe (pipeline/input/gltf_animation.h reads them). Plugged into worldline.h beside the spin
// and the acceleration: Motion::keyed.
//
// The authored path (KeyPath, lab frame): keys at lab times t_0 < ... < t_{n-1}, the centre X_k
// (light-seconds) and the turn Q_k (unit quaternion: the lab rotation of the body relative to its
// rest pose q). Between keys the centre moves on the straight line X_k -> X_{k+1} at constant
// lab speed and the body turns at a constant rate about one fixed axis from Q_k to Q_{k+1} (slerp,
// the shorter way round, glTF 2.0 appendix "Interpolation"). Before the first key and after the
// last the body **rests** at its end pose in the lab (glTF players hold the end values: what the
// author sees in Blender).
//
// Relativistic model (Lorentz: relativistic and contracted): a "rigid carry in the path's frame".
// Let V = (X_{n-1} - X_0) / (t_{n-1} - t_0) be the path's mean velocity (0 for one key) and F_V the
// frame moving at V whose origin is the centre's event at lab time t0 (Motion::t0, origin). Every
// key event is boosted into F_V: (sigma_k, P_k). In F_V the body is carried rigidly along the
// boosted path: rest point q is at  Y(s) = P(s) + R(s) q  at F_V time s, where P is the straight
// line between the boosted keys (a boost keeps lines straight, and keeps the fraction of a segment:
// the turn runs at a constant rate in s within a segment). The lab event is the boost of (s, Y(s))
// with V about (t0, X0): motion.h's map, as for the spin (worldline.h). Why this model:
//  - a path that turns a corner gives continuous worldlines (P and R are continuous), so the
//    output is continuous over frames; "the centre with the body contracted by its momentary
//    velocity" would jump at every corner of a linear path (the contraction changes at once);
//  - a two-key path at constant velocity v has V = v: the centre rests at F_V's origin and every
//    point's worldline is exactly the uniform model's with velocity v (between the keys);
//  - the body's shape in F_V is its rest shape: a body moving at velocities far from V is
//    contracted by V, not by its momentary velocity. That is the price of continuity: an instant
//    change of velocity (a corner) has no Born-rigid body (worldline.h's acceleration has one).
// Galilean (instant, finite): carried in the lab, x = X(t) + R(t) q, s = t - t0, as the spin.
// s is the object's time: F_V's time (Lorentz) or lab time since t0 (Galilean); `exists` reads it.
// A point's own clock reads 0 at s = 0 and runs at d tau = ds sqrt(1 - |dY/ds|^2) (Lorentz; the
// speed in F_V, so the boost needs no gamma of its own). Within a segment the speed is
//     |dY/ds|^2 = |u|^2 + w^2 rho^2 + 2 w rho (u . e(phi)),   phi = w (s - s_k),
// (u the segment's velocity in F_V, w its turn rate, rho q's distance from the turn axis, e a unit
// vector turning with q), A + B cos(phi - phi0), whose integral is an incomplete elliptic integral
// of the second kind: closed form per segment (mesh4d/elliptic.h), sqrt(1 - |u|^2) ds without a turn.
// Galilean: tau = s.
// Speeds: every rest point must be slower than light in F_V (the same condition as in the lab);
// maxKeyedSpeed gives the largest speed of a point over a segment's arc in closed form (a cosine's
// maximum over an interval), with the lab time where it is reached.
#pragma once

#include <memory>
#include <vector>

#include "mesh4d/event.h"

namespace mesh4d {

// A unit quaternion (w, x, y, z): the rotation by angle a about unit axis k is (cos a/2, k sin a/2).
struct Quat {
    double w = 1, x = 0, y = 0, z = 0;
};
Vec3 rotate(const Quat& r, const Vec3& v);
Quat multiply(const Quat& a, const Quat& b);  // a after b
Quat conjugate(const Quat& a);                // the inverse of a unit quaternion
// The turn a fraction f of the way from a to b at a constant rate about one axis, the shorter way
// round (glTF 2.0 appendix: slerp of unit quaternions): (b a^-1)^f a.
Quat slerp(const Quat& a, const Quat& b, double f);

// The authored path in the lab. Preconditions (the reader checks them): times finite and strictly
// increasing, at least one key, the same count in each vector, unit quaternions, finite positions.
struct KeyPath {
    std::vector<double> times;    // lab seconds
    std::vector<Vec3> positions;  // the centre (the mesh origin), light-seconds
    std::vector<Quat> turns;      // the body's lab rotation relative to its rest pose
};

// The path as one kinematics moves it: keys in the object's own frame (F_V or the lab, above).
// Segment j of the vectors sized n + 1 is: 0 before the first key, j between keys j - 1 and j,
// n after the last.
struct KeyedMotion {
    bool lorentz = false;
    double t0 = 0;                 // lab time of s = 0
    Vec3 origin;                   // lab position of the centre at t0
    Vec3 frame_velocity;           // V (Lorentz), 0 (Galilean)
    double gamma = 1;              // of V
    std::vector<double> s;         // the object's time at each key
    std::vector<Vec3> centre;      // P_k: the centre at each key, relative to the origin
    std::vector<Quat> turns;       // Q_k
    std::vector<Vec3> velocity;    // per segment (n + 1): dP/ds
    std::vector<Vec3> axis;        // per segment: unit turn axis (zero without a turn)
    std::vector<double> rate;      // per segment: turn rate, rad per unit s (>= 0)
    // Per segment: the trigonometry of its whole turn, the angle rate[j] (s[j] - s[j - 1]) (0 < j < n;
    // identity elsewhere), computed once: the pose at a segment's last key (the kink bound of
    // worldline_bound.h takes it at every key) then costs no sine. Bit-identical to the per-call turn.
    struct WholeTurn {
        double cos = 1, sin = 0, half_sin = 0;  // cos a, sin a, sin(a / 2)
    };
    std::vector<WholeTurn> whole_turn;
};

// The path's mean velocity between its first and last key (zero for one key): V above.
Vec3 meanVelocity(const KeyPath& path);

// The centre's lab position at lab time t (the path interpolated; the end pose outside).
Vec3 keyedCentreAt(const KeyPath& path, double t);

// The path in the object's own frame. Lorentz: boosted with `frame_velocity` about the event
// (t0, origin); precondition |frame_velocity| < 1 and every segment slower than light in the lab
// (checkKeyedCentre). Galilean: frame_velocity is ignored.
std::shared_ptr<const KeyedMotion> makeKeyedMotion(const KeyPath& path, bool lorentz, double t0, const Vec3& origin,
                                                   const Vec3& frame_velocity);

// Rest point q at the object's time s in its own frame: Y(s) (relative to the origin), dY/ds, and
// the rate of q's clock d tau/ds (1 for Galilean).
struct KeyedLocal {
    Vec3 y;
    Vec3 dy;
    double dtau = 1;
};
KeyedLocal keyedLocal(const KeyedMotion& k, double s, const Vec3& q);

// The segment holding s (the index into the vectors sized n + 1 above; a key's own time belongs to
// the segment that starts there).
size_t keyedSegment(const KeyedMotion& k, double s);

// keyedLocal with segment j's motion extended to every s: the straight line at velocity[j] and the
// turn at rate[j] about axis[j], from the pose at the segment's first key (key 0 for j = 0). So
// keyedLocal(k, s, q) is keyedSegmentLocal(k, keyedSegment(k, s), s, q), and at key i both
// segments i and i + 1 give the same y (the pose at key i) but different dy: the kink that the
// tolerance bound across a key (worldline_bound.h) takes apart.
KeyedLocal keyedSegmentLocal(const KeyedMotion& k, size_t j, double s, const Vec3& q);
// keyedSegmentLocal with q already turned by the segment's first key: p = rotate(k.turns[key], q),
// key = j - 1 (0 for j = 0). The same y and dy, bit for bit, but no clock rate (dtau is left 1);
// for callers that take several segments or times of one point and need only its pose and
// velocity (the bound of worldline_bound.cpp), so turn it once per key.
KeyedLocal keyedSegmentTurned(const KeyedMotion& k, size_t j, double s, const Vec3& p);

// q's own clock at s: the integral of d tau above from 0 to s, closed form per segment. O(keys).
double keyedProperTime(const KeyedMotion& k, double s, const Vec3& q);

// The fastest the centre moves in the lab: the largest segment speed |X_{k+1} - X_k| / (t_{k+1} - t_k),
// the lab time where that segment starts, and the segment's index (-1 for a path of one key).
struct KeyedSpeed {
    double speed = 0;
    double lab_time = 0;
    long index = -1;
};
KeyedSpeed fastestCentreSegment(const KeyPath& path);

// The largest speed of rest point q (in the own frame, over every segment's arc) and the lab time
// of the event where it is reached (the first such segment's). A point slower than light there is
// slower than light in every frame.
KeyedSpeed maxKeyedSpeed(const KeyedMotion& k, const Vec3& q);

}  // namespace mesh4d
