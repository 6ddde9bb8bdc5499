// The accuracy dial: refined cuts stay within the tolerance of the exact apparent surface in both
// directions, refine only where the surface is curved, stay watertight, and reproduce Penrose's
// circular outline of a relativistic sphere.
#include <gtest/gtest.h>

#include <map>

#include <Eigen/Dense>
#include <random>

#include "mesh4d/robust.h"
#include "mesh4d/slice.h"
#include "pipeline/mesh_check.h"
#include "mesh4d/measure.h"
#include "test_meshes.h"

using namespace mesh4d;

namespace {

using mesh4d::measure::exactToOutput;
using mesh4d::measure::outputToExact;

double restSize(const RestMesh& m) {
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (const auto& p : m.positions) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    return norm(hi - lo);
}

}  // namespace

// Both directions within T, for T from 1e-2 to 1e-6 of the object's size, finite and
// relativistic: a coarse sphere (icosahedron) passing 4 radii from the camera at 0.9c.
TEST(Tessellate, ErrorWithinToleranceBothDirections) {
    const RestMesh sphere = testmesh::icosphere(0, 1.0);
    const double size = restSize(sphere);
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotion(k, 0.0, {0, 0, -4}, {0.9, 0, 0});
        const World4D w = extrude(sphere, m, -100, 100, false, false);
        const ViewSurface view{ViewKind::PastCone, 4.0, {0, 0, 0}};
        const ApparentMesh vertex_mode = testmesh::sliceAbsolute(w, view);
        const double vertex_error = outputToExact(w, view, vertex_mode);
        EXPECT_GT(vertex_error, 1e-2 * size) << "the test must be able to fail: vertex mode is coarse here";
        // One face of the icosahedron (the one nearest the camera) carries the finest tolerances,
        // whose triangle counts grow as 1/T.
        RestMesh face = sphere;
        face.triangles = {sphere.triangles[0]};
        double best_z = -INFINITY;
        for (const auto& t : sphere.triangles) {
            const double z = sphere.positions[t[0]].z + sphere.positions[t[1]].z + sphere.positions[t[2]].z;
            if (z > best_z) { best_z = z; face.triangles = {t}; }
        }
        const World4D w_face = extrude(face, m, -100, 100, false, false);
        for (double rel : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6}) {
            SliceSettings s;
            s.tolerance = rel * size;
            s.max_segments = 4096;
            const World4D& wt = rel >= 1e-4 ? w : w_face;
            const ApparentMesh out = testmesh::sliceAbsolute(wt, view, s);
            EXPECT_EQ(out.limited_triangles, 0u);
            const double forward = outputToExact(wt, view, out);
            EXPECT_LE(forward, s.tolerance) << "T = " << rel << " x size, " << out.triangles.size() << " triangles";
            if (rel >= 1e-3 || &wt == &w_face) {  // the backward search is quadratic in the triangle count
                const double backward = exactToOutput(wt, view, out, rel >= 1e-5 ? 6 : 3);
                EXPECT_LE(backward, s.tolerance) << "T = " << rel << " x size";
            }
        }
    }
}

// Refinement follows curvature, speed and nearness: nothing at rest or in the instant model (the
// map is affine there), more for a nearer or faster object, never fewer than the input.
TEST(Tessellate, RefinesOnlyWhereTheSurfaceIsCurved) {
    const RestMesh sphere = testmesh::icosphere(1, 1.0);
    SliceSettings s;
    s.tolerance = 1e-3;
    auto count = [&](Kinematics k, ViewKind vk, double beta, double distance) {
        const Motion m = makeMotion(k, 0.0, {0, 0, -distance}, {beta, 0, 0});
        const World4D w = extrude(sphere, m, -1000, 1000, false, false);
        return testmesh::sliceAbsolute(w, {vk, distance, {0, 0, 0}}, s).triangles.size();
    };
    EXPECT_EQ(count(Kinematics::Lorentz, ViewKind::PastCone, 0.0, 10), sphere.triangles.size());
    EXPECT_EQ(count(Kinematics::Galilean, ViewKind::Hyperplane, 0.9, 10), sphere.triangles.size());
    const size_t far = count(Kinematics::Lorentz, ViewKind::PastCone, 0.9, 40);
    const size_t near = count(Kinematics::Lorentz, ViewKind::PastCone, 0.9, 5);
    const size_t slow = count(Kinematics::Lorentz, ViewKind::PastCone, 0.3, 5);
    EXPECT_GT(near, far);
    EXPECT_GT(near, slow);
    EXPECT_GE(far, sphere.triangles.size());
}

