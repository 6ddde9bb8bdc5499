// `apparent trade SCENE [--model M] [--frames A:B] [--out DIR]`: the speed-accuracy trade measured
// on the user's own scene, against what a user would pick instead.
//
// Three families of output, each cut from the same scene, frames and model, on one thread:
//   vertex     exact vertices joined by straight edges (--tolerance vertex, what per-vertex
//              engines do);
//   uniform k  every input triangle split 4-to-1 at its edge midpoints k times, then vertex mode
//              (mesh4d/refine/subdivide.h: OpenRelativity's ObjectMeshDensity), k = 1 .. --levels;
//   T          the adaptive refinement at tolerance T (slice.h), a ladder of T = 1e-1, 3e-2,
//              1e-2, ... 1e-4 x the largest moving object's size (its bounding-box diagonal;
//              objects at rest are never refined).
// Each row reports the measured two-sided error (mesh4d/refine/measure.h: sampled output points against
// the exact surface and exact-surface lattice points against the output, the largest over the
// objects and frames) in both of measure.h's senses: parametric (twoSided: each output point
// against the exact image of its own rest point; the column "error") and geometric
// (geometricTwoSided: against the nearest point of the other surface; the column "geometric",
// what --tolerance promises), output triangles per frame, the time of the cut per frame (all objects,
// refinement included, repeated until at least 2 ms are timed; CPU time of the thread, so that
// other load on the machine does not count), the time to convert a frame for
// the .glb (the real writer's per-frame work: crease split, normals, float32; timed the same way,
// the file's fixed costs left out) and the .glb bytes per frame (the frames written to a temporary
// file, then removed). End to end is the sum of the two times. It prints the table, writes DIR/trade.csv and, with gnuplot installed,
// DIR/trade.png (log-log error against time, one curve per family; DIR/trade.gp regenerates it),
// and names the tolerance that gives the least time for vertex mode's error and for a tenth of it.
//
// Frames: A:B measures every frame in [A, B); without it, five frames evenly spaced over the
// scene. Rows whose output would pass --max-triangles per frame are skipped and said so.
// The instant model, and the contracted model when every object moves uniformly, map the rest
// mesh affinely (a hyperplane cut): vertex mode is exact there, and the command says so instead of
// measuring.
// Motions beyond uniform (mesh4d/motion/worldline.h: spinning and rolling bodies, Born-rigid acceleration,
// keyframed paths) are measured the same way, the tolerance rows refined by worldline_refine.h
// (keyframed: after key_split.h) and the exact surface found from the true worldlines by
// measure.h's own root search (crossingBySearch); an object that cannot take a tolerance (one that
// begins or ends existing within the frames, one seen in a mirror: physics.h checkObjectMotion) is
// refused with that line.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "pipeline/stage/stage.h"

namespace apparent {

struct TradeSettings {
    StageOptions stage;        // scene, --model (one model; default the scene's), --frames, limits
    bool has_frames = false;   // --frames A:B given; otherwise five frames spread over the scene
    std::string out_dir = "out";
    int levels = 4;                       // uniform subdivision levels 1..levels
    std::vector<double> tolerances_rel;   // empty: 1e-1, 3e-2, ... 1e-4 x size
    long long max_triangles = 4'000'000;  // per frame; larger rows are skipped
    bool quiet = false;
};

// One measured row of the table.
struct TradeRow {
    std::string family;      // "vertex", "uniform", "tolerance"
    double parameter = 0;    // uniform: level; tolerance: T in light-seconds
    double error = 0;        // measured two-sided parametric error, light-seconds (measure.h twoSided)
    double geometric_error = 0;  // measured two-sided geometric distance, light-seconds (measure.h geometricTwoSided)
    double triangles = 0;    // output triangles per frame (mean)
    double seconds = 0;      // cut time per frame (mean), refinement included
    double export_seconds = 0;  // .glb conversion per frame (GlbSequenceWriter::prepare)
    double glb_bytes = 0;    // .glb bytes per frame
    bool skipped = false;    // over max_triangles
    double total() const { return seconds + export_seconds; }
};

// Runs the measurement; returns an exit code (0, 2 bad input, 3 output could not be written).
int trade(const TradeSettings& settings, std::ostream& out, std::ostream& err);

// The row of least time end to end (cut and .glb) whose error is at most `error` (nullptr if none).
const TradeRow* cheapestWithin(const std::vector<TradeRow>& rows, double error);

}  // namespace apparent
