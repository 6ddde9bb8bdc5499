// Tests of one frame's cut against closed forms (docs/DESIGN.md section 10) and against the inverse map.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>
#include <tuple>

#include "mesh4d/angles.h"
#include "mesh4d/normals.h"
#include "mesh4d/robust.h"
#include "mesh4d/slice.h"
#include "pipeline/input/mesh_check.h"
#include "test_meshes.h"

using namespace mesh4d;

namespace {

World4D alwaysExisting(const RestMesh& mesh, const Motion& m, double t_c) {
    // A span far wider than any delay in these tests, with open (non-clipping) caps.
    (void)t_c;
    return extrude(mesh, m, -1e4, 1e4, false, false);
}

// Distance from p to triangle (a, b, c), by projection and clamping to the edges.
double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = cross(b - a, c - a);
    const Vec3 proj = p - n * (dot(p - a, n) / norm2(n));
    const bool inside = dot(cross(b - a, proj - a), n) >= 0 && dot(cross(c - b, proj - b), n) >= 0 &&
                        dot(cross(a - c, proj - c), n) >= 0;
    if (inside) return norm(p - proj);
    auto seg = [&](const Vec3& s0, const Vec3& s1) {
        const double t = std::clamp(dot(p - s0, s1 - s0) / norm2(s1 - s0), 0.0, 1.0);
        return norm(p - (s0 + (s1 - s0) * t));
    };
    return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

double distanceToMesh(const Vec3& p, const RestMesh& m) {
    double best = INFINITY;
    for (const auto& t : m.triangles)
        best = std::min(best, pointTriangleDistance(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]));
    return best;
}

}  // namespace

// Every output vertex lies on the camera's past cone, |y - C| = t_c - t_e, and on the object's
// worldtube: un-retarding it (restFromLab at its emission time) lands on the input surface.
TEST(Slice, OutputVerticesAreOnConeAndWorldtube) {
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        for (int seed = 0; seed < 40; ++seed) {
            std::mt19937_64 rng(seed);
            std::uniform_real_distribution<double> u(-1, 1);
            const RestMesh mesh = testmesh::icosphere(2, 1.0 + 2 * std::fabs(u(rng)));
            Vec3 dir{u(rng), u(rng), u(rng)};
            const double beta = seed % 5 == 0 ? 0.999 : 0.95 * std::fabs(u(rng));
            const Motion m = makeMotion(k, u(rng), Vec3{u(rng), u(rng), u(rng)} * 40.0, dir * (beta / norm(dir)));
            const ViewSurface view{ViewKind::PastCone, 10 * u(rng), Vec3{u(rng), u(rng), u(rng)}};
            const ApparentMesh out = testmesh::sliceAbsolute(alwaysExisting(mesh, m, view.t_c), view);
            ASSERT_EQ(out.positions.size(), mesh.positions.size());
            ASSERT_EQ(out.triangles.size(), mesh.triangles.size());
            for (size_t i = 0; i < out.positions.size(); ++i) {
                const Vec3 y = out.positions[i];
                const double dist = norm(y - view.apex);
                const double delay = view.t_c - out.emission_times[i];
                EXPECT_NEAR(dist, delay, 1e-9 * dist) << "seed " << seed << " vertex " << i;
                const Vec3 q = restFromLab(m, y, out.emission_times[i]);
                EXPECT_LE(distanceToMesh(q, mesh), 1e-9 * (dist + 1)) << "seed " << seed << " vertex " << i;
            }
        }
    }
}

