// The kinds of motion answered in their own file (motion.h, "Adding a kind"): each such kind gives
// every answer the pipeline asks of a motion as one row of function pointers, KindAnswers, defined
// in its file; answersOf (kinds.cpp) is the one switch over MotionKind that names the rows. The
// questions' own switches (worldline.cpp, seen.cpp, extrude.cpp, worldline_bound.cpp, the stage's
// checks in pipeline/stage/physics.cpp, the raytracer's messages) keep their cases for the kinds that
// predate the table (uniform, spin, hyperbolic, keyed) and send every other kind to its row.
#pragma once

#include <string>
#include <vector>

#include "mesh4d/motion/local.h"
#include "mesh4d/motion/motion.h"

namespace mesh4d {

struct RestMesh;  // extrude.h

struct KindAnswers {
    // The scene field that states the kind, and the object it makes, for messages ("orbit", "an
    // orbiting object").
    const char* field;
    const char* what;
    // q's event at s in the object's own frame, its s-derivatives and its clock's rate: for Lorentz
    // the frame of `velocity` (worldline.cpp boosts it to the lab), for Galilean the lab carry
    // relative to the origin X0 (T = s).
    motion_detail::Local (*local)(const Motion& m, double s, const Vec3& q);
    // The reading of q's own clock at s (Lorentz; Galilean clocks read s).
    double (*proper_time)(const Motion& m, double s, const Vec3& q);
    // The largest speed of rest point q in the object's own frame, over all s (the pad of the span
    // seen, seen.h paddedSpanSeen).
    double (*fastest)(const Motion& m, const Vec3& q);
    // Bounds over the triangle with corners q[0..2], for all s, of the own frame's rates (the list of
    // worldline_bound.h, per unit |u|): out = {T_s, Y_s, T_ss, Y_ss, T_q, Y_q, T_sq, Y_sq}.
    void (*rates)(const Motion& m, const Vec3 q[3], double out[8]);
    // The slab step's K and M (extrude.h slabSpacing) over the whole mesh and all s.
    void (*slab_rates)(const Motion& m, const RestMesh& mesh, double* K, double* M);
    // Why the rest mesh `rest` cannot move so (one line, without the field), or empty.
    std::string (*problem)(const Motion& m, const std::vector<Vec3>& rest);
};

// The row of m's kind; null for the kinds answered where they are (uniform, spin, hyperbolic, keyed).
const KindAnswers* answersOf(const Motion& m);

}  // namespace mesh4d
