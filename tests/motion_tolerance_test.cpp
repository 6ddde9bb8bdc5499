// Tolerance mode for motions that are not uniform (mesh4d/refine/worldline_refine.h): the
// two-sided distance between the refined output and the exact apparent surface stays within T,
// the exact surface computed here from the true worldlines with kinematics of this file's own (a
// rotation written out, a Lorentz boost as a matrix, Born-rigid hyperbolas, the crossing by plain
// bisection), sharing nothing with the code under test.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/worldline.h"
#include "mesh4d/refine/measure.h"
#include "mesh4d/refine/worldline_bound.h"
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

// The output's point of rest point q on input triangle f (rest-frame barycentrics in the output
// triangle of that source that holds q); false when none holds it.
bool outputAt(const mesh4d::ApparentMesh& out, const std::map<uint32_t, std::vector<size_t>>& by_source, uint32_t f,
              const Vec3& q, Vec3* p) {
    const auto it = by_source.find(f);
    if (it == by_source.end()) return false;
    for (size_t t : it->second) {
        const auto& o = out.triangles[t];
        const Vec3 a = out.rest_points[o[0]], e1 = out.rest_points[o[1]] - a, e2 = out.rest_points[o[2]] - a;
        const Vec3 d = q - a;
        const double d11 = mesh4d::dot(e1, e1), d12 = mesh4d::dot(e1, e2), d22 = mesh4d::dot(e2, e2);
        const double det = d11 * d22 - d12 * d12;
        const double u = (d22 * mesh4d::dot(d, e1) - d12 * mesh4d::dot(d, e2)) / det;
        const double v = (d11 * mesh4d::dot(d, e2) - d12 * mesh4d::dot(d, e1)) / det;
        if (u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9) continue;
        *p = out.absolutePosition(o[0]) * (1 - u - v) + out.absolutePosition(o[1]) * u + out.absolutePosition(o[2]) * v;
        return true;
    }
    return false;
}

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
            Vec3 p;
            const bool found = outputAt(out, by_source, uint32_t(f), q, &p);
            if (found) r.exact_to_output = std::max(r.exact_to_output, mesh4d::norm(exactPoint(wl, t_c, C, q) - p));
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
// figures of docs/MOTION.md (err/T, output triangles).
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

// ---- Keyframed paths (mesh4d/motion/keyed.h, the bound across keys in worldline_bound.h) ----

