// Tolerance mode for motions that are not uniform (issue 18; mesh4d/worldline_refine.h): the
// two-sided distance between the refined output and the exact apparent surface stays within T,
// the exact surface computed here from the true worldlines with kinematics of this file's own (a
// rotation written out, a Lorentz boost as a matrix, Born-rigid hyperbolas, the crossing by plain
// bisection), sharing nothing with the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/slice.h"
#include "test_meshes.h"

using mesh4d::Event;
using mesh4d::Vec3;

namespace {

using testmesh::cylinder;

// A closed box of half-size a (12 triangles, outward).
mesh4d::RestMesh box(double a) {
    mesh4d::RestMesh m;
    for (int i = 0; i < 8; ++i) m.positions.push_back({i & 1 ? a : -a, i & 2 ? a : -a, i & 4 ? a : -a});
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
}

// An independent worldline: the event of rest point q at the object's time s.
using Worldline = std::function<Event(double s, const Vec3& q)>;

// Spin about z by w, then (Lorentz) the boost with velocity (b, 0, 0) about (0, x0), or (Galilean)
// the carry x = x0 + R q + (b, 0, 0) s.
Worldline spinning(double b, double w, const Vec3& x0, bool lorentz) {
    return [=](double s, const Vec3& q) {
        const double c = std::cos(w * s), sn = std::sin(w * s);
        const double yx = c * q.x - sn * q.y, yy = sn * q.x + c * q.y;
        if (!lorentz) return Event{s, {x0.x + yx + b * s, x0.y + yy, x0.z + q.z}};
        const double g = 1 / std::sqrt(1 - b * b);
        return Event{g * (s + b * yx), {x0.x + g * (yx + b * s), x0.y + yy, x0.z + q.z}};
    };
}

// Born-rigid acceleration a along x from rest at (0, x0): xi = 1/a + q.x, T = xi sinh(a s),
// X = q.x + xi (cosh(a s) - 1) for s > 0; at rest before.
Worldline accelerated(double a, const Vec3& x0) {
    return [=](double s, const Vec3& q) {
        if (s <= 0) return Event{s, x0 + q};
        const double xi = 1 / a + q.x;
        return Event{xi * std::sinh(a * s), {x0.x + q.x + xi * (std::cosh(a * s) - 1), x0.y + q.y, x0.z + q.z}};
    };
}

// The crossing of q's worldline with the past cone of (t_c, C) (the hyperplane t = t_c when
// `plane`), by bisection on s.
bool plane = false;
Vec3 exactPoint(const Worldline& wl, double t_c, const Vec3& C, const Vec3& q) {
    auto h = [&](double s) {
        const Event e = wl(s, q);
        return (t_c - e.t) - (plane ? 0.0 : std::hypot(e.x.x - C.x, e.x.y - C.y, e.x.z - C.z));
    };
    double lo = -1e3, hi = 1e3;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (h(mid) > 0) lo = mid;
        else hi = mid;
    }
    return wl(0.5 * (lo + hi), q).x;
}

struct Sampled {
    double output_to_exact = 0;  // largest |F(q) - L(q)| at points of the output triangles
    double exact_to_output = 0;  // largest distance from sampled exact points to the output's point of that rest point
};

// Both ways: (1) points of every output triangle (corners' rest points interpolated) against the
// exact point of that rest point; (2) rest points sampled on every input triangle, located in the
// output triangle of that source that holds them (rest-frame barycentrics), the exact point against
// the output's interpolated point there. Either distance bounds the one-sided distance it samples.
Sampled sample(const mesh4d::RestMesh& mesh, const mesh4d::ApparentMesh& out, const Worldline& wl, double t_c,
               const Vec3& C) {
    Sampled r;
    auto at = [&](size_t t, double l0, double l1, double l2, Vec3* rest) {
        const auto& tri = out.triangles[t];
        *rest = out.rest_points[tri[0]] * l0 + out.rest_points[tri[1]] * l1 + out.rest_points[tri[2]] * l2;
        return out.absolutePosition(tri[0]) * l0 + out.absolutePosition(tri[1]) * l1 + out.absolutePosition(tri[2]) * l2;
    };
    const double bary[][3] = {{1 / 3.0, 1 / 3.0, 1 / 3.0}, {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
                              {0.6, 0.2, 0.2},          {0.2, 0.6, 0.2}, {0.2, 0.2, 0.6}};
    for (size_t t = 0; t < out.triangles.size(); ++t)
        for (const auto& l : bary) {
            Vec3 q;
            const Vec3 p = at(t, l[0], l[1], l[2], &q);
            r.output_to_exact = std::max(r.output_to_exact, mesh4d::norm(p - exactPoint(wl, t_c, C, q)));
        }
    std::map<uint32_t, std::vector<size_t>> by_source;
    for (size_t t = 0; t < out.triangles.size(); ++t) by_source[out.source_triangles[t]].push_back(t);
    const double probe[][3] = {{0.13, 0.29, 0.58}, {0.71, 0.17, 0.12}, {0.05, 0.9, 0.05}, {0.44, 0.11, 0.45}};
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
        const auto& tri = mesh.triangles[f];
        for (const auto& l : probe) {
            const Vec3 q = mesh.positions[tri[0]] * l[0] + mesh.positions[tri[1]] * l[1] + mesh.positions[tri[2]] * l[2];
            bool found = false;
            for (size_t t : by_source[uint32_t(f)]) {
                const auto& o = out.triangles[t];
                const Vec3 a = out.rest_points[o[0]], e1 = out.rest_points[o[1]] - a, e2 = out.rest_points[o[2]] - a;
                const Vec3 d = q - a;
                const double d11 = mesh4d::dot(e1, e1), d12 = mesh4d::dot(e1, e2), d22 = mesh4d::dot(e2, e2);
                const double det = d11 * d22 - d12 * d12;
                const double u = (d22 * mesh4d::dot(d, e1) - d12 * mesh4d::dot(d, e2)) / det;
                const double v = (d11 * mesh4d::dot(d, e2) - d12 * mesh4d::dot(d, e1)) / det;
                if (u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9) continue;
                Vec3 rest;
                const Vec3 p = at(t, 1 - u - v, u, v, &rest);
                r.exact_to_output = std::max(r.exact_to_output, mesh4d::norm(exactPoint(wl, t_c, C, q) - p));
                found = true;
                break;
            }
            EXPECT_TRUE(found) << "input triangle " << f << " not covered by the output";
        }
    }
    return r;
}