// Lampa (1924), docs/DESIGN.md section 10: a rod of rest length L on the line of sight appears
// L/(1-b) approaching and L/(1+b) receding with finite light speed alone, and
// L sqrt((1+b)/(1-b)), L sqrt((1-b)/(1+b)) with the Lorentz contraction too.
TEST(Slice, RodOnTheLineOfSight) {
    const double L = 2.0;
    const RestMesh rod = testmesh::rod(L, 1e-3);
    for (double b : {0.1, 0.5, 0.866, 0.99}) {
        for (int approach : {1, -1}) {
            for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
                // The rod's near end is 100 light-seconds down the -z axis at t0 = 0.
                const Motion m = makeMotion(k, 0.0, {0, 0, -100}, {0, 0, approach * b});
                const ViewSurface view{ViewKind::PastCone, 0.0, {0, 0, 0}};
                const ApparentMesh out = testmesh::sliceAbsolute(alwaysExisting(rod, m, 0), view);
                ASSERT_EQ(out.triangles.size(), 1u);
                // Output vertices follow the triangle's corners: 0 and 1 are the rod's ends.
                const double apparent = norm(out.positions[1] - out.positions[0]);
                double expected;
                if (k == Kinematics::Galilean) expected = approach > 0 ? L / (1 - b) : L / (1 + b);
                else expected = approach > 0 ? L * std::sqrt((1 + b) / (1 - b)) : L * std::sqrt((1 - b) / (1 + b));
                EXPECT_NEAR(apparent, expected, 1e-10 * expected)
                    << "b " << b << (approach > 0 ? " approaching " : " receding ")
                    << (k == Kinematics::Galilean ? "finite" : "relativistic");
            }
        }
    }
}

// At b = 0 every model returns the input mesh moved to its position, and the instant model
// (hyperplane t = t_c, Galilean) is an exact translation by X0 + v (t_c - t0) at any speed.
TEST(Slice, RestIsIdentityAndInstantIsTranslation) {
    const RestMesh mesh = testmesh::torus(12, 8, 3.0, 1.0);
    const Vec3 X0{5, -2, -30};
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        for (ViewKind vk : {ViewKind::PastCone, ViewKind::Hyperplane}) {
            const Motion m = makeMotion(k, 2.0, X0, {0, 0, 0});
            const ApparentMesh out = testmesh::sliceAbsolute(alwaysExisting(mesh, m, 0), {vk, 7.0, {1, 1, 1}});
            ASSERT_EQ(out.positions.size(), mesh.positions.size());
            for (size_t i = 0; i < mesh.positions.size(); ++i)
                EXPECT_NEAR(norm(out.positions[i] - (mesh.positions[i] + X0)), 0, 1e-13 * 40) << i;
            EXPECT_EQ(out.triangles, mesh.triangles);
        }
    }
    for (double b : {0.5, 0.99, 3.0}) {  // the instant model does not care about light speed
        const Vec3 v{0, b, 0};
        const Motion m = makeMotion(Kinematics::Galilean, 2.0, X0, v);
        const double t_c = 7.0;
        const ApparentMesh out = testmesh::sliceAbsolute(alwaysExisting(mesh, m, 0), {ViewKind::Hyperplane, t_c, {}});
        for (size_t i = 0; i < mesh.positions.size(); ++i) {
            EXPECT_NEAR(norm(out.positions[i] - (mesh.positions[i] + X0 + v * (t_c - 2.0))), 0, 1e-13 * 40) << i;
            EXPECT_EQ(out.emission_times[i], t_c);
        }
    }
}

// A closed 2-manifold that exists throughout gives a closed 2-manifold of the same genus, with
// one output vertex per input vertex (no cracks, no duplicates), checked with CGAL.
TEST(Slice, ClosedManifoldStaysClosedWithSameGenus) {
    struct Case { RestMesh mesh; long genus; };
    const Case cases[] = {{testmesh::icosphere(2, 2.0), 0}, {testmesh::torus(16, 10, 3.0, 1.0), 1}};
    for (const Case& c : cases) {
        const apparent::Topology in = apparent::analyzeTopology(c.mesh.positions, c.mesh.triangles);
        ASSERT_TRUE(in.closed);
        ASSERT_EQ(in.genus, c.genus);
        for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
            const Motion m = makeMotion(k, 0, {-4, 1, -12}, {0.9, 0, 0.1});
            const ApparentMesh out = testmesh::sliceAbsolute(alwaysExisting(c.mesh, m, 0), {ViewKind::PastCone, 3.0, {}});
            const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
            EXPECT_TRUE(t.closed);
            EXPECT_EQ(t.genus, c.genus);
            EXPECT_EQ(t.vertices, in.vertices);
            EXPECT_EQ(t.components, 1u);
        }
    }
}