namespace {

// A keyframed path written out here: keys at lab times t_k with centres X_k and turns by angle a_k
// about one fixed unit axis (so the turn between keys is the linear interpolation of the angle; the
// code slerps quaternions). The object's t0 is 0 and its origin X_0 (the first key is at t = 0).
struct TestPath {
    std::vector<double> t;
    std::vector<Vec3> X;
    std::vector<double> angle;
    Vec3 axis{0, 1, 0};
};

Vec3 turnAbout(const Vec3& k, double a, const Vec3& q) {
    const Vec3 kxq{k.y * q.z - k.z * q.y, k.z * q.x - k.x * q.z, k.x * q.y - k.y * q.x};
    const double kq = k.x * q.x + k.y * q.y + k.z * q.z;
    return q * std::cos(a) + kxq * std::sin(a) + k * (kq * (1 - std::cos(a)));
}

// The boost into the frame moving at v, as a 4 x 4 matrix on (t, x, y, z).
std::array<std::array<double, 4>, 4> boostMatrix(const Vec3& v) {
    const double b2 = v.x * v.x + v.y * v.y + v.z * v.z, g = 1 / std::sqrt(1 - b2);
    const double u[3] = {v.x, v.y, v.z};
    std::array<std::array<double, 4>, 4> B{};
    B[0][0] = g;
    for (int i = 0; i < 3; ++i) {
        B[0][i + 1] = B[i + 1][0] = -g * u[i];
        for (int j = 0; j < 3; ++j) B[i + 1][j + 1] = (i == j ? 1.0 : 0.0) + (b2 > 0 ? (g - 1) * u[i] * u[j] / b2 : 0.0);
    }
    return B;
}
Event apply(const std::array<std::array<double, 4>, 4>& B, double t, const Vec3& x) {
    const double in[4] = {t, x.x, x.y, x.z};
    double o[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) o[i] += B[i][j] * in[j];
    return {o[0], {o[1], o[2], o[3]}};
}

// The centre and angle at parameter u of keys (u_k, C_k, a_k), linear between, resting at the end
// values outside ("rest" velocity `outside` per unit u: 0 in the lab, -V in the path's frame).
void interpolate(const std::vector<double>& u, const std::vector<Vec3>& C, const std::vector<double>& a, double x,
                 const Vec3& outside, Vec3* c, double* angle) {
    const size_t n = u.size();
    if (x <= u[0]) {
        *c = C[0] + outside * (x - u[0]);
        *angle = a[0];
        return;
    }
    if (x >= u[n - 1]) {
        *c = C[n - 1] + outside * (x - u[n - 1]);
        *angle = a[n - 1];
        return;
    }
    size_t j = 1;
    while (u[j] < x) ++j;
    const double f = (x - u[j - 1]) / (u[j] - u[j - 1]);
    *c = C[j - 1] + (C[j] - C[j - 1]) * f;
    *angle = a[j - 1] + (a[j] - a[j - 1]) * f;
}

// The true worldlines of the keyed.h model, written independently: relativistic and contracted
// carry the body in the frame of the mean velocity V (keys boosted there by a matrix), then back to
// the lab; finite carries it in the lab. Parameter: that frame's time (lab time for finite).
Worldline keyedPath(const TestPath& p, bool lorentz) {
    const size_t n = p.t.size();
    const Vec3 V = (p.X[n - 1] - p.X[0]) / (p.t[n - 1] - p.t[0]);
    if (!lorentz)
        return [=](double s, const Vec3& q) {
            Vec3 c;
            double a = 0;
            interpolate(p.t, p.X, p.angle, s, {0, 0, 0}, &c, &a);
            return Event{s, c + turnAbout(p.axis, a, q)};
        };
    const auto into = boostMatrix(V), back = boostMatrix(V * -1.0);
    std::vector<double> s;
    std::vector<Vec3> P;
    for (size_t k = 0; k < n; ++k) {
        const Event e = apply(into, p.t[k] - p.t[0], p.X[k] - p.X[0]);
        s.push_back(e.t);
        P.push_back(e.x);
    }
    return [=](double sv, const Vec3& q) {
        Vec3 c;
        double a = 0;
        interpolate(s, P, p.angle, sv, V * -1.0, &c, &a);
        const Event lab = apply(back, sv, c + turnAbout(p.axis, a, q));
        return Event{p.t[0] + lab.t, p.X[0] + lab.x};
    };
}

// The same path as the code takes it (mesh4d::KeyPath, quaternions).
mesh4d::Motion keyedMotion(const TestPath& p, bool lorentz) {
    mesh4d::KeyPath path;
    path.times = p.t;
    path.positions = p.X;
    for (double a : p.angle)
        path.turns.push_back({std::cos(a / 2), p.axis.x * std::sin(a / 2), p.axis.y * std::sin(a / 2), p.axis.z * std::sin(a / 2)});
    const Vec3 V = mesh4d::meanVelocity(path);
    mesh4d::Motion m = mesh4d::makeMotion(lorentz ? mesh4d::Kinematics::Lorentz : mesh4d::Kinematics::Galilean, p.t[0], p.X[0], V);
    m.keyed = mesh4d::makeKeyedMotion(path, lorentz, p.t[0], p.X[0], V);
    return m;
}

struct KeyedCase {
    const char* name;
    TestPath path;
    bool lorentz;
    bool hyperplane;
    std::vector<double> t_c;  // frames where the emission times cross a key over the body
};

// keyed_cubic.gltf's path (data/scenes/make_keyed_gltf.py): the corner as a glTF CUBICSPLINE
// (Hermite, tangents per second scaled by the interval) through (-4, -1, -6), (0, -1, -6), (0, 2, -6)
// at t = 0, 8, 16 s, sampled here at `steps` equal sub-steps per interval into linear keys (the
// reader also takes equal sub-steps, as many as its chord error needs); the quarter turn about y
// linear in time between the three keys.
TestPath cubicCorner(int steps) {
    const double times[3] = {0, 8, 16};
    const Vec3 X[3] = {{-4, -1, -6}, {0, -1, -6}, {0, 2, -6}};
    const Vec3 m[3] = {{0.5, 0, 0}, {0.25, 0.19, 0}, {0, 0.375, 0}};
    const double angle[3] = {0, M_PI / 4, M_PI / 2};
    TestPath p;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < steps + (j == 1 ? 1 : 0); ++i) {
            const double f = double(i) / steps, d = times[j + 1] - times[j];
            const double h00 = 2 * f * f * f - 3 * f * f + 1, h10 = f * f * f - 2 * f * f + f;
            const double h01 = -2 * f * f * f + 3 * f * f, h11 = f * f * f - f * f;
            p.t.push_back(times[j] + d * f);
            p.X.push_back(X[j] * h00 + m[j] * (d * h10) + X[j + 1] * h01 + m[j + 1] * (d * h11));
            p.angle.push_back(angle[j] + (angle[j + 1] - angle[j]) * f);
        }
    return p;
}

