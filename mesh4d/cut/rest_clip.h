// The rest clip (cut/rest_clip.cpp, FrameBuilder::restPlan and restEmit): objects at rest on the
// past cone with a real cap and a tolerance. Its constants, the keys of its pieces and their
// helpers; the frame's state it works in is FrameBuilder's (mesh4d/cut/frame_builder.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

namespace mesh4d {
namespace slicing {

// The rest clip (restPlan): a chord of a cap's clip circle through a piece must lie within this
// fraction of the tolerance of the circle.
constexpr double kMidpointShare = 0.25;

// Step (objects at rest on the past cone, with a real cap, tolerance > 0). The surface is the
// input itself (the cut is affine), but a cap meets the cone in a sphere, so the clip curves
// are circles. A triangle a cap may cut is split in four, recursively, where a cap's curve could
// hide in a piece or its chord through the piece lies farther than T/4 from the circle
// (clipRatio), at most to 2^-depth of the triangle with 2^depth <= max_segments. Each leaf
// piece is then a convex polygon: its corners and the corners of finer neighbours on its sides
// (so the pieces of a triangle meet edge to edge), clipped at exact crossings as in vertex mode.
// Points and crossings on a mesh edge are keyed by the edge and their place along it, so the
// two triangles of the edge share those they both make; where the two split the edge
// differently they meet at T-junctions (the edge is straight: no gap). A whole mesh edge keeps
// its vertex-mode crossing (crossingPoint).
constexpr int kRestDepth = 20;                          // deepest split the keys can hold
constexpr int64_t kRestOne = int64_t(1) << kRestDepth;  // barycentric 1 in piece keys
using Key = std::pair<int64_t, int64_t>;                // barycentrics on corners 1, 2 (x 2^-20)

struct RestPiece {
    Key k[3];
};

// Pass 1 (restPlan, every triangle): the leaf pieces, and their places along the mesh edges;
// pass 2 (restEmit, once all triangles are planned): the polygons, with the corners of finer
// neighbours on every side, also across mesh edges, so the pieces meet edge to edge.
struct RestPlan {
    size_t f = 0;
    std::vector<RestPiece> leaves;
    std::set<Key> corners;
};
// The barycentrics of a key on its triangle's corners 0, 1, 2.
void barycentrics(const Key& k, double l[3]);

// The triangle corner a key is, or -1.
int cornerOf(const Key& k);

// Whether a key lies on triangle side s (0: corners 0-1, 1: 1-2, 2: 2-0), and its place along
// the side from the side's first corner.
bool onSide(const Key& k, int s, int64_t* place);
// The side a point that is no corner lies on, or -1.
int sideOfKey(const Key& k, int64_t* place);

// The key of the point at `place` along triangle side s from its first corner.
Key keyOnSide(int s, int64_t place);

// The corners strictly inside the side a -> b of a piece that its finer leaves (in `corners`)
// put there, in order (they halve the side dyadically).
void innerHanging(const Key& a, const Key& b, const std::set<Key>& corners, std::vector<Key>* out_keys);

}  // namespace slicing
}  // namespace mesh4d