// Edges shared by two triangles are split once: a refined closed torus stays a closed
// 2-manifold of genus 1 (CGAL), with no T-junctions.
TEST(Tessellate, RefinedClosedMeshStaysWatertight) {
    const RestMesh torus = testmesh::torus(12, 8, 3.0, 1.0);
    for (Kinematics k : {Kinematics::Galilean, Kinematics::Lorentz}) {
        const Motion m = makeMotion(k, 0, {-2, 0, -9}, {0.9, 0, 0.2});
        const World4D w = extrude(torus, m, -100, 100, false, false);
        SliceSettings s;
        s.tolerance = 1e-3;
        const ApparentMesh out = testmesh::sliceAbsolute(w, {ViewKind::PastCone, 8.0, {}}, s);
        EXPECT_GT(out.refined_triangles, 0u);
        const apparent::Topology t = apparent::analyzeTopology(out.positions, out.triangles);
        EXPECT_TRUE(t.closed);
        EXPECT_EQ(t.genus, 1);
        EXPECT_EQ(t.components, 1u);
    }
}

namespace {

// Penrose (1959): the outline of a relativistic sphere, as directions from the camera, is a
// circle. The outline is taken from the silhouette edges of the apparent mesh seen from C; its
// directions are compared with the cone about their mean direction: returns (max - min) / mean
// of the angles to that axis.
double outlineNonCircularity(const ApparentMesh& m, const Vec3& C) {
    std::vector<Vec3> face_normal(m.triangles.size());
    for (size_t f = 0; f < m.triangles.size(); ++f) {
        const auto& t = m.triangles[f];
        face_normal[f] = cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]);
    }
    std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> edge_faces;
    for (size_t f = 0; f < m.triangles.size(); ++f)
        for (int c = 0; c < 3; ++c)
            edge_faces[std::minmax(m.triangles[f][c], m.triangles[f][(c + 1) % 3])].push_back(f);
    std::vector<Vec3> dirs;
    for (const auto& [e, faces] : edge_faces) {
        if (faces.size() != 2) continue;
        const Vec3 p = m.positions[e.first] - C;
        const bool front0 = dot(face_normal[faces[0]], p) < 0, front1 = dot(face_normal[faces[1]], p) < 0;
        if (front0 == front1) continue;
        dirs.push_back(p / norm(p));
        const Vec3 q = m.positions[e.second] - C;
        dirs.push_back(q / norm(q));
    }
    // The circle's axis: the normal of the plane that fits the unit directions best (a circle on
    // the unit sphere is the sphere cut by a plane), the covariance's smallest eigenvector.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& d : dirs) mean += Eigen::Vector3d(d.x, d.y, d.z);
    mean /= double(dirs.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& d : dirs) {
        const Eigen::Vector3d x = Eigen::Vector3d(d.x, d.y, d.z) - mean;
        cov += x * x.transpose();
    }
    const Eigen::Vector3d a = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    Vec3 axis{a.x(), a.y(), a.z()};
    if (dot(axis, Vec3{mean.x(), mean.y(), mean.z()}) < 0) axis = -axis;
    double lo = INFINITY, hi = 0, sum = 0;
    for (const auto& d : dirs) {
        const double a = std::atan2(norm(cross(d, axis)), dot(d, axis));
        lo = std::min(lo, a);
        hi = std::max(hi, a);
        sum += a;
    }
    return (hi - lo) / (sum / double(dirs.size()));
}

}  // namespace