// An object that begins existing inside the frames: on the frame where the cone crosses its
// start, the surface is clipped and open. The clip points lie on the cap tau = tau_a: in the
// Galilean model at one lab time (t0 + tau_a), in the Lorentz model on the tilted simultaneity
// t = t0 + g (tau_a + v.q), which spreads the clip's emission times.
TEST(Slice, ExistenceStartClipsAlongTheTiltedCap) {
    const RestMesh mesh = testmesh::icosphere(3, 2.0);
    const double tau_a = 0.0;
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotion(k, 0.0, {-1, 0, -20}, {0.8, 0, 0});
        const World4D w = extrude(mesh, m, tau_a, 1e4, true, false);
        // The frame whose cone meets the object's origin at its start: t_c = 0 + |X0 - C|.
        const ViewSurface view{ViewKind::PastCone, norm(m.origin), {}};
        const ApparentMesh out = testmesh::sliceAbsolute(w, view);
        EXPECT_GT(out.clipped_triangles, 0u);
        EXPECT_GT(out.triangles.size(), 0u);
        EXPECT_LT(out.triangles.size(), mesh.triangles.size());
        const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
        EXPECT_TRUE(t.manifold);
        EXPECT_FALSE(t.closed);
        EXPECT_GE(t.boundary_loops, 1u);
        double t_min = INFINITY, t_max = -INFINITY;
        size_t clip_points = 0;
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const Vec3 y = out.positions[i];
            const double t_e = out.emission_times[i];
            EXPECT_NEAR(norm(y - view.apex), view.t_c - t_e, 1e-9 * 20);
            const Vec3 q = restFromLab(m, y, t_e);
            const double tau = properTimeAt(m, q, t_e);
            EXPECT_GE(tau, tau_a - 1e-9);
            if (std::fabs(tau - tau_a) < 1e-9) {
                ++clip_points;
                t_min = std::min(t_min, t_e);
                t_max = std::max(t_max, t_e);
                // The clip point is on the rest surface's edges (on the surface, to rounding).
                EXPECT_LE(distanceToMesh(q, mesh), 1e-9);
            }
        }
        EXPECT_GT(clip_points, 10u);
        if (k == Kinematics::Galilean) {
            EXPECT_NEAR(t_max - t_min, 0, 1e-12);  // a flat cap: one lab time
        } else {
            // Tilted: emission times spread by g b times the extent along v (up to 2 g b r).
            EXPECT_GT(t_max - t_min, 0.5);
        }
    }
}

// Clip points are computed once per (edge, cap): triangles sharing an edge share its point, so
// a clipped closed surface has no cracks: every interior edge is shared by exactly two faces.
TEST(Slice, ClippedSurfaceHasNoCracks) {
    const RestMesh mesh = testmesh::torus(24, 12, 3.0, 1.0);
    const Motion m = makeMotion(Kinematics::Lorentz, 0.0, {0, 0, -15}, {0.7, 0.3, 0});
    const World4D w = extrude(mesh, m, 0.0, 2.0, true, true);
    for (double t_c = 10; t_c <= 22; t_c += 0.25) {
        const ApparentMesh out = testmesh::sliceAbsolute(w, {ViewKind::PastCone, t_c, {}});
        if (out.triangles.empty()) continue;
        const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
        EXPECT_TRUE(t.manifold) << "t_c " << t_c;
        if (out.clipped_triangles == 0) {
            EXPECT_TRUE(t.closed) << "t_c " << t_c;
        }
    }
}

