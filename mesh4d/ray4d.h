// Light rays traced backwards through the static 4D world: the paper's own renderer (Black et al.
// 2007, section III.C), kept independent of the cone cut of slice.h so each can check the other.
//
// A ray leaves the camera event (t_c, C) in the unit spatial direction d and runs back in time
// along the past lightcone: R(s) = (t_c - s, C + s d), s >= 0 (c = 1, s is both the distance
// and the delay). For the hyperplane models (infinite light speed) the ray stays at t = t_c:
// R(s) = (t_c, C + s d). A mirror bounce restarts the ray at the hit event with the reflected
// direction, still running back in time.
//
// A ray meets a tetrahedron V0..V3 where R(s) = V0 + l1 (V1 - V0) + l2 (V2 - V0) + l3 (V3 - V0):
// four equations (t, x, y, z) in l1, l2, l3, s, solved by Gaussian elimination with partial
// pivoting; the hit counts when l1, l2, l3 >= 0, l1 + l2 + l3 <= 1 (within kBaryEps, so rays
// through the faces shared by neighbouring tetrahedra never slip between them) and s > 0. The
// nearest hit over all tetrahedra wins (ordinary z-buffering along the ray, docs/DESIGN.md section 8).
//
// The lab normal at the hit: all tetrahedra of a prism lie in one 3-flat of spacetime, with 4D
// normal N (the generalised cross product of three edge vectors, N . E = 0 for every tangent E).
// Its section by the lab instant t = t_hit is the object's triangle at that instant, whose tangents
// (0, w) satisfy N_x . w = 0: the spatial part N_x is the lab-frame surface normal the paper
// shades with (the contracted triangle's normal under a boost, the rest normal under a shear).
// Reference: Black et al., Am. J. Phys. 75 (2007), sections III.B-C; docs/DESIGN.md sections 6 and 8.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "event.h"
#include "extrude.h"