std::vector<KeyedCase> keyedCases() {
    // keyed.gltf's path without its turn: 0.8c along +x, a corner at t = 5 s, 0.6c along +y.
    const TestPath corner{{0, 5, 10}, {{-4, -1, -6}, {0, -1, -6}, {0, 2, -6}}, {0, 0, 0}};
    // 0.5c along +x; the turn about y runs forward at 0.5 rad/s, then back at 0.375 rad/s from t = 4 s.
    const TestPath turn{{0, 4, 8}, {{-2, 0, -5}, {0, 0, -5}, {2, 0, -5}}, {0, 2.0, 0.5}};
    return {{"corner, relativistic", corner, true, false, {11.0, 16.0}},
            {"corner, finite", corner, false, false, {11.0, 16.0}},
            {"corner, contracted", corner, true, true, {5.0}},
            {"turn key, relativistic", turn, true, false, {9.0}},
            {"turn key, finite", turn, false, false, {9.0}},
            {"turn key, contracted", turn, true, true, {4.0}},
            {"cubic corner, relativistic", cubicCorner(32), true, false, {11.0, 14.0}}};
}

}  // namespace

// The independent worldlines above agree with the code's (keyed.h, worldline.h) event for event:
// the test's exact surface is the model's.
TEST(MotionTolerance, KeyedTestWorldlinesAreTheModels) {
    for (const KeyedCase& c : keyedCases()) {
        const mesh4d::Motion m = keyedMotion(c.path, c.lorentz);
        const Worldline exact = keyedPath(c.path, c.lorentz);
        for (double s : {-3.0, 0.5, 2.0, 4.5, 7.0, 9.5, 14.0})
            for (const Vec3& q : {Vec3{0.5, 0.5, 0.5}, Vec3{-0.5, 0.2, 0.5}}) {
                const Event a = mesh4d::worldlineEvent(m, s, q), b = exact(s, q);
                EXPECT_NEAR(a.t, b.t, 1e-12) << c.name << " s " << s;
                EXPECT_LT(mesh4d::norm(a.x - b.x), 1e-12) << c.name << " s " << s;
            }
    }
}

// A path that turns a corner and one whose turn changes at a key, relativistic, finite and
// contracted, at frames where the emission times cross a key over the box: two-sided error <= T at
// T = 1e-2 and 1e-3 of the box's size, sampled both ways against the exact surface of the true
// keyframed worldlines; the output of the closed box stays closed. Prints err / T, vertex mode's
// error and the triangles.
TEST(MotionTolerance, KeyedPathsWithinTheTolerance) {
    const mesh4d::RestMesh mesh = box(0.5);
    const double size = std::sqrt(3.0);
    for (const KeyedCase& c : keyedCases()) {
        const mesh4d::Motion m = keyedMotion(c.path, c.lorentz);
        const Worldline exact = keyedPath(c.path, c.lorentz);
        const mesh4d::World4D world = mesh4d::extrude(mesh, m, -1e3, 1e3, false, false);
        plane = c.hyperplane;
        for (double t_c : c.t_c) {
            mesh4d::ViewSurface view;
            view.kind = c.hyperplane ? mesh4d::ViewKind::Hyperplane : mesh4d::ViewKind::PastCone;
            view.t_c = t_c;
            const Sampled v = sample(mesh, mesh4d::sliceWorld(world, view), exact, t_c, view.apex);
            for (double rel : {1e-2, 1e-3}) {
                mesh4d::SliceSettings settings;
                settings.tolerance = rel * size;
                const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view, settings);
                const Sampled s = sample(mesh, out, exact, t_c, view.apex);
                EXPECT_LE(s.output_to_exact, settings.tolerance + 1e-11) << c.name << " t_c " << t_c << " T = " << rel;
                EXPECT_LE(s.exact_to_output, settings.tolerance + 1e-11) << c.name << " t_c " << t_c << " T = " << rel;
                EXPECT_EQ(out.limited_triangles, 0u) << c.name;
                EXPECT_FALSE(out.over_budget) << c.name;
                expectClosed(out);
                std::printf("[ tolerance ] %-24s t_c = %4.1f T = %g x size: err/T %.3f (vertex mode %.3g), 12 -> %zu triangles\n",
                            c.name, t_c, rel, std::max(s.output_to_exact, s.exact_to_output) / settings.tolerance,
                            std::max(v.output_to_exact, v.exact_to_output) / settings.tolerance, out.triangles.size());
            }
        }
    }
    plane = false;
}