// The contracted model (hyperplane t = t_c, Lorentz): each vertex is where the boosted object is
// at t_c, X0 + v (t_c - t0) + q - (1 - 1/g)(q.u) u; a rod along the motion measures L / gamma.
TEST(Slice, ContractedModelIsTheMeasuredShape) {
    const double b = 0.866, L = 2.0;
    RestMesh rod;
    rod.positions = {{0, 0, 0}, {L, 0, 0}, {0, 0.01, 0}};
    rod.triangles = {{0, 1, 2}};
    const Motion m = makeMotion(Kinematics::Lorentz, 1.0, {-3, 0, -18}, {b, 0, 0});
    const double t_c = 4.0;
    const ApparentMesh out = testmesh::sliceAbsolute(extrude(rod, m, -10, 10, false, false), {ViewKind::Hyperplane, t_c, {}});
    ASSERT_EQ(out.positions.size(), 3u);
    const double gamma = 1 / std::sqrt((1 - b) * (1 + b));
    EXPECT_NEAR(norm(out.positions[1] - out.positions[0]), L / gamma, 1e-12);
    EXPECT_NEAR(out.positions[0].x, -3 + b * (t_c - 1.0), 1e-12);
    for (double t_e : out.emission_times) EXPECT_EQ(t_e, t_c);
}

// Crease splitting (for shading): the flange's 90-degree fold splits its two shared vertices,
// a finely tessellated sphere stays in one piece, and every normal is a unit vector.
TEST(Normals, CreaseSplitKeepsCurvesSmoothAndFoldsSharp) {
    ApparentMesh flange;
    flange.positions = {{0, -2, 0}, {0, 2, 0}, {2, -2, 0}, {2, 2, 0}, {0, -2, -2}, {0, 2, -2}};
    flange.emission_times.assign(6, 0.0);
    flange.triangles = {{0, 2, 3}, {0, 3, 1}, {0, 1, 5}, {0, 5, 4}};
    const CreasedMesh f = creaseSplit(flange, 30);
    EXPECT_EQ(f.mesh.positions.size(), 8u);  // the two fold vertices doubled
    for (size_t i = 0; i < f.normals.size(); ++i) {
        EXPECT_NEAR(norm(f.normals[i]), 1.0, 1e-15);
        // Each normal is one plate's normal exactly: +z or -x.
        EXPECT_TRUE(f.normals[i] == (Vec3{0, 0, 1}) || f.normals[i] == (Vec3{-1, 0, 0})) << i;
    }
    const RestMesh s = testmesh::icosphere(3, 1.0);
    ApparentMesh sphere;
    sphere.positions = s.positions;
    sphere.emission_times.assign(s.positions.size(), 0.0);
    sphere.triangles = s.triangles;
    const CreasedMesh c = creaseSplit(sphere, 30);
    EXPECT_EQ(c.mesh.positions.size(), s.positions.size());
    for (size_t i = 0; i < c.normals.size(); ++i)
        EXPECT_GT(dot(c.normals[i], c.mesh.positions[i]), 0.99);  // close to the radial direction
}

// creaseSplitMap with kept scratch (a sequence: the same triangles, points moved) gives what a
// fresh creaseSplit gives, bit for bit, on a smooth mesh (the numbering reused) and on a folded
// one (vertices split: numbered again).
TEST(Normals, CreaseSplitMapReusedMatchesFresh) {
    const RestMesh s = testmesh::icosphere(3, 1.0);
    ApparentMesh sphere;
    sphere.positions = s.positions;
    sphere.emission_times.assign(s.positions.size(), 0.0);
    sphere.triangles = s.triangles;
    ApparentMesh flange;
    flange.positions = {{0, -2, 0}, {0, 2, 0}, {2, -2, 0}, {2, 2, 0}, {0, -2, -2}, {0, 2, -2}};
    flange.emission_times.assign(6, 0.0);
    flange.triangles = {{0, 2, 3}, {0, 3, 1}, {0, 1, 5}, {0, 5, 4}};
    for (ApparentMesh* m : {&sphere, &flange}) {
        CreaseMap map;
        CreaseWork work;
        for (int frame = 0; frame < 3; ++frame) {
            for (Vec3& p : m->positions) p = Vec3{p.x * 1.1, p.y, p.z * 0.95};  // a squash, as aberration does
            creaseSplitMap(*m, 30, &map, &work);
            const CreasedMesh fresh = creaseSplit(*m, 30);
            ASSERT_EQ(map.source.size(), fresh.mesh.positions.size());
            EXPECT_EQ(map.triangles, fresh.mesh.triangles);
            for (size_t k = 0; k < map.source.size(); ++k) {
                EXPECT_EQ(map.normals[k], fresh.normals[k]) << k;
                EXPECT_EQ(m->positions[map.source[k]], fresh.mesh.positions[k]) << k;
            }
        }
    }
}

