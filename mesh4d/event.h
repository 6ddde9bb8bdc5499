// Events and 3-vectors of flat spacetime.
//
// Conventions (docs/DESIGN.md section 2): c = 1, lengths in light-seconds, times in seconds, velocities
// as fractions of c. An event is (t, x) in the lab frame, the camera's rest frame. Everything is
// double; float32 appears only in exporters/, relative to a local origin.
//
// Vec3 is a plain value type with the handful of operations the geometry needs; it is not a
// linear-algebra library (Eigen is used where real linear algebra is needed).
#pragma once

#include <cmath>

namespace mesh4d {

struct Vec3 {
    double x = 0, y = 0, z = 0;

    Vec3() = default;
    constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}

    double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    Vec3 operator-() const { return {-x, -y, -z}; }
    Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
    Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
    bool operator!=(const Vec3& o) const { return !(*this == o); }
};

inline Vec3 operator*(double s, const Vec3& v) { return v * s; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm2(const Vec3& a) { return dot(a, a); }
// Euclidean length without overflow or underflow at extreme magnitudes: a sqrt((x/a)^2 + (y/a)^2 +
// (z/a)^2), a the largest magnitude (0 when a is 0). This is libstdc++'s std::hypot(x, y, z) written
// out, so that every standard library gives the same bits (libc++, the WebAssembly build's, computes
// hypot's three-argument form otherwise: docs/DESIGN.md section 14).
inline double norm(const Vec3& v) {
    const double x = std::fabs(v.x), y = std::fabs(v.y), z = std::fabs(v.z);
    const double a = x < y ? (y < z ? z : y) : (x < z ? z : x);
    if (a == 0) return 0;
    return a * std::sqrt((x / a) * (x / a) + (y / a) * (y / a) + (z / a) * (z / a));
}
inline bool isFinite(const Vec3& a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// A point of spacetime in the lab frame: time t (s) and position x (light-seconds).
struct Event {
    double t = 0;
    Vec3 x;
};

inline Event lerp(const Event& a, const Event& b, double s) {
    return {a.t + s * (b.t - a.t), a.x + s * (b.x - a.x)};
}

// Minkowski interval -(dt)^2 + |dx|^2 between two events (signature -+++): negative for timelike
// separation, positive for spacelike, zero on the light cone.
inline double interval2(const Event& a, const Event& b) {
    const double dt = b.t - a.t;
    return norm2(b.x - a.x) - dt * dt;
}

}  // namespace mesh4d
