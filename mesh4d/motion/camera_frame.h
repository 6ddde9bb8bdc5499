// A moving camera: the change from the lab frame to the camera's rest frame, applied to an
// object's uniform motion, so that the rest of the pipeline cuts, refines and exports in the
// camera's frame exactly as it does for a camera at rest.
//
// The camera's worldline is C(t) = P + v t in the lab (|v| < 1). Its rest frame keeps the event
// (t = 0, P) fixed: there the camera sits at P for all times, and its time coordinate is the
// camera's proper time (frame k is at tau_k = start + k / fps).
//
// Lorentz kinematics (relativistic, contracted): the pure boost with velocity v about (0, P),
// g = 1/sqrt(1 - |v|^2), n = v/|v|:
//     t' = g (t - v.(x - P)),      x' = P + (x - P) + (g - 1)((x - P).n) n - g v t.
// An object whose rest frame maps into the lab by the boost B(u) (lab velocity u) maps into the
// camera frame by B(-v) B(u) = B(w) R: the boost with the composed velocity
//     w = [u / g - v + (g / (1 + g)) (u.v) v] / (1 - u.v)
// after a rotation R of its rest coordinates, the Thomas-Wigner rotation. R = I when u and v are
// parallel (or either is zero); otherwise it turns about u x v. So the object moves in the camera
// frame with velocity w, through the image of its origin event, with rest points R q.
// Precision: 1 - |w|^2 = (1 - |u|^2)(1 - |v|^2) / (1 - u.v)^2 exactly, and 1 - u.v is formed as
// (1 - |v|^2) + v.(v - u), so neither a fast camera nor a nearly comoving object loses it to
// cancellation. R is the spatial block of B(-w) B(-v) B(u), multiplied in long double: its
// entries carry an absolute error of about 1e-19 g_u g_v g_w (R is exactly I, not computed, in the
// parallel case, which includes every object at rest in the lab).
//
// Galilean kinematics (instant): x' = x - v t, t' = t about the same event: w = u - v, R = I.
// The finite model maps its outputs the same way, but its light moves at c in the lab, so it is
// cut there and sheared afterwards (lightcone.h ViewSurface::shear; labRayDirection below).
//
// With v = 0 the motion is returned unchanged (bit for bit), so scenes with a camera at rest keep
// their bytes.
#pragma once

#include <array>

#include "mesh4d/motion/motion.h"

namespace mesh4d {

// 3x3 rotation, column-major (r[col * 3 + row]), acting on rest-frame points.
using Rotation3 = std::array<double, 9>;

constexpr Rotation3 kIdentityRotation{1, 0, 0, 0, 1, 0, 0, 0, 1};

inline Vec3 apply(const Rotation3& r, const Vec3& q) {
    return {r[0] * q.x + r[3] * q.y + r[6] * q.z, r[1] * q.x + r[4] * q.y + r[7] * q.z,
            r[2] * q.x + r[5] * q.y + r[8] * q.z};
}

struct CameraMotion {
    Vec3 position;        // P: the camera at lab time 0 (and in its own frame at every time)
    Vec3 velocity;        // v, lab frame, |v| < 1
    double one_minus_b2 = 1;  // 1 - |v|^2 without cancellation (robust.h oneMinusNorm2)

    bool moving() const { return velocity.x != 0 || velocity.y != 0 || velocity.z != 0; }
};

CameraMotion makeCameraMotion(const Vec3& position, const Vec3& velocity);

// The lab event e in the camera frame.
Event toCameraFrame(const CameraMotion& camera, Kinematics kinematics, const Event& e);
// The linear part of toCameraFrame: the camera-frame difference of two events whose lab
// difference is d (so that outputs in local coordinates are mapped as origin plus difference).
Event toCameraFrameDifference(const CameraMotion& camera, Kinematics kinematics, const Event& d);
// The inverse of toCameraFrame: the camera-frame event e in the lab (the boost with +v about
// (0, P): t = g (t' + v.r'), x = P + r' + (g^2 / (g + 1)) (v.r') v + g v t', r' = x' - P; Galilean
// x = x' + v t').
Event fromCameraFrame(const CameraMotion& camera, Kinematics kinematics, const Event& e);
// Its linear part, as toCameraFrameDifference.
Event fromCameraFrameDifference(const CameraMotion& camera, Kinematics kinematics, const Event& d);

struct MotionInCameraFrame {
    Motion motion;                          // the object's motion in the camera frame
    Rotation3 rotation = kIdentityRotation;  // R: rest points become R q (Thomas-Wigner)
    bool rotated = false;                   // R differs from I
};

// `lab` (an object's motion in the lab) as seen in the camera frame. Precondition: |v| < 1.
MotionInCameraFrame motionInCameraFrame(const Motion& lab, const CameraMotion& camera);

// The finite model with a moving camera (light at c in the lab; its cut is made there and sheared
// into the camera's frame, lightcone.h ViewSurface::shear): the unit lab direction d of the light
// ray the camera sees along the unit camera-frame direction k (both from the camera into the
// scene). The ray's events are (t_c - s, C + v t_c + s d) in the lab, at P + s (d + v) in the
// camera's frame, so d + v lies along k: d = a k - v with |d| = 1,
//     a = k.v + sqrt((k.v)^2 + 1 - |v|^2) > 0   (the conjugate (1 - |v|^2) / (sqrt(...) - k.v) when k.v < 0).
// This is classical aberration: a star at rest in lab direction d appears along d + v.
Vec3 labRayDirection(const CameraMotion& camera, const Vec3& k);

}  // namespace mesh4d