// creaseSplitMap with kept scratch on a mesh of the same vertex and triangle counts but other
// triangles (the adjacency built again, not reused) gives what a fresh creaseSplit gives; and on
// a mesh of many vertices (several parallel blocks) with creases, faces of zero area and unused
// vertices, each output normal is the definition's, computed here independently: the normalised
// sum, in face order, of the area vectors of the faces around the vertex within the crease angle
// of the corner's face.
TEST(Normals, CreaseSplitMapFollowsTheDefinition) {
    // A folded 300 x 200 grid (120k faces): ridges, valleys and flat strips (folds of 45 and 90
    // degrees) across it, slightly curved along it; rows 49 and 50 of vertices equal (a row of
    // faces of zero area); 10 vertices unused.
    const int nx = 300, ny = 200;
    ApparentMesh m;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            const double fold = (i % 25 < 12 ? i % 25 : 24 - i % 25) * 0.1;
            const int row = j == 50 ? 49 : j;
            m.positions.push_back({0.1 * i, 0.1 * row, fold + 0.01 * std::sin(0.3 * row)});
        }
    for (int k = 0; k < 10; ++k) m.positions.push_back({-1.0 - k, 0, 0});
    m.emission_times.assign(m.positions.size(), 0.0);
    auto id = [&](int i, int j) { return uint32_t(j * (nx + 1) + i); };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    const double crease = 30, cos_crease = std::cos(crease * kPi / 180.0);
    // The definition, from the mesh alone.
    std::vector<std::vector<uint32_t>> around(m.positions.size());
    for (uint32_t f = 0; f < m.triangles.size(); ++f)
        for (uint32_t v : m.triangles[f]) around[v].push_back(f);
    auto areaOf = [&](uint32_t f) {
        const auto& t = m.triangles[f];
        return cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]);
    };
    auto unitOf = [&](uint32_t f) {
        const Vec3 a = areaOf(f);
        const double l = std::sqrt(dot(a, a));
        return l > 0 ? a / l : Vec3{0, 0, 0};
    };
    auto expected = [&](uint32_t f, uint32_t v) {
        Vec3 sum{0, 0, 0};
        for (uint32_t g : around[v])
            if (g == f || dot(unitOf(g), unitOf(f)) >= cos_crease) sum += areaOf(g);
        if (norm(sum) > 0) return sum / norm(sum);
        const Vec3 a = areaOf(f);
        return norm(a) > 0 ? a / norm(a) : Vec3{0, 0, 1};
    };
    CreaseMap map;
    CreaseWork work;
    ApparentMesh other = m;  // the same counts, the triangles turned (another corner first)
    for (auto& t : other.triangles) t = {t[1], t[2], t[0]};
    for (const ApparentMesh* mesh : {&other, &m}) {
        creaseSplitMap(*mesh, crease, &map, &work);
        const CreasedMesh fresh = creaseSplit(*mesh, crease);
        ASSERT_EQ(map.source.size(), fresh.mesh.positions.size());
        EXPECT_EQ(map.triangles, fresh.mesh.triangles);
        for (size_t k = 0; k < map.source.size(); ++k) ASSERT_EQ(map.normals[k], fresh.normals[k]) << k;
    }
    EXPECT_GT(map.source.size(), m.positions.size() - 10 + 2 * ny);  // the folds split
    size_t checked = 0;
    for (uint32_t f = 0; f < m.triangles.size(); ++f)
        for (int c = 0; c < 3; ++c) {
            const uint32_t k = map.triangles[f][size_t(c)];
            ASSERT_EQ(map.source[k], m.triangles[f][size_t(c)]);
            const Vec3 want = expected(f, m.triangles[f][size_t(c)]);
            // A vertex's corners within the angle of one another share one normal (their common
            // sum); the definition sums each corner's own set, the same faces in the same order.
            ASSERT_EQ(map.normals[k], want) << "face " << f << " corner " << c;
            ++checked;
        }
    EXPECT_EQ(checked, 3 * m.triangles.size());
}

