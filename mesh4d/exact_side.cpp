// The only translation unit of mesh4d that includes CGAL (slow to compile): keep it small.
#include "exact_side.h"

#include <CGAL/MP_Float.h>

#include <cmath>

namespace mesh4d {

namespace {
thread_local long long fallbacks = 0;

int signOf(const CGAL::MP_Float& v) {
    return v > CGAL::MP_Float(0) ? 1 : (v < CGAL::MP_Float(0) ? -1 : 0);
}
}  // namespace

long long exactSideFallbacks() { return fallbacks; }

int viewSideSign(const ViewSurface& view, const Event& e) {
    // Step 1: the filter. With u = 2^-53, fl(dt) and each fl(dx_i) are within u of their values,
    // the sum of squares within 4u, the root within 3u more and the final difference within u:
    // |h - fl(h)| <= 8u (|dt| + |dx|) generously; 1e-15 > 8u covers it.
    const double dt = view.t_c - e.t;
    if (view.kind == ViewKind::Hyperplane && view.tilted()) {
        // The null hyperplane: h = dt - (x - C).k, filtered as the cone's (|k| = 1), then exact.
        const Vec3 dx = e.x - view.apex;
        const double along = dot(dx, view.tilt);
        const double h = dt - along;
        const double bound = 1e-15 * (std::fabs(dt) + std::fabs(dx.x) + std::fabs(dx.y) + std::fabs(dx.z));
        if (h > bound) return 1;
        if (h < -bound) return -1;
        if (!std::isfinite(h)) return h > 0 ? 1 : -1;
        ++fallbacks;
        using MP = CGAL::MP_Float;
        const MP exact = (MP(view.t_c) - MP(e.t)) - (MP(e.x.x) - MP(view.apex.x)) * MP(view.tilt.x) -
                         (MP(e.x.y) - MP(view.apex.y)) * MP(view.tilt.y) - (MP(e.x.z) - MP(view.apex.z)) * MP(view.tilt.z);
        return signOf(exact);
    }
    if (view.kind == ViewKind::Hyperplane) {
        // One subtraction of doubles: its sign is exact (Sterbenz; the rounded difference is zero
        // only if the exact one is).
        return dt > 0 ? 1 : (dt < 0 ? -1 : 0);
    }
    const Vec3 dx = e.x - view.apex;
    const double r = norm(dx);
    const double h = dt - r;
    const double bound = 1e-15 * (std::fabs(dt) + r);
    if (h > bound) return 1;
    if (h < -bound) return -1;
    if (!std::isfinite(h)) return h > 0 ? 1 : -1;  // NaN or infinities: no exact answer to give

    // Step 2: exact arithmetic on the doubles themselves.
    ++fallbacks;
    using MP = CGAL::MP_Float;
    const MP edt = MP(view.t_c) - MP(e.t);
    const MP ex = MP(e.x.x) - MP(view.apex.x), ey = MP(e.x.y) - MP(view.apex.y), ez = MP(e.x.z) - MP(view.apex.z);
    const int s_dt = signOf(edt);
    const MP r2 = ex * ex + ey * ey + ez * ez;
    if (s_dt <= 0) return (s_dt < 0 || signOf(r2) > 0) ? -1 : 0;
    return signOf(edt * edt - r2);
}

}  // namespace mesh4d