// Two keys at constant velocity (0.6c, emission times between the keys): the worldlines are the
// uniform model's, so the tolerance output lies within T of the exact surface and, at every sampled
// rest point, within 2 T of the uniform model's tolerance output (each within T of the same
// surface); the measured gap is printed.
TEST(MotionTolerance, TwoKeysAtConstantSpeedMatchUniformMotion) {
    const mesh4d::RestMesh mesh = box(0.5);
    const double size = std::sqrt(3.0);
    const TestPath line{{0, 20}, {{-6, 0, -5}, {6, 0, -5}}, {0, 0}};
    plane = false;
    for (bool lorentz : {true, false}) {
        const mesh4d::Motion keyed = keyedMotion(line, lorentz);
        const mesh4d::Motion uniform =
            mesh4d::makeMotion(lorentz ? mesh4d::Kinematics::Lorentz : mesh4d::Kinematics::Galilean, 0, {-6, 0, -5}, {0.6, 0, 0});
        const Worldline exact = keyedPath(line, lorentz);
        const mesh4d::World4D wk = mesh4d::extrude(mesh, keyed, -1e3, 1e3, false, false);
        const mesh4d::World4D wu = mesh4d::extrude(mesh, uniform, -1e3, 1e3, false, false);
        mesh4d::ViewSurface view;
        view.t_c = 15;
        for (double rel : {1e-2, 1e-3}) {
            mesh4d::SliceSettings settings;
            settings.tolerance = rel * size;
            const mesh4d::ApparentMesh ok = mesh4d::sliceWorld(wk, view, settings);
            mesh4d::SliceSettings same_points = settings;  // the uniform model's points within T of their own images
            same_points.attribute_tolerance = settings.tolerance;
            const mesh4d::ApparentMesh ou = mesh4d::sliceWorld(wu, view, same_points);
            const Sampled s = sample(mesh, ok, exact, view.t_c, view.apex);
            EXPECT_LE(std::max(s.output_to_exact, s.exact_to_output), settings.tolerance + 1e-11) << lorentz << " " << rel;
            std::map<uint32_t, std::vector<size_t>> bk, bu;
            for (size_t t = 0; t < ok.triangles.size(); ++t) bk[ok.source_triangles[t]].push_back(t);
            for (size_t t = 0; t < ou.triangles.size(); ++t) bu[ou.source_triangles[t]].push_back(t);
            double gap = 0;
            for (uint32_t f = 0; f < mesh.triangles.size(); ++f)
                for (int i = 1; i < 10; ++i)
                    for (int j = 1; i + j < 10; ++j) {
                        const auto& tri = mesh.triangles[f];
                        const Vec3 q = mesh.positions[tri[0]] * ((10.0 - i - j) / 10) + mesh.positions[tri[1]] * (i / 10.0) +
                                       mesh.positions[tri[2]] * (j / 10.0);
                        Vec3 pk, pu;
                        ASSERT_TRUE(outputAt(ok, bk, f, q, &pk));
                        ASSERT_TRUE(outputAt(ou, bu, f, q, &pu));
                        gap = std::max(gap, mesh4d::norm(pk - pu));
                    }
            EXPECT_LE(gap, 2 * settings.tolerance) << lorentz << " " << rel;
            std::printf("[ tolerance ] two keys at 0.6c, %-12s T = %g x size: err/T %.3f, gap to uniform/T %.3f, %zu vs %zu triangles\n",
                        lorentz ? "relativistic" : "finite", rel, std::max(s.output_to_exact, s.exact_to_output) / settings.tolerance,
                        gap / settings.tolerance, ok.triangles.size(), ou.triangles.size());
        }
    }
}

