#include "mesh4d/motion/camera_frame.h"

#include "mesh4d/robust.h"

namespace mesh4d {

namespace {

// The boost B(b) of velocity b (|b| < 1) as a 4x4 matrix on (t, x) in long double: it maps the
// rest coordinates (tau, q) of a frame moving at b to (g (tau + b.q), q + g^2/(g + 1) (b.q) b + g b tau).
using Mat4 = long double[4][4];

void boostMatrix(const Vec3& b, long double one_minus_b2, Mat4 out) {
    const long double g = 1.0L / std::sqrt(one_minus_b2);
    const long double bb[3] = {b.x, b.y, b.z};
    const long double k = g * g / (g + 1.0L);  // (g - 1) / b^2 without cancellation
    out[0][0] = g;
    for (int i = 0; i < 3; ++i) {
        out[0][i + 1] = g * bb[i];
        out[i + 1][0] = g * bb[i];
        for (int j = 0; j < 3; ++j) out[i + 1][j + 1] = (i == j ? 1.0L : 0.0L) + k * bb[i] * bb[j];
    }
}

void multiply(const Mat4 a, const Mat4 b, Mat4 out) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            long double s = 0;
            for (int k = 0; k < 4; ++k) s += a[i][k] * b[k][j];
            out[i][j] = s;
        }
}

}  // namespace

CameraMotion makeCameraMotion(const Vec3& position, const Vec3& velocity) {
    CameraMotion c;
    c.position = position;
    c.velocity = velocity;
    c.one_minus_b2 = oneMinusNorm2(velocity.x, velocity.y, velocity.z);
    return c;
}

Event toCameraFrame(const CameraMotion& camera, Kinematics kinematics, const Event& e) {
    if (!camera.moving()) return e;
    const Vec3& v = camera.velocity;
    if (kinematics == Kinematics::Galilean) return {e.t, e.x - v * e.t};
    const double g = 1.0 / std::sqrt(camera.one_minus_b2);
    const Vec3 r = e.x - camera.position;
    const double rv = dot(r, v);
    return {g * (e.t - rv), camera.position + r + v * (g * g / (g + 1.0) * rv) - v * (g * e.t)};
}

namespace {
// The boost (Lorentz) or shear (Galilean) with velocity b on an event difference d.
Event boostDifference(const Vec3& b, double one_minus_b2, Kinematics kinematics, const Event& d) {
    if (kinematics == Kinematics::Galilean) return {d.t, d.x - b * d.t};
    const double g = 1.0 / std::sqrt(one_minus_b2);
    const double rb = dot(d.x, b);
    return {g * (d.t - rb), d.x + b * (g * g / (g + 1.0) * rb) - b * (g * d.t)};
}
}  // namespace

Event toCameraFrameDifference(const CameraMotion& camera, Kinematics kinematics, const Event& d) {
    if (!camera.moving()) return d;
    return boostDifference(camera.velocity, camera.one_minus_b2, kinematics, d);
}

Event fromCameraFrameDifference(const CameraMotion& camera, Kinematics kinematics, const Event& d) {
    if (!camera.moving()) return d;
    return boostDifference(-camera.velocity, camera.one_minus_b2, kinematics, d);
}

Event fromCameraFrame(const CameraMotion& camera, Kinematics kinematics, const Event& e) {
    if (!camera.moving()) return e;
    const Event d = fromCameraFrameDifference(camera, kinematics, {e.t, e.x - camera.position});
    return {d.t, camera.position + d.x};
}

MotionInCameraFrame motionInCameraFrame(const Motion& lab, const CameraMotion& camera) {
    MotionInCameraFrame out;
    if (!camera.moving()) {
        out.motion = lab;
        return out;
    }
    const Vec3& u = lab.velocity;
    const Vec3& v = camera.velocity;
    // Step: the origin event, a point of the object's rest frame, in the camera frame.
    const Event origin = toCameraFrame(camera, lab.kinematics, {lab.t0, lab.origin});
    if (lab.kinematics == Kinematics::Galilean) {
        out.motion = makeMotion(Kinematics::Galilean, origin.t, origin.x, u - v);
        return out;
    }
    // Step: the composed velocity, and 1 - |w|^2 from the exact identity.
    const double g = 1.0 / std::sqrt(camera.one_minus_b2);
    const double uv = dot(u, v);
    const double one_minus_uv = camera.one_minus_b2 + dot(v, v - u);
    const Vec3 w = (u / g - v + v * (g / (1.0 + g) * uv)) / one_minus_uv;
    const double one_minus_w2 = lab.one_minus_beta2 * camera.one_minus_b2 / (one_minus_uv * one_minus_uv);
    out.motion = makeMotion(Kinematics::Lorentz, origin.t, origin.x, w);
    out.motion.one_minus_beta2 = one_minus_w2;
    out.motion.inv_gamma2 = one_minus_w2;
    out.motion.gamma = 1.0 / std::sqrt(one_minus_w2);
    // Step: the Thomas-Wigner rotation R = spatial block of B(-w) B(-v) B(u); I when u || v.
    const Vec3 axis = cross(u, v);
    if (axis.x == 0 && axis.y == 0 && axis.z == 0) return out;
    Mat4 bw, bv, bu, tmp, m;
    boostMatrix(-w, one_minus_w2, bw);
    boostMatrix(-v, camera.one_minus_b2, bv);
    boostMatrix(u, lab.one_minus_beta2, bu);
    multiply(bv, bu, tmp);
    multiply(bw, tmp, m);
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row) out.rotation[size_t(col * 3 + row)] = double(m[row + 1][col + 1]);
    out.rotated = out.rotation != kIdentityRotation;
    return out;
}

Vec3 labRayDirection(const CameraMotion& camera, const Vec3& k) {
    if (!camera.moving()) return k;
    const Vec3& v = camera.velocity;
    const double kv = dot(k, v);
    const double root = std::sqrt(kv * kv + camera.one_minus_b2);
    const double a = kv >= 0 ? kv + root : camera.one_minus_b2 / (root - kv);
    const Vec3 d = k * a - v;
    return d / norm(d);  // unit already to rounding
}

}  // namespace mesh4d