// An object at rest that exists for lab time [-16, -10] (a 30 x 8 ls quad of two triangles, 23.675
// ls in front of the camera, like the default scene's backdrop) is seen where its distance from
// the camera lies in [t_c + 10, t_c + 16]: the quad's plane cut by two spheres, so its clip
// curves are circles about the foot F of the camera on the plane. With a tolerance (restTriangle)
// the output stays within T of that region both ways, its vertices lie inside it, and at t_c = 8
// s, when only a disc of radius 3.94 ls about F is seen (every corner of the quad still too far),
// the output has the disc's area less the segment below the quad's lower edge (closed form).
TEST(Slice, ObjectsAtRestAppearAlongCircles) {
    RestMesh quad;
    quad.positions = {{-15, 0, 0}, {15, 0, 0}, {15, 8, 0}, {-15, 8, 0}};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    const Vec3 origin{0, -2.05, -23.675};
    const Motion m = makeMotion(Kinematics::Lorentz, 0.0, origin, {0, 0, 0});
    const World4D w = extrude(quad, m, -16, -10, true, true);
    SliceSettings s;
    s.tolerance = 1e-3;
    s.max_segments = 4096;  // a 2.4 ls circle in a 30 ls triangle needs pieces of 1/512 (256 is the default limit)
    const double p = 23.675;  // distance of the camera (origin) from the quad's plane z = -23.675
    for (double t_c : {7.8, 8.0, 9.0, 12.0, 15.0, 17.0, 18.5}) {
        const ViewSurface view{ViewKind::PastCone, t_c, {0, 0, 0}};
        const ApparentMesh out = testmesh::sliceAbsolute(w, view, s);
        const double R_out = t_c + 16, R_in = t_c + 10;
        const double r_out = R_out > p ? std::sqrt((R_out - p) * (R_out + p)) : -1;
        const double r_in = R_in > p ? std::sqrt((R_in - p) * (R_in + p)) : 0;
        auto rho = [&](const Vec3& x) { return std::hypot(x.x, x.y); };  // in-plane distance from F = (0, 0)
        if (r_out < 0) {
            EXPECT_TRUE(out.triangles.empty()) << "t_c " << t_c;
            continue;
        }
        // Vertices inside the region (to rounding); sampled output points within T of it.
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const double d = norm(out.positions[i]);
            EXPECT_LE(d, R_out + 1e-9) << "t_c " << t_c;
            EXPECT_GE(d, R_in - 1e-9) << "t_c " << t_c;
            EXPECT_NEAR(out.positions[i].z, -p, 1e-12);
        }
        double area = 0;
        for (const auto& t : out.triangles) {
            const Vec3 a = out.positions[t[0]], b = out.positions[t[1]], c = out.positions[t[2]];
            area += 0.5 * norm(cross(b - a, c - a));
            for (const Vec3& x : {(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5, (a + b + c) / 3.0})
                EXPECT_LE(std::max({rho(x) - r_out, r_in - rho(x), 0.0}), s.tolerance) << "t_c " << t_c;
        }
        // Every seen point of a grid over the quad within T of the output (planar: distance in the plane).
        double worst = 0;
        size_t seen = 0;
        for (int i = 0; i <= 150; ++i)
            for (int j = 0; j <= 40; ++j) {
                const Vec3 x = origin + Vec3{-15 + 0.2 * i, 0.2 * j, 0};
                if (rho(x) > r_out || rho(x) < r_in) continue;
                ++seen;
                double best = INFINITY;
                for (const auto& t : out.triangles) {
                    best = std::min(best, pointTriangleDistance(x, out.positions[t[0]], out.positions[t[1]],
                                                                out.positions[t[2]]));
                    if (best == 0) break;
                }
                worst = std::max(worst, best);
            }
        // One oriented piece of surface (or two, where the hole of the end cap cuts through):
        // pieces meet edge to edge, no point twice, nothing limited.
        const apparent::Topology topo = apparent::analyzeTopology(out.positions, out.triangles);
        EXPECT_TRUE(topo.manifold) << "t_c " << t_c;
        EXPECT_LE(topo.components, 2u) << "t_c " << t_c;
        EXPECT_EQ(out.limited_triangles, 0u) << "t_c " << t_c;
        std::vector<Vec3> sorted = out.positions;
        std::sort(sorted.begin(), sorted.end(), [](const Vec3& a, const Vec3& b) {
            return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
        });
        size_t twins = 0;
        for (size_t i = 0; i + 1 < sorted.size(); ++i) twins += norm(sorted[i + 1] - sorted[i]) < 1e-9;
        EXPECT_EQ(twins, 0u) << "t_c " << t_c;
        std::cout << "[rest clip] t_c " << t_c << ": " << out.triangles.size() << " triangles, " << topo.components
                  << " component(s), " << topo.boundary_loops << " boundary loop(s), " << seen
                  << " seen grid points, farthest from the output " << worst << " ls\n";
        EXPECT_LE(worst, s.tolerance) << "t_c " << t_c;
        if (t_c == 8.0) {
            // Disc of radius r about F, less the segment beyond the lower edge 2.05 ls below F.
            const double r = r_out, a = 2.05;
            const double exact = M_PI * r * r - (r * r * std::acos(a / r) - a * std::sqrt(r * r - a * a));
            EXPECT_GT(seen, 100u);
            EXPECT_NEAR(area, exact, 2 * M_PI * r * s.tolerance) << "every corner outside, the middle seen";
        }
    }
}