// ---- Born-rigid acceleration on the cone (worldline_bound.h, "A Born-rigid acceleration on the cone") ----

// The rocket of data/scenes/rocket.json (box.obj scaled 2 x 0.5 x 0.5 at X0 = (-3, 0, 0), a = 0.5 along x
// from t0 = 0, camera at (0, 0, 6)) launched from a frame moving at V: its Motion and its true worldlines,
// the start-frame hyperbolas of `accelerated` carried into the lab by the boost matrix.
struct Rocket {
    mesh4d::RestMesh mesh;
    mesh4d::Motion motion;
    Worldline exact;
    double size;
};
Rocket rocket(const Vec3& V) {
    Rocket r;
    r.mesh = box(0.5);
    for (Vec3& p : r.mesh.positions) p = {p.x * 2, p.y * 0.5, p.z * 0.5};
    r.size = std::sqrt(4 + 0.25 + 0.25);
    const Vec3 X0{-3, 0, 0};
    r.motion = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, X0, V);
    r.motion.acceleration = {0.5, 0, 0};
    const auto back = boostMatrix(V * -1.0);
    const Worldline start = accelerated(0.5, {0, 0, 0});
    r.exact = [=](double s, const Vec3& q) {
        const Event e = start(s, q);
        const Event l = apply(back, e.t, e.x);
        return Event{l.t, X0 + l.x};
    };
    return r;
}

// The rocket at rest before launch (the shipped scene) and launched from a frame moving at
// (0.3, 0.4, 0), at frames before, while and after it passes the camera: two-sided error <= T at T = 1e-2,
// 1e-3 and 1e-4 of its size, sampled both ways against the exact surface; the closed box stays closed. The
// bound is tight enough that the largest error over the frames is at least half of T (0.87 to 0.94 when
// written; docs/ACCURACY.md "Non-uniform motion").
TEST(MotionTolerance, RocketSceneWithinTheTolerance) {
    plane = false;
    for (const Vec3& V : {Vec3{0, 0, 0}, Vec3{0.3, 0.4, 0}}) {
        const Rocket r = rocket(V);
        const mesh4d::World4D world = mesh4d::extrude(r.mesh, r.motion, -1e3, 1e3, false, false);
        for (double rel : {1e-2, 1e-3, 1e-4}) {
            double worst = 0;  // err / T over the frames, as `apparent trade` takes it
            for (double t_c : {4.0, 8.0, 12.0, 16.0}) {
                mesh4d::ViewSurface view;
                view.t_c = t_c;
                view.apex = {0, 0, 6};
                const Sampled v = sample(r.mesh, mesh4d::sliceWorld(world, view), r.exact, t_c, view.apex);
                mesh4d::SliceSettings settings;
                settings.tolerance = rel * r.size;
                const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view, settings);
                const Sampled s = sample(r.mesh, out, r.exact, t_c, view.apex);
                const double err = std::max(s.output_to_exact, s.exact_to_output);
                EXPECT_LE(err, settings.tolerance + 1e-11) << "V.x " << V.x << " t_c " << t_c << " T = " << rel;
                EXPECT_EQ(out.limited_triangles, 0u);
                EXPECT_FALSE(out.over_budget);
                expectClosed(out);
                worst = std::max(worst, err / settings.tolerance);
                std::printf("[ tolerance ] rocket, V = (%.1f, %.1f, 0) t_c = %4.1f T = %g x size: err/T %.3f (vertex mode %.3g), "
                            "12 -> %zu triangles\n",
                            V.x, V.y, t_c, rel, err / settings.tolerance,
                            std::max(v.output_to_exact, v.exact_to_output) / settings.tolerance, out.triangles.size());
            }
            EXPECT_GE(worst, 0.5) << "V.x " << V.x << " T = " << rel;
        }
    }
}