// Every undirected edge of the output in exactly two triangles, used in opposite directions.
void expectClosed(const mesh4d::ApparentMesh& out) {
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (const auto& t : out.triangles)
        for (int c = 0; c < 3; ++c) ++directed[{t[c], t[(c + 1) % 3]}];
    for (const auto& [e, count] : directed) {
        EXPECT_EQ(count, 1) << "edge " << e.first << "-" << e.second << " used twice in one direction";
        EXPECT_EQ(directed.count({e.second, e.first}), 1u) << "edge " << e.first << "-" << e.second << " open";
    }
}

struct Case {
    const char* name;
    mesh4d::RestMesh mesh;
    mesh4d::Motion motion;
    Worldline exact;
    double t_c;
    Vec3 camera;
    double size;  // the object's bounding-box diagonal
    bool hyperplane = false;
};

std::vector<Case> cases() {
    std::vector<Case> cs;
    {
        mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {0, 0, 0}, {0, 0, 0});
        m.angular_velocity = {0, 0, 0.9};
        cs.push_back({"spinning cylinder, rim at 0.9c", cylinder(1, 0.2, 12), m, spinning(0, 0.9, {0, 0, 0}, true), 3.0,
                      {3, 0, 2}, std::sqrt(4 + 4 + 0.16)});
    }
    {
        mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {-4.5, 0, 0}, {0.9, 0, 0});
        m.angular_velocity = {0, 0, -0.9};
        cs.push_back({"rolling wheel, b = 0.9", cylinder(1, 0.1, 12), m, spinning(0.9, -0.9, {-4.5, 0, 0}, true), 10.0,
                      {0, 0, 5}, std::sqrt(4 + 4 + 0.04)});
    }
    {
        mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Galilean, 0, {-1, 0, 0}, {0.3, 0, 0});
        m.angular_velocity = {0, 0, 0.5};
        cs.push_back({"finite model, carried spin", cylinder(1, 0.2, 12), m, spinning(0.3, 0.5, {-1, 0, 0}, false), 5.0,
                      {0, 0, 4}, std::sqrt(4 + 4 + 0.16)});
    }
    {
        mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {-2, 0, 0}, {0, 0, 0});
        m.acceleration = {0.5, 0, 0};
        cs.push_back({"accelerated box, a = 0.5", box(0.5), m, accelerated(0.5, {-2, 0, 0}), 8.0, {0, 0, 5},
                      std::sqrt(3.0)});
    }
    {
        mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {-4.5, 0, 0}, {0.9, 0, 0});
        m.angular_velocity = {0, 0, -0.9};
        cs.push_back({"contracted model, rolling wheel", cylinder(1, 0.1, 12), m, spinning(0.9, -0.9, {-4.5, 0, 0}, true),
                      5.0, {0, 0, 5}, std::sqrt(4 + 4 + 0.04), true});
    }
    return cs;
}

}  // namespace

