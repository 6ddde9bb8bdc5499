// The view hypersurfaces a frame is cut with, and the exact cuts of worldlines and segments.
//
// Past lightcone of the camera event (t_c, C): the events with t = t_c - |x - C| (past sheet only,
// c = 1). Hyperplane: the events with t = t_c (infinite light speed), or, tilted by the unit view
// direction k of an orthographic camera, the null hyperplane t = t_c - (x - C).k: the emissions of
// the light that crosses the image plane (through C, normal to k) at t_c travelling along -k, the
// far-field limit of the cone (Terrell 1959, Penrose 1959). For all three we use the side function
//     h(E) = (t_c - E.t) - |E.x - C|   (cone)      h(E) = (t_c - E.t) - (E.x - C).k   (hyperplane, k = 0 untilted)
// h > 0: E is inside the past cone (its light has already passed the camera); h < 0: E is still
// outside it (in the future of the view surface); h = 0: on the surface.
//
// A subluminal worldline x(t) = a + v (t - t_a) meets the past cone exactly once (h decreases
// strictly along it, at rate <= -(1 - |v|)). With e = a + v (t_c - t_a) - C, where the point is
// "now" seen from the camera, the light delay d = t_c - t_e >= 0 is the non-negative root of
//     (1 - b^2) d^2 + 2 (e.v) d - |e|^2 = 0,
// taken in the cancellation-free form of docs/DESIGN.md section 5:
//     s = sqrt((e.v)^2 + (1 - b^2)|e|^2);  e.v >= 0: d = |e|^2 / (e.v + s);  else d = (s - e.v)/(1 - b^2).
// The apparent point is y = C + e - v d. A point at the camera (e = 0) gives d = 0, y = C.
// On the tilted hyperplane h is affine, and the delay is linear: t_c - d = t_c - (e - v d).k gives
//     d = e.k / (1 + v.k)      (1 + v.k >= 1 - |v| > 0),     y = C + e - v d,
// so the cut of a uniformly moving body is an affine image of its rest shape: with v normal to k,
// its projection along k is that of the body turned by asin|v| about k x v (Terrell's rotation).
// A spacelike segment whose end events lie on opposite sides (h changes sign) crosses the view
// surface exactly once, because h is concave along any segment (affine minus a norm); the crossing
// is the root of a quadratic in the segment parameter, chosen on the past sheet.
// Reference: Black et al., Am. J. Phys. 2007, section III.B; docs/DESIGN.md sections 5 and 6.
#pragma once

#include "motion/motion.h"
#include "event.h"