// The bound's K against the map's second derivative measured along lines: small rest triangles of the
// launched rocket, the exact apparent point by bisection at the centroid and a step +-h along each side's
// direction (central second difference, within about 1e-6 of the derivative here); |F..| <= K on every
// line (the header's closed forms in the start frame, boosted); K finite at sides 0.1 ls (a larger piece
// may have none: it is split). Prints the largest |F..| / K.
TEST(MotionTolerance, RigidBoundAboveSecondDerivative) {
    plane = false;
    const Rocket r = rocket({0.3, 0.4, 0});
    double tight = 0;
    for (double t_c : {5.0, 8.0, 11.0, 14.0, 17.0})
        for (const Vec3& q0 : {Vec3{-1, -0.25, 0.25}, Vec3{1, 0.25, -0.25}, Vec3{0, 0.25, 0.25}, Vec3{0.5, -0.25, 0}})
            for (double side : {0.4, 0.1}) {
                mesh4d::ViewSurface view;
                view.t_c = t_c;
                view.apex = {0, 0, 6};
                const Vec3 q[3] = {q0, q0 + Vec3{side, 0, 0}, q0 + Vec3{0.3 * side, 0.6 * side, -0.7 * side}};
                mesh4d::CornerCrossing c[3];
                for (int i = 0; i < 3; ++i) {
                    bool ok = false;
                    c[i] = mesh4d::cornerCrossing(view, r.motion, q[i], &ok);
                    ASSERT_TRUE(ok);
                }
                const double K = mesh4d::pieceBound(r.motion, view, 0, c).K;
                if (!std::isfinite(K)) {  // no bound closes on a large piece: refinement splits it
                    EXPECT_GT(side, 0.1) << "t_c " << t_c << " q0.x " << q0.x;
                    continue;
                }
                const Vec3 mid = (q[0] + q[1] + q[2]) / 3.0;
                const double h = 1e-3 * side;
                for (int i = 0; i < 3; ++i) {
                    const Vec3 u = (q[(i + 1) % 3] - q[i]) / mesh4d::norm(q[(i + 1) % 3] - q[i]);
                    const Vec3 fdd = (exactPoint(r.exact, t_c, view.apex, mid + u * h) - exactPoint(r.exact, t_c, view.apex, mid) * 2.0 +
                                      exactPoint(r.exact, t_c, view.apex, mid - u * h)) / (h * h);
                    EXPECT_LE(mesh4d::norm(fdd), K + 1e-6) << "t_c " << t_c << " side " << side;
                    tight = std::max(tight, mesh4d::norm(fdd) / K);
                }
            }
    std::printf("[ tolerance ] launched rocket: largest |F..| / K on the sampled lines %.3f\n", tight);
}

// ---- The measure of `apparent trade` on motions beyond uniform (mesh4d/refine/measure.h) ----

// measure.h's own root search (crossingBySearch) against the retarded event of hyperbolic motion in
// closed form: a Born-rigid body accelerated along x from rest at t0 = 0, camera on the x axis.
// Rest point q = (qx, 0, 0) follows X = X0 - 1/a + sqrt(xi^2 + t^2), xi = 1/a + qx (the origin:
// x(t) = X0 + (sqrt(1 + (a t)^2) - 1)/a). Camera behind at C = X0 - L: t_c - t = X - C squares to
// t = (K^2 - xi^2) / (2 K), K = t_c - L + 1/a; ahead at C = X0 + L: t_c - t = C - X gives
// t = (xi^2 - M^2) / (2 M), M = L + 1/a - t_c (> 0 here; both roots checked to lie in (0, t_c)).
TEST(MotionMeasure, CrossingBySearchMatchesHyperbolicMotion) {
    const double a = 0.5;
    const Vec3 X0{-2, 1, 0.5};
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, X0, {0, 0, 0});
    m.acceleration = {a, 0, 0};
    for (bool behind : {true, false})
        for (double qx : behind ? std::vector<double>{0.0, -1.0, 1.5} : std::vector<double>{0.0, 0.5, 1.5}) {
            const double L = behind ? 3 : 6, t_c = behind ? 9 : 7;
            mesh4d::ViewSurface view;
            view.t_c = t_c;
            view.apex = X0 + Vec3{behind ? -L : L, 0, 0};
            const double xi = 1 / a + qx;
            double t;
            if (behind) {
                const double K = t_c - L + 1 / a;
                t = (K * K - xi * xi) / (2 * K);
            } else {
                const double M = L + 1 / a - t_c;
                t = (xi * xi - M * M) / (2 * M);
            }
            ASSERT_TRUE(t > 0 && t < t_c) << "the case must lie after t0, before the frame";
            const double x = X0.x - 1 / a + std::sqrt(xi * xi + t * t);
            bool ok = false;
            const Event e = mesh4d::measure::crossingBySearch(view, m, {qx, 0, 0}, &ok);
            ASSERT_TRUE(ok);
            EXPECT_NEAR(e.t, t, 1e-12 * t_c) << "qx " << qx << (behind ? " behind" : " ahead");
            EXPECT_NEAR(e.x.x, x, 1e-12 * t_c) << "qx " << qx;
            EXPECT_EQ(e.x.y, X0.y);
            EXPECT_EQ(e.x.z, X0.z);
        }
    // The origin's: x(t) = (sqrt(1 + (a t)^2) - 1)/a from X0 (behind, t_c = 9, L = 3: t = 3.75, x = 2.25).
    mesh4d::ViewSurface view;
    view.t_c = 9;
    view.apex = X0 + Vec3{-3, 0, 0};
    const Event o = mesh4d::measure::crossingBySearch(view, m, {0, 0, 0});
    EXPECT_NEAR(o.t, 3.75, 1e-12);
    EXPECT_NEAR(o.x.x - X0.x, 2.25, 1e-12);
}

