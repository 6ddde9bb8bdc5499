// The 4D bounding box of events: a time range [t_lo, t_hi] and a spatial box [lo, hi], empty
// until something is added (infinite bounds the wrong way round). Used wherever the code needs
// bounds: the per-frame cull of triangle runs (extrude.h, slice.h), the raytracer's prism bounds
// (ray4d.h), a rest mesh's size (mesh4d/motion/seen.cpp, pipeline/stage/mirror.cpp) and a frame's local
// origin (exporters/glb/write.cpp). A box of points only (addPoint) keeps its time range empty.
#pragma once

#include <algorithm>
#include <cmath>

#include "event.h"

namespace mesh4d {

struct EventBox {
    double t_lo = INFINITY, t_hi = -INFINITY;
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};

    void add(const Event& e) {
        t_lo = std::min(t_lo, e.t);
        t_hi = std::max(t_hi, e.t);
        addPoint(e.x);
    }
    // The spatial bounds alone.
    void addPoint(const Vec3& p) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    // Whether `e` lies in the box widened by `slack` on every side, time included.
    bool contains(const Event& e, double slack) const {
        return !(e.x.x < lo.x - slack || e.x.x > hi.x + slack || e.x.y < lo.y - slack || e.x.y > hi.y + slack ||
                 e.x.z < lo.z - slack || e.x.z > hi.z + slack || e.t < t_lo - slack || e.t > t_hi + slack);
    }
    // Centre and diagonal of the spatial box (meaningless while it is empty).
    Vec3 center() const { return {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)}; }
    double diagonal() const { return norm(hi - lo); }
    // The largest side of the spatial box.
    double extent() const { return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}); }
};

}  // namespace mesh4d
