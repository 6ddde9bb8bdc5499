// Tests of the temporal extrusion: prisms of three tetrahedra forming a conforming complex.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "mesh4d/extrude.h"
#include "test_meshes.h"

using namespace mesh4d;

namespace {
std::set<std::pair<uint32_t, uint32_t>> tetEdges(const std::array<uint32_t, 4>& t) {
    std::set<std::pair<uint32_t, uint32_t>> e;
    for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) e.insert(std::minmax(t[a], t[b]));
    return e;
}
}  // namespace

TEST(Extrude, EventsLieOnTheWorldlinesAtBothCaps) {
    const RestMesh mesh = testmesh::icosphere(1, 2.0);
    const Motion m = makeMotion(Kinematics::Lorentz, 1.0, {3, 0, -20}, {0.5, 0.2, 0});
    const World4D w = extrude(mesh, m, -3.0, 4.0, true, false);
    ASSERT_EQ(w.events.size(), 2 * mesh.positions.size());
    ASSERT_EQ(w.tetCount(), 3 * mesh.triangles.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        EXPECT_NEAR(properTimeAt(m, mesh.positions[i], w.events[2 * i].t), -3.0, 1e-12);
        EXPECT_NEAR(properTimeAt(m, mesh.positions[i], w.events[2 * i + 1].t), 4.0, 1e-12);
        // The lateral edge is timelike: the worldline of a subluminal point.
        EXPECT_LT(interval2(w.events[2 * i], w.events[2 * i + 1]), 0);
    }
    // Euler: every edge appears once, V - E + F = 2 for the sphere.
    EXPECT_EQ(long(mesh.positions.size()) - long(w.edges.size()) + long(mesh.triangles.size()), 2);
}

// Neighbouring prisms choose the same diagonal on their shared lateral quad: the one from the
// lower vertex id at cap a to the higher id at cap b, and never the other.
TEST(Extrude, SharedLateralQuadsUseTheSameDiagonal) {
    const RestMesh mesh = testmesh::torus(9, 7, 3.0, 1.0);
    const World4D w = extrude(mesh, makeMotion(Kinematics::Galilean, 0, {}, {0.3, 0, 0}), 0, 1, false, false);
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
        std::set<std::pair<uint32_t, uint32_t>> edges;
        for (int k = 0; k < 3; ++k)
            for (auto e : tetEdges(w.tet(3 * f + k))) edges.insert(e);
        for (int c = 0; c < 3; ++c) {
            const uint32_t lo = std::min(mesh.triangles[f][c], mesh.triangles[f][(c + 1) % 3]);
            const uint32_t hi = std::max(mesh.triangles[f][c], mesh.triangles[f][(c + 1) % 3]);
            EXPECT_TRUE(edges.count({2 * lo, 2 * hi + 1})) << "face " << f << " edge " << lo << "-" << hi;
            EXPECT_FALSE(edges.count({2 * lo + 1, 2 * hi})) << "face " << f << " edge " << lo << "-" << hi;
        }
    }
}

// The three tetrahedra tile the prism: in the prism's parameter space (triangle barycentrics
// and s in [0, 1] along the worldlines) a random point lies in exactly one of them, and the
// three volumes add up to the prism's.
TEST(Extrude, ThreeTetsTileThePrism) {
    RestMesh tri;
    tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (auto order : {std::array<uint32_t, 3>{0, 1, 2}, {2, 0, 1}, {1, 2, 0}}) {
        tri.triangles = {order};
        const World4D w = extrude(tri, makeMotion(Kinematics::Galilean, 0, {}, {}), 0, 1, false, false);
        // Parameter-space coordinates of event 2 i + cap: (x, y) of the rest vertex, and cap as s.
        auto param = [&](uint32_t ev) {
            const Vec3& p = tri.positions[ev / 2];
            return Vec3{p.x, p.y, double(ev % 2)};
        };
        double volume = 0;
        std::vector<std::array<Vec3, 4>> tets;
        for (size_t i = 0; i < w.tetCount(); ++i) {
            const auto t = w.tet(i);
            std::array<Vec3, 4> v{param(t[0]), param(t[1]), param(t[2]), param(t[3])};
            volume += std::fabs(dot(v[1] - v[0], cross(v[2] - v[0], v[3] - v[0]))) / 6;
            tets.push_back(v);
        }
        EXPECT_NEAR(volume, 0.5, 1e-15);  // triangle area 1/2 times height 1
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<double> u(0, 1);
        for (int i = 0; i < 1000; ++i) {
            double a = u(rng), b = u(rng);
            if (a + b > 1) { a = 1 - a; b = 1 - b; }
            const Vec3 p{a, b, u(rng)};
            int inside = 0;
            for (const auto& v : tets) {
                const double vol = dot(v[1] - v[0], cross(v[2] - v[0], v[3] - v[0]));
                bool in = true;
                for (int k = 0; k < 4 && in; ++k) {
                    auto w4 = v;
                    w4[k] = p;
                    in = dot(w4[1] - w4[0], cross(w4[2] - w4[0], w4[3] - w4[0])) / vol >= -1e-12;
                }
                inside += in;
            }
            EXPECT_EQ(inside, 1) << "point " << i;
        }
    }
}