// The input is a polyhedron, so its outline is a circle only to the polyhedron's own accuracy:
// the reference is the outline of the same mesh at rest, measured the same way. The relativistic
// outline must be as round as that (within a factor 3), at every tolerance; the finite model's
// outline (no contraction) is far from round. Refinement cannot beat the polyhedral floor: its
// extra points are images of the flat faces, not of the sphere.
TEST(Tessellate, PenroseOutlineOfARelativisticSphereIsACircle) {
    const RestMesh sphere = testmesh::icosphere(4, 1.0);  // 5120 faces, edge angle 0.07 rad
    const Vec3 C{0, 0, 0};
    // Seen at closest approach (the centre 4 radii away at t_c - 4), at 0.9c.
    auto outline = [&](Kinematics k, double beta, double tolerance) {
        const Motion m = makeMotion(k, 0.0, {0, 0, -4}, {beta, 0, 0});
        const World4D w = extrude(sphere, m, -100, 100, false, false);
        SliceSettings s;
        s.tolerance = tolerance;
        return outlineNonCircularity(testmesh::sliceAbsolute(w, {ViewKind::PastCone, 4.0, C}, s), C);
    };
    const double rest = outline(Kinematics::Lorentz, 0.0, 0);
    const double finite = outline(Kinematics::Galilean, 0.9, 1e-4);
    std::printf("outline non-circularity: at rest %.2e; relativistic 0.9c:", rest);
    for (double tolerance : {0.0, 1e-2, 1e-4}) {
        const double rel = outline(Kinematics::Lorentz, 0.9, tolerance);
        std::printf(" %.2e (T = %g)", rel, tolerance);
        EXPECT_LT(rel, 3 * rest) << "T = " << tolerance;
        EXPECT_GT(finite, 30 * rel) << "T = " << tolerance;
    }
    std::printf("; finite 0.9c: %.3f\n", finite);
}

// Objects that begin or end existing inside the frames, refined: the clipped surface stays a
// crack-free manifold (clip points shared along refined edges), every point of it is within T of
// the exact surface, and its boundary points lie on the tilted caps (proper time tau_a or tau_b).
TEST(Tessellate, ClippedSurfacesAreRefinedToo) {
    const RestMesh torus = testmesh::torus(16, 8, 3.0, 1.0);
    const Motion m = makeMotion(Kinematics::Lorentz, 0.0, {0, 0, -12}, {0.8, 0.2, 0});
    const double tau_a = 0.0, tau_b = 3.0;
    const World4D w = extrude(torus, m, tau_a, tau_b, true, true);
    SliceSettings s;
    s.tolerance = 1e-3;
    size_t clipped_frames = 0;
    for (double t_c = 6; t_c <= 22; t_c += 0.5) {
        const ViewSurface view{ViewKind::PastCone, t_c, {}};
        const ApparentMesh out = testmesh::sliceAbsolute(w, view, s);
        if (out.triangles.empty()) continue;
        const apparent::Topology topo = apparent::analyzeTopology(out.positions, out.triangles);
        EXPECT_TRUE(topo.manifold) << "t_c " << t_c;
        if (out.clipped_triangles == 0) continue;
        ++clipped_frames;
        EXPECT_GT(out.refined_triangles, 0u) << "t_c " << t_c;
        EXPECT_FALSE(topo.closed) << "t_c " << t_c;
        EXPECT_LE(outputToExact(w, view, out), s.tolerance) << "t_c " << t_c;
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const double tau = properTimeAt(m, out.rest_points[i], out.emission_times[i]);
            EXPECT_GE(tau, tau_a - 1e-9) << "t_c " << t_c;
            EXPECT_LE(tau, tau_b + 1e-9) << "t_c " << t_c;
            EXPECT_NEAR(norm(out.positions[i] - view.apex), view.t_c - out.emission_times[i], 1e-9 * 20);
        }
    }
    EXPECT_GT(clipped_frames, 3u);
}