namespace mesh4d {

// Slack on the barycentric coordinates of a hit, relative (they are dimensionless): wide enough
// that a ray through a shared face or edge is caught by at least one neighbour, far below a pixel.
constexpr double kBaryEps = 1e-9;

struct Ray4D {
    Event origin;     // the camera event, or the event of the last bounce
    Vec3 direction;   // unit spatial direction d (from the camera into the scene)
    bool along_cone = true;  // true: R(s) = (t - s, x + s d); false: R(s) = (t, x + s d)
    Event at(double s) const { return {along_cone ? origin.t - s : origin.t, origin.x + s * direction}; }
};

struct TetHit {
    double s = 0;                  // ray parameter: distance (and, along the cone, delay) from the origin
    std::array<double, 4> bary{};  // barycentric coordinates of the hit in V0..V3
};

// The hit of `ray` with the tetrahedron v (4 events), s in (0, s_max). Empty for a miss, a
// ray parallel to the tetrahedron's 3-flat, or a degenerate tetrahedron (singular system).
std::optional<TetHit> intersectTet(const Ray4D& ray, const std::array<Event, 4>& v, double s_max);

// The 4D normal (t, x, y, z components) of the 3-flat through v0..v3: the generalised cross
// product of v1 - v0, v2 - v0, v3 - v0 (zero for a degenerate tetrahedron).
std::array<double, 4> flatNormal(const std::array<Event, 4>& v);

// One object's history prepared for tracing: per prism (input triangle) its 3-flat and the bounds
// a ray must reach, built once per model and reused for every ray of every frame.
//
// The bounding hierarchy works in co-moving coordinates (t, y = x - v t), v the object's lab
// velocity: every vertex's worldline is a straight line of velocity v in both kinematics, so y is
// constant along it and a prism's box in y is its triangle's box (not the whole sweep of the
// history), while the ray stays a straight line there: y(s) = C - v t_c + s (d + v) along the cone,
// C - v t_c + s d along t = t_c. Nodes split the prisms at the median of their box centres along
// the widest axis of those centres, down to kLeafPrisms per leaf.
struct TraceWorld {
    const World4D* world = nullptr;
    struct Prism {
        std::array<double, 4> normal{};  // 4D normal of the prism's 3-flat
        double offset = 0;               // normal . V for every event V of the prism (flat_prisms)
        // normal . V over the prism's six events lies in [offset + below, offset + above], widened
        // by 1e-8 of |normal|_1 (box diagonal + duration + largest |V| + 1): a twisted prism's
        // thickness across its first tetrahedron's 3-flat. Floats rounded outwards (8 bytes a prism,
        // not 16: a window of the rolling wheel holds 3.2 million prisms).
        float below = 0, above = 0;
        EventBox box;                    // 4D bounds of the prism's six events
    };
    std::vector<Prism> prisms;           // one per input triangle
    struct Node {
        EventBox box;                    // co-moving bounds (t, y) of the node's prisms
        uint32_t begin = 0, end = 0;     // the node's prisms: order[begin, end)
        uint32_t left = 0;               // children left and left + 1; 0: a leaf
    };
    Vec3 velocity;                       // v of the co-moving coordinates
    std::vector<Node> nodes;             // nodes[0] is the root; empty: every prism is tested (linear scan)
    std::vector<uint32_t> order;         // prism indices grouped by leaf
    // The time slabs of one history traced as one (prepareSlabsTrace): their prisms in one
    // hierarchy, which then splits along time as well as space (a ray through a spinning wheel
    // passes thousands of slabs' boxes; one hierarchy meets only the prisms near its 4D path).
    // Empty for one world (`world`).
    std::vector<const World4D*> slabs;
    std::vector<uint32_t> slab_first;    // per slab its first prism: prism p of slab k is its triangle p - slab_first[k]
    bool split_time = false;             // the hierarchy may split along t (only with slabs)
    // Each prism's three tetrahedra lie in its one 3-flat (`normal`, `offset`): true for uniform
    // motion, where the prism is the affine image of triangle x interval. A slab of a spin or a
    // keyframed turn twists its lateral quads (extrude.h slabSpacing), so its tetrahedra lie in
    // three 3-flats, all inside the convex hull of its six events: a ray is then kept only where it
    // passes through both the prism's box and the thick flat offset + below <= normal . V <= offset + above
    // ahead of the origin and nearer than the best hit so far (both hold the hull, so no hit is lost).
    bool flat_prisms = true;
};
constexpr uint32_t kLeafPrisms = 4;

// Builds the per-prism data of `world`, and the bounding hierarchy unless `hierarchy` is false (the
// linear scan, kept as the benchmarks' and tests' peer). `world` must outlive the result.
TraceWorld prepareTrace(const World4D& world, bool hierarchy = true);

// The same over the slabs of one history (extrude.h extrudeSlabs; one motion): one hierarchy over
// all their prisms, splitting along the widest of t and the co-moving axes. Empty slabs are left out.
// The slabs must outlive the result.
TraceWorld prepareSlabsTrace(const std::vector<const World4D*>& slabs);

struct WorldHit {
    double s = 0;           // ray parameter of the hit
    Event event;            // the hit event: emission time and lab position
    uint32_t triangle = 0;  // input triangle (prism) hit, in its slab's mesh
    uint32_t slab = 0;      // the slab hit (TraceWorld::slabs; 0 for one world)
    Vec3 lab_normal;        // unit lab-frame normal of that triangle at the hit's lab instant, turned
                            // towards the side the ray arrives from in 4D (N . D < 0, D = dR/ds): the
                            // outward normal wherever a closed surface is seen from outside
    Vec3 rest_point;        // the rest point of the hit: its tetrahedron's barycentric mix of rest vertices
    double own_time = 0;    // the object's time s there: the same mix of the world's tau_a and tau_b
};

// The nearest hit of `ray` with any tetrahedron of `trace`, s in (0, s_max). Empty for a miss.
// The hierarchy and the linear scan find the same nearest hit (a test checks it).
std::optional<WorldHit> intersectWorld(const TraceWorld& trace, const Ray4D& ray, double s_max);

}  // namespace mesh4d
