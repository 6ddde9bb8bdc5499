// The worldline of a rest point in the object's own frame, per kind of motion (worldline.h): the
// pieces worldline.cpp's dispatch joins, shared by spin.cpp and hyperbolic.cpp. Internal to
// mesh4d/motion/.
#pragma once

#include <cmath>

#include "mesh4d/lightcone.h"
#include "mesh4d/motion/motion.h"

namespace mesh4d {
namespace motion_detail {

// q's event at s in the object's own frame (the centre frame of a spin, the start frame of an
// acceleration: the rest frame of `velocity`, origin at the event (t0, X0)), its derivatives with
// respect to s, and the rate of q's clock.
struct Local {
    double T = 0;
    Vec3 Y;
    double dT = 1;
    Vec3 dY;
    double dtau = 1;
};

// A spin about the origin (spin.cpp); q itself without one.
Local spinLocal(const Motion& m, double s, const Vec3& q);

// Born-rigid hyperbolic motion from s = 0 on, uniform before (hyperbolic.cpp).
Local rigidLocal(const Motion& m, double s, const Vec3& q);

// gamma of `velocity` whatever the kinematics (the Galilean carry of an acceleration follows the
// origin's relativistic lab path).
inline double lorentzGamma(const Motion& m) { return 1.0 / std::sqrt(m.one_minus_beta2); }

// (g - 1)(a.u) u = v (a.v) g^2 / (g + 1): the boost's stretch along v, no division by b.
inline Vec3 stretch(const Vec3& v, double g, const Vec3& a) { return v * (dot(a, v) * (g * g / (g + 1.0))); }

// The origin's lab displacement and velocity (per unit lab time) at lab time t0 + dt, Galilean
// carry of an acceleration (hyperbolic.cpp).
void originPath(const Motion& m, double dt, Vec3* disp, Vec3* vel);

// The closed form of an accelerated point's past-cone crossing on its hyperbolic part (s > 0),
// relativistic; false when there is none (the crossing is before t0) (hyperbolic.cpp).
bool hyperbolicCrossing(const ViewSurface& view, const Motion& m, const Vec3& q, double* s_out);

}  // namespace motion_detail
}  // namespace mesh4d
