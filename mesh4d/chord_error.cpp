#include "chord_error.h"

#include <algorithm>
#include <cmath>

namespace mesh4d {

ChordError chordError(const ViewAnchor& anchor, const Motion& m, const Event corner[3], const Event mid[3],
                      double tolerance) {
    if (m.beta == 0) return {};
    const double t_corner[3] = {corner[0].t, corner[1].t, corner[2].t};
    const double t_mid[3] = {mid[0].t, mid[1].t, mid[2].t};
    Vec3 s[3];
    double xm[3];
    for (int i = 0; i < 3; ++i) {
        s[i] = shapeOfEvent(m, corner[i]);
        xm[i] = normMOfEvent(anchor, m, corner[i]);
    }
    return chordErrorOfTerms(m, t_corner, t_mid, s, xm, tolerance);
}

ChordError chordErrorOfTerms(const Motion& m, const double t_corner[3], const double t_mid[3], const Vec3 s[3],
                             const double xm[3], double tolerance) {
    return displacedChordError(m, m.beta, t_corner, t_mid, s, xm, tolerance);
}

ChordError displacedChordError(const Motion& m, double speed, const double t_corner[3], const double t_mid[3],
                               const Vec3 s[3], const double xm[3], double tolerance) {
    if (speed == 0) return {};  // no displacement: the map is affine
    // Delays (delta = -t) and the midpoint bubbles, |beta| (delta is convex: beta <= 0 up to rounding).
    double c[3];
    for (int e = 0; e < 3; ++e) {
        const double d0 = -t_corner[e], d1 = -t_corner[(e + 1) % 3], dm = -t_mid[e];
        c[e] = 4 * std::fabs(dm - 0.5 * (d0 + d1));
    }
    return chordErrorOfBubbles(m, speed, c, s, xm, tolerance);
}

double chordErrorFromCorners(const ViewAnchor& anchor, const Motion& m, const Event corner[3]) {
    if (m.beta == 0) return 0;
    Vec3 s[3];
    double xm[3];
    for (int i = 0; i < 3; ++i) {
        s[i] = shapeOfEvent(m, corner[i]);
        xm[i] = normMOfEvent(anchor, m, corner[i]);
    }
    return chordErrorFromSpread(cornerSpread(s, m), xm, m);
}

}  // namespace mesh4d