// The two-sided measure of a spinning disk seen along its axis, against its closed form. A wheel
// spins at w about z, centre at rest at the origin, camera on the axis at distance D: the point at
// radius rho and angle phi appears at angle phi + w (t_c - sqrt(D^2 + rho^2)) (the spoke spiral),
// radius rho. One triangle of the disk, hub and two rim points at radius r: vertex mode's output is
// the rest triangle turned by theta(r) (the hub stays at 0), so at rest point q the output is off
// the exact surface by 2 |q| |sin((theta(|q|) - theta(r)) / 2)|, both ways (the same rest point).
// twoSided must be the largest of that over its sample points: the 12 barycentric samples of every
// output triangle and the grid-8 lattice of the input triangle. Also for the hyperplane (contracted
// model), where theta = w t_c for every point: error 0.
TEST(MotionMeasure, TwoSidedOfSpinningDiskMatchesClosedForm) {
    const double w = 0.9, r = 1, D = 4, t_c = 3, half = 0.5;  // the triangle spans 2 x half rad
    mesh4d::RestMesh mesh;
    mesh.positions = {{0, 0, 0}, {r * std::cos(half), -r * std::sin(half), 0}, {r * std::cos(half), r * std::sin(half), 0}};
    mesh.triangles = {{0, 1, 2}};
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, {0, 0, 0}, {0, 0, 0});
    m.angular_velocity = {0, 0, w};
    const mesh4d::World4D world = mesh4d::extrude(mesh, m, -1e3, 1e3, false, false);
    mesh4d::ViewSurface view;
    view.t_c = t_c;
    view.apex = {0, 0, D};
    const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
    ASSERT_EQ(out.triangles.size(), 1u);
    auto theta = [&](double rho) { return w * (t_c - std::sqrt(D * D + rho * rho)); };
    auto error = [&](const double l[3]) {
        const Vec3 q = mesh.positions[0] * l[0] + mesh.positions[1] * l[1] + mesh.positions[2] * l[2];
        const double rho = mesh4d::norm(q);
        return 2 * rho * std::fabs(std::sin((theta(rho) - theta(r)) / 2));
    };
    double expected = 0;
    for (const auto& b : mesh4d::measure::kSamples) expected = std::max(expected, error(b));
    for (int i = 0; i <= 8; ++i)
        for (int j = 0; i + j <= 8; ++j) {
            const double l[3] = {(8.0 - i - j) / 8, i / 8.0, j / 8.0};
            expected = std::max(expected, error(l));
        }
    ASSERT_GT(expected, 0.01);  // a case that can fail: the spiral bends the chords by about 1e-2
    EXPECT_NEAR(mesh4d::measure::twoSided(world, view, out), expected, 1e-9 * expected);
    // The spoke spiral point by point: exactRelative of a rest point at radius 0.6 on the x axis.
    const Vec3 p = mesh4d::measure::exactRelative(world, view, {0.6, 0, 0}, {0, 0, 0});
    EXPECT_NEAR(p.x, 0.6 * std::cos(theta(0.6)), 1e-12);
    EXPECT_NEAR(p.y, 0.6 * std::sin(theta(0.6)), 1e-12);
    view.kind = mesh4d::ViewKind::Hyperplane;
    EXPECT_LT(mesh4d::measure::twoSided(world, view, mesh4d::sliceWorld(world, view)), 1e-14);
}