TEST(Extrude, SpanSeenCoversEveryFrameBetween) {
    const RestMesh mesh = testmesh::icosphere(1, 1.0);
    const Motion m = makeMotion(Kinematics::Lorentz, 0, {-10, 0, -20}, {0.9, 0, 0});
    const ViewSurface first{ViewKind::PastCone, 0.0, {}}, last{ViewKind::PastCone, 30.0, {}};
    const ProperTimeSpan span = spanSeen(mesh, m, first, last);
    const double one_minus_b2 = (1 - 0.9) * (1 + 0.9);
    for (double t_c = 0; t_c <= 30; t_c += 0.5) {
        for (const Vec3& q : mesh.positions) {
            const double t_e = cutWorldline({ViewKind::PastCone, t_c, {}}, labFromRest(m, 0, q), m.velocity,
                                            one_minus_b2).event.t;
            const double tau = properTimeAt(m, q, t_e);
            EXPECT_GE(tau, span.lo - 1e-12);
            EXPECT_LE(tau, span.hi + 1e-12);
        }
    }
}

// Edges are numbered in order of first appearance over the slots (edge c of triangle f is slot
// 3 f + c) and each edge's slots of non-degenerate triangles form one cycle in triangle order:
// checked against a direct computation with a map, on a mesh with three triangles on one edge,
// a triangle with a repeated index and shuffled faces.
TEST(Extrude, EdgeNumberingAndSlotCyclesFollowTheTriangleOrder) {
    RestMesh mesh = testmesh::torus(7, 5, 3.0, 1.0);
    mesh.triangles.push_back({0, 1, 7});    // a third triangle on edge 0-1
    mesh.triangles.push_back({4, 4, 9});    // a repeated index
    std::mt19937 rng(3);
    std::shuffle(mesh.triangles.begin(), mesh.triangles.end(), rng);
    const World4D w = extrude(mesh, makeMotion(Kinematics::Galilean, 0, {}, {0.3, 0, 0}), 0, 1, false, false);
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> number;
    std::map<uint32_t, std::vector<uint32_t>> slots_of;  // edge -> slots of non-degenerate triangles
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        const auto& t = mesh.triangles[f];
        const bool degenerate = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
        for (uint32_t c = 0; c < 3; ++c) {
            const auto key = std::minmax(t[c], t[(c + 1) % 3]);
            const uint32_t e = number.emplace(key, uint32_t(number.size())).first->second;
            ASSERT_EQ(w.triangle_edges[f][c], e) << f << " " << c;
            ASSERT_EQ(w.edges[e].lo, key.first);
            ASSERT_EQ(w.edges[e].hi, key.second);
            if (!degenerate) slots_of[e].push_back(3 * f + c);
            else EXPECT_EQ(w.slot_next[3 * f + c], 3 * f + c);
        }
    }
    ASSERT_EQ(w.edges.size(), number.size());
    for (const auto& [e, slots] : slots_of)
        for (size_t k = 0; k < slots.size(); ++k) EXPECT_EQ(w.slot_next[slots[k]], slots[(k + 1) % slots.size()]) << e;
}