// Two-sided error <= T, sampled both ways against the exact surface from the true worldlines, at
// T = 1e-2 and 1e-3 of the object's size (1e-4 for the box), on the cone (relativistic, finite)
// and the hyperplane (contracted); the output of a closed mesh is closed. Prints err / T and the output's triangles (the bound's tightness).
TEST(MotionTolerance, TwoSidedErrorWithinTheTolerance) {
    for (const Case& c : cases()) {
        const mesh4d::World4D world = mesh4d::extrude(c.mesh, c.motion, -1e3, 1e3, false, false);
        mesh4d::ViewSurface view;
        view.kind = c.hyperplane ? mesh4d::ViewKind::Hyperplane : mesh4d::ViewKind::PastCone;
        view.t_c = c.t_c;
        view.apex = c.camera;
        plane = c.hyperplane;
        const mesh4d::ApparentMesh vertex = mesh4d::sliceWorld(world, view);
        const Sampled v = sample(c.mesh, vertex, c.exact, c.t_c, c.camera);
        std::vector<double> rels = {1e-2, 1e-3};
        if (mesh4d::norm(c.motion.acceleration) > 0) rels.push_back(1e-4);
        for (double rel : rels) {
            mesh4d::SliceSettings settings;
            settings.tolerance = rel * c.size;
            const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view, settings);
            const Sampled s = sample(c.mesh, out, c.exact, c.t_c, c.camera);
            // The exact points here and the code's agree to about 1e-13 (bisection against Newton).
            EXPECT_LE(s.output_to_exact, settings.tolerance + 1e-11) << c.name << " T = " << rel << " x size";
            EXPECT_LE(s.exact_to_output, settings.tolerance + 1e-11) << c.name << " T = " << rel << " x size";
            EXPECT_EQ(out.limited_triangles, 0u) << c.name;
            EXPECT_FALSE(out.over_budget) << c.name;
            expectClosed(out);
            std::printf("[ tolerance ] %-32s T = %g x size: err/T %.3f (vertex mode %.3g), %zu -> %zu triangles\n", c.name,
                        rel, std::max(s.output_to_exact, s.exact_to_output) / settings.tolerance,
                        std::max(v.output_to_exact, v.exact_to_output) / settings.tolerance, c.mesh.triangles.size(),
                        out.triangles.size());
        }
    }
}

// A tolerance the input already meets changes nothing: the output is vertex mode's, point for point.
TEST(MotionTolerance, CoarseToleranceKeepsVertexModeOutput) {
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {0, 0, 0}, {0, 0, 0});
    m.angular_velocity = {0, 0, 0.1};
    const mesh4d::RestMesh mesh = cylinder(1, 0.2, 12);
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -1e3, 1e3, false, false);
    mesh4d::ViewSurface view;
    view.t_c = 1;
    view.apex = {0, 0, 50};
    mesh4d::SliceSettings settings;
    settings.tolerance = 1.0;
    const mesh4d::ApparentMesh vertex = mesh4d::sliceWorld(world, view);
    const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view, settings);
    EXPECT_EQ(out.refined_triangles, 0u);
    ASSERT_EQ(out.positions.size(), vertex.positions.size());
    ASSERT_EQ(out.triangles, vertex.triangles);
    for (size_t i = 0; i < out.positions.size(); ++i) {
        EXPECT_EQ(out.positions[i].x, vertex.positions[i].x);
        EXPECT_EQ(out.positions[i].y, vertex.positions[i].y);
        EXPECT_EQ(out.positions[i].z, vertex.positions[i].z);
    }
}

// The shipped rolling wheel (data/scenes/rolling_wheel.json: wheel.obj, radius 1 ls, b = 0.9, w = -0.9,
// camera at (0, 0, 5)) at T = 1e-2 of its size, at frames before, during and after it passes: the
// figures of the README's motion section (err/T, output triangles).
TEST(MotionTolerance, RollingWheelSceneWithinTheTolerance) {
    mesh4d::RestMesh mesh;
    FILE* f = std::fopen((std::string(APPARENT_SOURCE_DIR) + "/data/meshes/wheel.obj").c_str(), "r");
    ASSERT_NE(f, nullptr);
    char line[256];
    while (std::fgets(line, sizeof line, f)) {
        double x, y, z;
        unsigned a, b, c;
        if (std::sscanf(line, "v %lf %lf %lf", &x, &y, &z) == 3) mesh.positions.push_back({x, y, z});
        if (std::sscanf(line, "f %u %u %u", &a, &b, &c) == 3) mesh.triangles.push_back({a - 1, b - 1, c - 1});
    }
    std::fclose(f);
    ASSERT_EQ(mesh.triangles.size(), 792u);
    Vec3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
    for (const Vec3& p : mesh.positions)
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)},
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    const double size = mesh4d::norm(hi - lo);
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {-4.5, 0, 0}, {0.9, 0, 0});
    m.angular_velocity = {0, 0, -0.9};
    const Worldline exact = spinning(0.9, -0.9, {-4.5, 0, 0}, true);
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -1e3, 1e3, false, false);
    plane = false;
    for (double t_c : {0.0, 5.0, 10.0, 15.0}) {
        mesh4d::ViewSurface view;
        view.t_c = t_c;
        view.apex = {0, 0, 5};
        mesh4d::SliceSettings settings;
        settings.tolerance = 1e-2 * size;
        const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view, settings);
        const Sampled s = sample(mesh, out, exact, t_c, view.apex);
        EXPECT_LE(s.output_to_exact, settings.tolerance + 1e-11) << "t_c " << t_c;
        EXPECT_LE(s.exact_to_output, settings.tolerance + 1e-11) << "t_c " << t_c;
        expectClosed(out);
        std::printf("[ tolerance ] rolling_wheel.json t = %4.1f s, T = 1e-2 x size: err/T %.3f, 792 -> %zu triangles\n",
                    t_c, std::max(s.output_to_exact, s.exact_to_output) / settings.tolerance, out.triangles.size());
    }
}