// The cap through a vertex of an object at rest: a triangle whose nearest point to the camera is a
// corner exactly 5 ls away (3-4-5), existing from lab time -16, seen at t_c = -11: the cone meets
// the cap exactly at that corner, which is inside (zero counts as inside). The clip point there is the corner itself:
// no zero-area triangle, no point twice, no piece split to the limit.
TEST(Slice, RestClipThroughAVertex) {
    RestMesh tri;
    tri.positions = {{0, 4, 0}, {3, 8, 0}, {-3, 8, 0}};  // nearest to the camera's foot (0, 0): the corner
    tri.triangles = {{0, 1, 2}};
    const Motion m = makeMotion(Kinematics::Lorentz, 0.0, {0, 0, -3}, {0, 0, 0});
    const World4D w = extrude(tri, m, -16, 100, true, false);
    SliceSettings s;
    s.tolerance = 1e-3;
    const ApparentMesh out = testmesh::sliceAbsolute(w, {ViewKind::PastCone, -11.0, {0, 0, 0}}, s);
    EXPECT_EQ(out.limited_triangles, 0u);
    for (const auto& t : out.triangles) {
        const Vec3 a = out.positions[t[0]], b = out.positions[t[1]], c = out.positions[t[2]];
        EXPECT_GT(norm(cross(b - a, c - a)), 0.0);
    }
    size_t at_corner = 0;
    for (const Vec3& p : out.positions) at_corner += norm(p - Vec3{0, 4, -3}) < 1e-12;
    EXPECT_LE(at_corner, 1u);
    // The rest of the triangle is farther than 5 ls: nothing else is seen yet.
    double area = 0;
    for (const auto& t : out.triangles)
        area += 0.5 * norm(cross(out.positions[t[1]] - out.positions[t[0]], out.positions[t[2]] - out.positions[t[0]]));
    EXPECT_LT(area, 1e-9);
}