namespace mesh4d {

enum class ViewKind { PastCone, Hyperplane };

struct ViewSurface {
    ViewKind kind = ViewKind::PastCone;
    double t_c = 0;  // camera time of the frame
    Vec3 apex;       // camera position C (unused for the hyperplane)
    // The Galilean map applied to what a cut outputs (the finite model with a moving camera:
    // physics.h viewAt). The surface above and every function of this file live in the frame of
    // the light's medium (the lab, where the cone is round; apex = the camera's lab position at
    // t_c); slice.h's outputs are the events (t, x - shear t) of the camera's frame. Zero: outputs
    // in the cut's own frame (every other case).
    Vec3 shear{0, 0, 0};
    bool sheared() const { return shear.x != 0 || shear.y != 0 || shear.z != 0; }
    // A Hyperplane's tilt: the orthographic camera's unit view direction k (the null hyperplane
    // above); zero: the hyperplane t = t_c. Only uniform motion is cut on a tilted hyperplane
    // (pipeline/input/scene.cpp checkSceneForModel refuses the rest).
    Vec3 tilt{0, 0, 0};
    bool tilted() const { return tilt.x != 0 || tilt.y != 0 || tilt.z != 0; }
};

// Side function h(E) above.
double viewSide(const ViewSurface& view, const Event& e);

// Light delay d >= 0 for a point seen from the camera at relative position e ("now" minus C),
// moving at v with 1 - |v|^2 = one_minus_b2 > 0. Relative error a few ulps (no cancellation).
double retardedDelay(const Vec3& e, const Vec3& v, double one_minus_b2);

struct WorldlineCut {
    Event event;  // the crossing: emission time and apparent position
};

// The crossing of the worldline through `anchor` with velocity v (|v| < 1) and the view surface.
// one_minus_b2 = 1 - |v|^2 computed without cancellation by the caller.
WorldlineCut cutWorldline(const ViewSurface& view, const Event& anchor, const Vec3& v, double one_minus_b2);

// The crossing of the worldline of rest point q (an object moving with `m`) with the view surface,
// from where the point is at t_c relative to the camera: e = (X0 - C) + v (t_c - t0) + shape(q),
// the large terms summed first and once (docs/DESIGN.md section 5's e). Anchoring at an event far
// from t_c instead would make e a difference of large numbers, whose rounding the light delay
// then multiplies by up to 2 gamma^2. `now_base` = (X0 - C) + v (t_c - t0), computed once a frame.
// A motion that is not uniform (mesh4d/motion/worldline.h) is sent to crossWorldline by this function,
// viewAnchor, cutRestLocal and cutRestLocalBatch; uniform motion keeps the closed forms below.
Vec3 nowBase(const ViewSurface& view, const Motion& m);
Event cutRestWorldline(const ViewSurface& view, const Motion& m, const Vec3& now_base, const Vec3& q);

// Per-object origins (docs/DESIGN.md section 5, "scale"): an object far from the camera (|e| ~ 1e9) but
// small (|shape| ~ 1e-6) would lose its shape to the rounding of C + e - v d, and of e itself.
// Instead the cut is anchored once per frame at the object's origin, d = D + delta, with
//     D    the delay of the origin (e = E = now_base), S = sqrt((E.v)^2 + (1 - b^2)|E|^2),
//     Y0 = E - v D  the apparent position of the origin relative to C,
// and for rest point q with s = shape(q), subtracting the origin's quadratic from the point's:
//     (1 - b^2) delta^2 + 2 B delta - K = 0,   B = S + s.v,   K = 2 s.Y0 + |s|^2,
// whose physical root is delta = K / (B + sqrt(B^2 + (1 - b^2) K)) (B >= 0; otherwise the
// conjugate form). The apparent point relative to the anchor is s - v delta, emitted delta before
// the origin's emission: no term of the size of the distance enters the shape. (Clip points
// where an object begins or ends existing are images of rest points too, so they stay exactly on
// the surface; only where along the cap edge they fall is found from the absolute 4D events.)
struct ViewAnchor {
    Vec3 origin;             // lab position the local coordinates are relative to: C + Y0
    double time_origin = 0;  // lab time local emission times are relative to: t_c - D
    Vec3 y0;                 // Y0 (cone) or E (hyperplane), relative to the camera
    double S = 0;
    bool cone = true;
    // On a tilted hyperplane: k / (1 + v.k), so that the point at s from the origin emits
    // delta = s.lean before the origin does (its image s - v delta); zero otherwise.
    Vec3 lean{0, 0, 0};
    bool tilted = false;
    // A motion that is not uniform (worldline.h) is cut by crossWorldline on this view, its result
    // taken relative to origin and time_origin (the crossing of the origin's worldline).
    ViewSurface view;
};
ViewAnchor viewAnchor(const ViewSurface& view, const Motion& m);
// The cut of rest point q's worldline in the anchor's local coordinates: {-delta, s - v delta}.
Event cutRestLocal(const ViewAnchor& anchor, const Motion& m, const Vec3& q);
// The same for n points at once (the vertex-mode fast path): bit-identical to n calls.
void cutRestLocalBatch(const ViewAnchor& anchor, const Motion& m, const Vec3* q, size_t n, Vec3* positions,
                       double* times);

// The parameter s in [0, 1] where the segment p0 -> p1 crosses the view surface.
// Precondition: viewSide(p0) and viewSide(p1) have opposite signs or one is zero; the segment is
// spacelike or lies in a hyperplane of constant t. Returns the root of the exact quadratic
// (cone) or linear (hyperplane) equation, clamped to [0, 1]; if rounding moves the quadratic's
// root off the past sheet or out of the segment, bisection on h decides instead.
double cutSegment(const ViewSurface& view, const Event& p0, const Event& p1);

}  // namespace mesh4d