// The per-frame cull's triangle chunks: each chunk's two cap boxes are exactly the EventBox of
// its triangles' cap events (extrude takes them two doubles at a time; here EventBox::add, one
// event after another), the chunks cover the triangles in order, kChunkTriangles each.
TEST(Extrude, ChunkBoxesAreTheBoxesOfTheirTrianglesEvents) {
    const RestMesh mesh = testmesh::icosphere(3, 1.5);  // 1280 triangles: five chunks, the last partial
    const Motion m = makeMotion(Kinematics::Lorentz, 1.0, {3, -1, -20}, {0.5, 0.2, -0.1});
    const World4D w = extrude(mesh, m, -3.0, 4.0, true, false);
    ASSERT_EQ(w.chunks.size(), (mesh.triangles.size() + kChunkTriangles - 1) / kChunkTriangles);
    for (size_t k = 0; k < w.chunks.size(); ++k) {
        const TriangleChunk& c = w.chunks[k];
        EXPECT_EQ(c.first, k * kChunkTriangles);
        EXPECT_EQ(c.last, std::min<size_t>(mesh.triangles.size(), (k + 1) * kChunkTriangles));
        for (int cap = 0; cap < 2; ++cap) {
            EventBox want;
            for (uint32_t f = c.first; f < c.last; ++f)
                for (uint32_t v : mesh.triangles[f]) want.add(w.events[2 * v + cap]);
            const EventBox& got = c.cap[cap];
            EXPECT_EQ(got.t_lo, want.t_lo) << k << " " << cap;
            EXPECT_EQ(got.t_hi, want.t_hi) << k << " " << cap;
            EXPECT_EQ(got.lo.x, want.lo.x);
            EXPECT_EQ(got.lo.y, want.lo.y);
            EXPECT_EQ(got.lo.z, want.lo.z);
            EXPECT_EQ(got.hi.x, want.hi.x);
            EXPECT_EQ(got.hi.y, want.hi.y);
            EXPECT_EQ(got.hi.z, want.hi.z);
            EXPECT_LT(got.t_lo, got.t_hi);  // not the empty box
        }
    }
}

// The slab grid (extrude.h SlabGrid) is fixed by the motion alone: the samples of a span
// are the tau_a, tau_b given and exactly the grid points between them, so the samples of a narrower
// span are a wider one's inside it, bit for bit; every step is within slabSpacing over its own
// interval; atOrBefore / atOrAfter bracket a time by neighbouring samples.
TEST(SlabGrid, SamplesOfAnySpanAreOneGridsPoints) {
    const RestMesh mesh = testmesh::cylinder(1.0, 0.5, 24);
    Motion spin = makeMotion(Kinematics::Lorentz, 0, {0, 0, 0}, {0.6, 0, 0});
    spin.angular_velocity = {0, 0, 0.8};
    Motion rocket = makeMotion(Kinematics::Lorentz, 0, {0, 0, 0}, {0.3, 0, 0});
    rocket.acceleration = {0.2, 0, 0};
    const double chord = 1e-3;
    for (const Motion& m : {spin, rocket}) {
        const SlabGrid grid(mesh, m, chord);
        const std::vector<double> wide = grid.samples(-3.0, 12.0, 100000);
        ASSERT_GT(wide.size(), 20u);
        for (size_t i = 1; i < wide.size(); ++i) {
            ASSERT_LT(wide[i - 1], wide[i]);
            // each step within the bound over its own interval; before t0 an acceleration is uniform
            // motion (straight worldlines, one slab up to s = 0, where the grid begins)
            if (norm(m.acceleration) > 0 && wide[i] <= 0) continue;
            EXPECT_LE(wide[i] - wide[i - 1], slabSpacing(mesh, m, wide[i - 1], wide[i], chord) * (1 + 1e-12)) << i;
        }
        for (const auto& [lo, hi] : {std::pair{0.37, 4.1}, std::pair{-1.5, 0.25}, std::pair{7.0, 11.9}}) {
            const std::vector<double> narrow = grid.samples(lo, hi, 100000);
            ASSERT_GE(narrow.size(), 2u);
            EXPECT_EQ(narrow.front(), lo);
            EXPECT_EQ(narrow.back(), hi);
            std::vector<double> inside;
            for (double s : wide)
                if (s > lo && s < hi) inside.push_back(s);
            EXPECT_EQ(std::vector<double>(narrow.begin() + 1, narrow.end() - 1), inside) << lo << " " << hi;
            // the bracket of lo: the wide samples just below (a grid point, not the span's start -3,
            // or none) and above it
            const auto up = std::upper_bound(wide.begin(), wide.end(), lo);
            EXPECT_EQ(grid.atOrBefore(lo), up - 1 == wide.begin() ? -INFINITY : *(up - 1));
            EXPECT_EQ(grid.atOrAfter(lo), *up);
            EXPECT_EQ(grid.atOrAfter(*up), *up);
        }
        EXPECT_TRUE(grid.samples(-3.0, 12.0, 10).empty());  // more than 10 slabs: none
    }
    // Uniform motion has no grid points: one slab.
    const SlabGrid none(mesh, makeMotion(Kinematics::Lorentz, 0, {0, 0, 0}, {0.6, 0, 0}), chord);
    EXPECT_EQ(none.samples(-3.0, 12.0, 10), (std::vector<double>{-3.0, 12.0}));
}
