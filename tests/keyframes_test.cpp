// Keyframed paths (mesh4d/motion/keyed.h, pipeline/input/gltf_animation.h): glTF
// animation channels on an object node, through the whole stage, against the uniform and spin
// models and against a path, a boost and a clock written out here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <cstdio>
#include <string>
#include <vector>

#include "keyed_gltf.h"
#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/motion.h"
#include "mesh4d/extrude.h"
#include "mesh4d/light_factors.h"
#include "mesh4d/ray4d.h"
#include "mesh4d/slice.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"
#include "quiet_stage.h"
#include "slab_rays.h"

#include "temp_dir.h"

using apparent::Model;
using mesh4d::Vec3;
using testkeys::Channel;
using testkeys::KeyedGltf;

namespace {

// Every frame's cut of the scene's one object: positions, emission times, clocks, rest points.
struct Cut {
    std::vector<double> t_c;
    std::vector<std::vector<Vec3>> positions, rest;
    std::vector<std::vector<double>> times, clocks;
};

Cut cutAll(const std::string& scene, Model model) {
    Cut c;
    apparent::Stage st;
    std::string error;
    EXPECT_TRUE(apparent::loadQuietStage(scene, &st, &error, {model})) << error;
    if (st.objects.empty()) return c;
    const mesh4d::World4D world = apparent::buildWorld(st.objects[0], model, st.scene, st.first, st.last_excl - 1);
    for (long long k = st.first; k < st.last_excl; ++k) {
        const mesh4d::ViewSurface view = apparent::viewForFrame(st.scene, model, k);
        mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, view);
        mesh4d::addLightFactors(world, view, &out);
        c.t_c.push_back(view.t_c);
        c.positions.emplace_back();
        c.times.emplace_back();
        for (size_t i = 0; i < out.positions.size(); ++i) {
            c.positions.back().push_back(out.absolutePosition(i));
            c.times.back().push_back(out.absoluteTime(i));
        }
        c.rest.push_back(out.rest_points);
        c.clocks.push_back(out.proper_time);
    }
    return c;
}

std::string dir() { return testio::processTempDir(); }

Channel translationKeys(const std::vector<float>& times, const std::vector<Vec3>& points) {
    Channel ch;
    ch.times = times;
    for (const Vec3& p : points)
        for (double v : {p.x, p.y, p.z}) ch.values.push_back(float(v));
    return ch;
}

}  // namespace

// Two keys at constant velocity are the uniform model with that velocity (keyed.h: V = v, the
// centre rests in F_V), in every model, to 1e-9 relative; the clocks too. Key positions are exact
// in float32 (X0 + v t with these values).
TEST(Keyframes, TwoKeysAtConstantSpeedAreTheUniformModel) {
    for (const Vec3 v : {Vec3{0.6, 0, 0}, Vec3{0.5, 0.25, 0}, Vec3{0, 0, 0.75}}) {
        const Vec3 x0{0, 0, -8};
        KeyedGltf keyed;
        keyed.channels.push_back(translationKeys({-40, 40}, {x0 - v * 40, x0 + v * 40}));
        KeyedGltf uniform;
        uniform.object_extras = {{"velocity", {v.x, v.y, v.z}}};
        for (auto* g : {&keyed, &uniform}) g->scene_extras["frames"] = {{"start", 2}, {"end", 4}, {"fps", 4}};
        const std::string kp = keyed.write(dir(), "two_keys"), up = uniform.write(dir(), "uniform");
        for (Model model : {Model::Relativistic, Model::Finite, Model::Contracted, Model::Instant}) {
            const Cut a = cutAll(kp, model), b = cutAll(up, model);
            ASSERT_EQ(a.positions.size(), 8u);
            ASSERT_EQ(a.positions.size(), b.positions.size());
            for (size_t k = 0; k < a.positions.size(); ++k) {
                ASSERT_EQ(a.positions[k].size(), 8u);
                for (size_t i = 0; i < 8; ++i) {
                    ASSERT_EQ(a.rest[k][i], b.rest[k][i]);
                    const double scale = mesh4d::norm(b.positions[k][i]);
                    EXPECT_NEAR(mesh4d::norm(a.positions[k][i] - b.positions[k][i]), 0, 1e-9 * scale)
                        << apparent::modelName(model) << " frame " << k << " vertex " << i;
                    EXPECT_NEAR(a.times[k][i], b.times[k][i], 1e-9 * scale);
                    EXPECT_NEAR(a.clocks[k][i], b.clocks[k][i], 1e-9 * scale) << apparent::modelName(model);
                }
            }
        }
    }
}

// A path that turns a corner (0.6c along x, then 0.6c along y, from rest and back to rest) is
// continuous, and each vertex is where the model says, computed here without the code under test:
// with no turn, q's worldline is the centre's lab polyline shifted by the 4-vector D = L_V(0, q)
// (the boost of q's rest-frame event at s = 0 with the mean velocity V = (0.3, 0.3, 0)), and q's
// clock, 0 at D, reads 0.8 (t - D.t) while the centre moves at 0.6.
TEST(Keyframes, CornerIsContinuousAndOnTheShiftedPath) {
    KeyedGltf g;
    g.channels.push_back(translationKeys({-20, 0, 20}, {{-12, 0, -6}, {0, 0, -6}, {0, 12, -6}}));
    g.scene_extras["frames"] = {{"start", 2}, {"end", 10}, {"fps", 8}};
    const std::string path = g.write(dir(), "corner");
    auto centre = [](double t) {  // the lab path, written out
        if (t <= -20) return Vec3{-12, 0, -6};
        if (t <= 0) return Vec3{0.6 * t, 0, -6};
        if (t <= 20) return Vec3{0, 0.6 * t, -6};
        return Vec3{0, 12, -6};
    };
    const double b = 0.3 * std::sqrt(2.0), gam = 1 / std::sqrt(1 - b * b);
    const Vec3 u{1 / std::sqrt(2.0), 1 / std::sqrt(2.0), 0};
    for (Model model : {Model::Relativistic, Model::Finite}) {
        const Cut c = cutAll(path, model);
        ASSERT_EQ(c.positions.size(), 64u);
        size_t straddles = 0;
        for (size_t k = 0; k < c.positions.size(); ++k)
            for (size_t i = 0; i < c.positions[k].size(); ++i) {
                const Vec3 q = c.rest[k][i], p = c.positions[k][i];
                const double t = c.times[k][i];
                // On the past cone of the camera at the origin.
                EXPECT_NEAR(c.t_c[k] - t, mesh4d::norm(p), 1e-12 * c.t_c[k]);
                // On the shifted path (Lorentz), or the carried one (Galilean: D = (0, q)).
                const bool lorentz = model == Model::Relativistic;
                const double d_t = lorentz ? gam * 0.3 * (q.x + q.y) : 0.0;
                const Vec3 d_x = lorentz ? q + u * ((gam - 1) * mesh4d::dot(q, u)) : q;
                EXPECT_NEAR(mesh4d::norm(p - (centre(t - d_t) + d_x)), 0, 1e-12 * 20) << k << " " << i;
                if (lorentz) {
                    EXPECT_NEAR(c.clocks[k][i], 0.8 * (t - d_t), 1e-12 * 20);
                }
                if (k == 0) continue;
                // Continuity: a step no longer than the speed times the emission-time step, which is
                // the frame step plus the change of the light delay.
                const double t_prev = c.times[k - 1][i];
                const double bound = 0.6 * ((c.t_c[k] - c.t_c[k - 1]) + std::fabs((c.t_c[k] - t) - (c.t_c[k - 1] - t_prev)));
                EXPECT_LE(mesh4d::norm(p - c.positions[k - 1][i]), bound * (1 + 1e-9) + 1e-12) << k << " " << i;
                if ((t_prev - d_t < 0) != (t - d_t < 0)) ++straddles;
            }
        EXPECT_GT(straddles, 0u) << "no frame pair straddles the corner";
    }
}

// A rotation channel is a spin: keys turning about z at a constant rate give the spin model's
// output (mesh4d/motion/worldline.h, tested against an independent boost in motion_test.cpp), clocks
// included (the rim runs at sqrt(1 - w^2 rho^2)). The rate is taken from the float32 keys.
TEST(Keyframes, RotationKeysAreTheSpin) {
    const double half = 1.5;
    const float s = float(std::sin(half / 2)), c = float(std::cos(half / 2));
    const double angle = 2 * std::atan2(double(s), double(c));  // the keys' angle from the floats
    const double w = 2 * angle / 5.0;                            // from -angle at t = -2.5 to +angle at 2.5
    KeyedGltf keyed;
    Channel ch;
    ch.path = "rotation";
    ch.times = {-2.5f, 2.5f};
    ch.values = {0, 0, -s, c, 0, 0, s, c};
    keyed.channels.push_back(ch);
    keyed.translation = {0, 0, -4};
    KeyedGltf spin = keyed;
    spin.channels.clear();
    spin.object_extras = {{"angular_velocity", {0, 0, w}}};
    for (auto* g : {&keyed, &spin}) g->scene_extras["frames"] = {{"start", 3}, {"end", 5}, {"fps", 5}};
    const std::string kp = keyed.write(dir(), "turn"), sp = spin.write(dir(), "spin");
    for (Model model : {Model::Relativistic, Model::Finite}) {
        const Cut a = cutAll(kp, model), b = cutAll(sp, model);
        ASSERT_EQ(a.positions.size(), 10u);
        for (size_t k = 0; k < a.positions.size(); ++k)
            for (size_t i = 0; i < 8; ++i) {
                ASSERT_EQ(a.rest[k][i], b.rest[k][i]);
                EXPECT_NEAR(mesh4d::norm(a.positions[k][i] - b.positions[k][i]), 0, 1e-9 * 4) << k << " " << i;
                EXPECT_NEAR(a.clocks[k][i], b.clocks[k][i], 1e-9 * 4) << k << " " << i;
            }
    }
}

// The clock in closed form across a turning segment (keyed.h: an elliptic integral) against a
// plain midpoint sum of d tau = ds sqrt(1 - |dY/ds|^2) over the positions themselves, for a point
// carried along a path that moves and turns at once.
TEST(Keyframes, ClockOfAMovingTurningPointIsTheIntegral) {
    mesh4d::KeyPath path;
    path.times = {0, 4, 9};
    path.positions = {{0, 0, 0}, {2, 0, 0}, {2, 2.5, 1}};
    const double a1 = 1.2, a2 = 2.6;
    path.turns = {{1, 0, 0, 0}, {std::cos(a1 / 2), 0, 0, std::sin(a1 / 2)}, {std::cos(a2 / 2), std::sin(a2 / 2) * 0.6, 0, std::sin(a2 / 2) * 0.8}};
    const Vec3 V = mesh4d::meanVelocity(path);
    const auto k = mesh4d::makeKeyedMotion(path, true, 1.0, mesh4d::keyedCentreAt(path, 1.0), V);
    const Vec3 q{0.7, -0.4, 0.3};
    ASSERT_LT(mesh4d::maxKeyedSpeed(*k, q).speed, 1);
    for (double s_end : {-2.0, 0.5, 3.0, 6.5, 9.0, 12.0}) {
        // Pieces between the keys (the worldline has a kink at each), 20000 chords each.
        std::vector<double> cuts{0.0, s_end};
        for (double sk : k->s)
            if ((sk > 0 && sk < s_end) || (sk < 0 && sk > s_end)) cuts.push_back(sk);
        std::sort(cuts.begin(), cuts.end());
        double sum = 0;
        for (size_t p = 0; p + 1 < cuts.size(); ++p)
            for (int i = 0, n = 20000; i < n; ++i) {
                const double s0 = cuts[p] + (cuts[p + 1] - cuts[p]) * i / n, s1 = cuts[p] + (cuts[p + 1] - cuts[p]) * (i + 1) / n;
                const Vec3 d = mesh4d::keyedLocal(*k, s1, q).y - mesh4d::keyedLocal(*k, s0, q).y;
                sum += std::sqrt((s1 - s0) * (s1 - s0) - mesh4d::norm2(d));
            }
        if (s_end < 0) sum = -sum;
        EXPECT_NEAR(mesh4d::keyedProperTime(*k, s_end, q), sum, 1e-8 * (1 + std::fabs(s_end))) << s_end;
    }
}

// A segment's motion at its own keys (keyed.h keyedSegmentLocal): at its first key the pose
// of that key, at its last (the stored whole turn, KeyedMotion::whole_turn) the pose of the next
// key, centre P_k plus the key's turn Q_k q, each rotated here by a matrix written out from the
// quaternion; and the bound's shortcut keyedSegmentTurned (q turned once by the caller) gives
// the same pose and velocity bit for bit at the keys and between them.
TEST(Keyframes, SegmentPoseAtItsKeysIsTheKeyPose) {
    mesh4d::KeyPath path;
    path.times = {0, 4, 9, 11};
    path.positions = {{0, 0, 0}, {2, 0, 0}, {2, 2.5, 1}, {1, 3, 1}};
    const double a1 = 1.2, a2 = 2.6, a3 = 0.4;
    path.turns = {{1, 0, 0, 0},
                  {std::cos(a1 / 2), 0, 0, std::sin(a1 / 2)},
                  {std::cos(a2 / 2), std::sin(a2 / 2) * 0.6, 0, std::sin(a2 / 2) * 0.8},
                  {std::cos(a3 / 2), 0, std::sin(a3 / 2), 0}};
    auto matrixTurn = [](const mesh4d::Quat& r, const Vec3& v) {
        const double w = r.w, x = r.x, y = r.y, z = r.z;
        return Vec3{(1 - 2 * (y * y + z * z)) * v.x + 2 * (x * y - w * z) * v.y + 2 * (x * z + w * y) * v.z,
                    2 * (x * y + w * z) * v.x + (1 - 2 * (x * x + z * z)) * v.y + 2 * (y * z - w * x) * v.z,
                    2 * (x * z - w * y) * v.x + 2 * (y * z + w * x) * v.y + (1 - 2 * (x * x + y * y)) * v.z};
    };
    for (bool lorentz : {true, false}) {
        const Vec3 V = mesh4d::meanVelocity(path);
        const auto k = mesh4d::makeKeyedMotion(path, lorentz, 1.0, mesh4d::keyedCentreAt(path, 1.0), V);
        for (const Vec3& q : {Vec3{0.7, -0.4, 0.3}, Vec3{-0.2, 0.5, -0.6}, Vec3{0, 0, 0}}) {
            for (size_t j = 1; j < k->s.size(); ++j) {
                for (size_t key : {j - 1, j}) {
                    const Vec3 want = k->centre[key] + matrixTurn(k->turns[key], q);
                    const Vec3 got = mesh4d::keyedSegmentLocal(*k, j, k->s[key], q).y;
                    EXPECT_LT(mesh4d::norm(got - want), 1e-12 * (1 + mesh4d::norm(want))) << lorentz << " " << j << " " << key;
                }
                const Vec3 p = mesh4d::rotate(k->turns[j - 1], q);
                for (double f : {0.0, 0.3, 1.0, 1.7}) {
                    const double s = f == 1.0 ? k->s[j] : k->s[j - 1] + f * (k->s[j] - k->s[j - 1]);
                    const mesh4d::KeyedLocal a = mesh4d::keyedSegmentLocal(*k, j, s, q);
                    const mesh4d::KeyedLocal b = mesh4d::keyedSegmentTurned(*k, j, s, p);
                    EXPECT_TRUE(a.y.x == b.y.x && a.y.y == b.y.y && a.y.z == b.y.z) << j << " " << f;
                    EXPECT_TRUE(a.dy.x == b.dy.x && a.dy.y == b.dy.y && a.dy.z == b.dy.z) << j << " " << f;
                }
            }
        }
    }
}

// Faster than light anywhere is refused with the time and the speed: the centre's path (every
// model), and a vertex carried by the turn (the box's corner at rho = 0.707 turning at 3 rad/s).
// A tolerance for a keyframed object that begins existing within the frames is refused (its clip
// curve is not bounded); its velocity comes from the path.
TEST(Keyframes, RefusalsNameFileFieldTimeAndSpeed) {
    std::string error;
    {
        KeyedGltf g;
        g.channels.push_back(translationKeys({0, 1, 3}, {{0, 0, -8}, {0.5, 0, -8}, {3.5, 0, -8}}));
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(g.write(dir(), "ftl"), &st, &error));
        EXPECT_NE(error.find("ftl.gltf: animations[0].channels[0]: the path moves at 1.5 (light-seconds per second) from lab "
                             "time 1 s, which must be < 1 (the speed of light)"),
                  std::string::npos)
            << error;
    }
    {
        KeyedGltf g;
        Channel ch;
        ch.path = "rotation";
        ch.times = {0, 1};
        ch.values = {0, 0, 0, 1, 0, 0, float(std::sin(1.5)), float(std::cos(1.5))};
        g.channels.push_back(ch);
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(g.write(dir(), "rim"), &st, &error));
        EXPECT_NE(error.find("rim.gltf: animations[0].channels[0]: vertex 0 would move at 2.12"), std::string::npos) << error;
        EXPECT_NE(error.find(" at lab time "), std::string::npos) << error;
        EXPECT_NE(error.find("must be < 1 (the speed of light) for model relativistic"), std::string::npos) << error;
    }
    {
        KeyedGltf g;
        g.channels.push_back(translationKeys({0, 1}, {{0, 0, -8}, {0.5, 0, -8}}));
        g.scene_extras["tolerance"] = "1e-3";
        g.object_extras = {{"t0", 0}, {"exists", {-8.0, nullptr}}};
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(g.write(dir(), "tol"), &st, &error));
        EXPECT_NE(error.find("tol.gltf: animations[0].channels[0]: a keyframed object that begins or ends existing (exists) "
                             "is cut in vertex mode only"),
                  std::string::npos)
            << error;
    }
    {
        KeyedGltf g;
        g.channels.push_back(translationKeys({0, 1}, {{0, 0, -8}, {0.5, 0, -8}}));
        g.object_extras = {{"velocity", {0.1, 0, 0}}};
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(g.write(dir(), "both"), &st, &error));
        EXPECT_NE(error.find("both.gltf: nodes[1].extras.velocity: the node's path is keyframed (animations[0].channels[0])"),
                  std::string::npos)
            << error;
    }
    {
        KeyedGltf g;
        g.channels.push_back(translationKeys({0, 1}, {{0, 0, -8}, {0.5, 0, -8}}));
        g.object_extras = {{"mirror", true}};
        apparent::Stage st;
        EXPECT_FALSE(apparent::loadQuietStage(g.write(dir(), "mirror"), &st, &error));
        EXPECT_NE(error.find("mirror.gltf: nodes[1].extras.mirror: a mirror must be at rest"), std::string::npos) << error;
    }
}

// Scale channels and channels on nodes that are not objects are not modelled: one warning each.
TEST(Keyframes, UnmodelledChannelsWarn) {
    KeyedGltf g;
    g.channels.push_back(translationKeys({0, 1}, {{0, 0, -8}, {0.5, 0, -8}}));
    Channel scale = translationKeys({0, 1}, {{1, 1, 1}, {2, 2, 2}});
    scale.path = "scale";
    g.channels.push_back(scale);
    apparent::Scene scene;
    const apparent::Status st = apparent::loadScene(g.write(dir(), "scaled_keys"), &scene);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_TRUE(scene.objects[0].keys);
    size_t found = 0;
    for (const std::string& w : scene.warnings)
        if (w.find("scaled_keys.gltf: animations[0].channels[1].target.path: 'scale' of nodes[1] is not modelled") != std::string::npos)
            ++found;
    EXPECT_EQ(found, 1u);
}

// The 4D raytracer meets a keyframed history through time slabs (mesh4d/extrude.h: a sample at
// every key, the spin's bound within a turning segment): every hit, boosted back into the path's
// frame by a boost written here and turned back by the path's pose there, lies on the plane of
// the rest triangle it hit within the slabs' chord; one slab over the same span misses by far more.
TEST(Keyframes, RaytracedHitsLieOnTheRestSurfaceThroughTimeSlabs) {
    mesh4d::RestMesh box;
    for (int i = 0; i < 8; ++i) box.positions.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
    const uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
        box.triangles.push_back({f[0], f[1], f[2]});
        box.triangles.push_back({f[0], f[2], f[3]});
    }
    mesh4d::KeyPath path;
    path.times = {-10, 0, 10};
    path.positions = {{-4, 0, 0}, {0, 0, 0}, {0, 4, 0}};
    path.turns = {{1, 0, 0, 0}, {std::cos(0.4), 0, 0, std::sin(0.4)}, {std::cos(1.0), 0, 0, std::sin(1.0)}};
    const Vec3 V = mesh4d::meanVelocity(path), origin = mesh4d::keyedCentreAt(path, 0);
    mesh4d::Motion m = mesh4d::makeMotion(mesh4d::Kinematics::Lorentz, 0, origin, V);
    m.keyed = mesh4d::makeKeyedMotion(path, true, 0, origin, V);
    const Vec3 camera{0, 0, 6};
    const double t_c = 6.5, chord = 1e-2;
    mesh4d::ViewSurface view;
    view.kind = mesh4d::ViewKind::PastCone;
    view.t_c = t_c;
    view.apex = camera;
    double lo = INFINITY, hi = -INFINITY;
    for (const Vec3& q : box.positions) {
        const double s = mesh4d::crossWorldline(view, m, q).s;
        lo = std::min(lo, s - 0.5);
        hi = std::max(hi, s + 0.5);
    }
    ASSERT_LT(lo, m.keyed->s[1]);  // the span holds the corner
    ASSERT_GT(hi, m.keyed->s[1]);
    const double b = mesh4d::norm(V), g = 1 / std::sqrt(1 - b * b);
    const std::vector<double> samples = mesh4d::slabSamples(box, m, lo, hi, chord / (g * (1 + b)), 4096);
    ASSERT_GT(samples.size(), 3u);
    auto rest_point = [&](const mesh4d::Event& e) {
        // The boost into the frame of V about (0, origin), written out.
        const double dt = e.t;
        const Vec3 dx = e.x - origin, u = V / b;
        const double T = g * (dt - mesh4d::dot(V, dx));
        const Vec3 Y = dx + u * ((g - 1) * mesh4d::dot(dx, u)) - V * (g * dt);
        // The pose there: centre P and turn R (columns from the unit vectors), q = R^T (Y - P).
        const Vec3 P = mesh4d::keyedLocal(*m.keyed, T, {0, 0, 0}).y;
        const Vec3 rel = Y - P;
        return Vec3{mesh4d::dot(mesh4d::keyedLocal(*m.keyed, T, {1, 0, 0}).y - P, rel),
                    mesh4d::dot(mesh4d::keyedLocal(*m.keyed, T, {0, 1, 0}).y - P, rel),
                    mesh4d::dot(mesh4d::keyedLocal(*m.keyed, T, {0, 0, 1}).y - P, rel)};
    };
    double worst[2] = {0, 0};
    for (int pass = 0; pass < 2; ++pass) {
        const testslab::OffPlanes r =
            testslab::slabHitsOffTheirPlanes(box, m, pass == 0 ? samples : std::vector<double>{lo, hi}, t_c, camera, rest_point);
        worst[pass] = r.worst;
        if (pass == 0) {
            EXPECT_GT(r.hits, 100);
        }
    }
    EXPECT_LE(worst[0], 2 * chord);
    EXPECT_GT(worst[1], 10 * chord);
}

// The shipped scene (data/scenes/make_keyed_gltf.py) loads and every frame cuts every vertex; the
// vertices move continuously (steps within the fastest speed, 0.8 + 0.11, times the emission step).
TEST(Keyframes, ShippedSceneRenders) {
    const Cut c = cutAll("data/scenes/keyed.gltf", Model::Relativistic);
    ASSERT_EQ(c.positions.size(), 160u);
    for (size_t k = 0; k < c.positions.size(); ++k) {
        ASSERT_EQ(c.positions[k].size(), 8u);
        if (k == 0) continue;
        for (size_t i = 0; i < 8; ++i)
            EXPECT_LE(mesh4d::norm(c.positions[k][i] - c.positions[k - 1][i]), 0.92 * std::fabs(c.times[k][i] - c.times[k - 1][i]) + 1e-12);
    }
}

// A tolerance for a keyframed object is taken (mesh4d/refine/worldline_refine.h, key_split.h): the scene's
// "1e-2x" loads, and the frames where the emission times cross the corner key at t = 1 s are refined
// (more triangles than the box's 12, each on one of them), the box's output closed in every frame.
TEST(Keyframes, ToleranceModeRefinesAcrossTheCorner) {
    KeyedGltf g;
    g.channels.push_back(translationKeys({0, 1, 2}, {{-0.5, 0, -8}, {0, 0, -8}, {0, 0.4, -8}}));
    g.scene_extras["tolerance"] = "1e-2x";
    g.scene_extras["frames"] = {{"start", 8}, {"end", 10}, {"fps", 10}};
    apparent::Stage st;
    std::string error;
    ASSERT_TRUE(apparent::loadQuietStage(g.write(dir(), "keyed_tol"), &st, &error)) << error;
    ASSERT_GT(st.tolerances[0], 0.0);
    const mesh4d::World4D world = apparent::buildWorld(st.objects[0], Model::Relativistic, st.scene, st.first, st.last_excl - 1);
    size_t refined = 0;
    for (long long k = st.first; k < st.last_excl; ++k) {
        mesh4d::SliceSettings settings;
        settings.tolerance = st.tolerances[0];
        const mesh4d::ApparentMesh out = mesh4d::sliceWorld(world, apparent::viewForFrame(st.scene, Model::Relativistic, k), settings);
        refined += out.triangles.size() > 12 ? 1 : 0;
        std::map<std::pair<uint32_t, uint32_t>, int> directed;
        for (const auto& t : out.triangles)
            for (int c = 0; c < 3; ++c) ++directed[{t[c], t[(c + 1) % 3]}];
        for (const auto& [e, count] : directed) {
            EXPECT_EQ(count, 1) << "frame " << k;
            EXPECT_EQ(directed.count({e.second, e.first}), 1u) << "frame " << k;
        }
        for (uint32_t f : out.source_triangles) EXPECT_LT(f, 12u);
        EXPECT_EQ(out.limited_triangles, 0u) << "frame " << k;
    }
    EXPECT_GT(refined, 0u);
}

// Keys under a turned parent are composed with the parent's transform as static values are: a
// parent turned +90 degrees about x sends the child's local (a, b, c) to (a, -c, b), and a child's
// turn about its local z is the lab turn about U z = -y (the turn conjugated by the parent's).
TEST(Keyframes, KeysUnderATurnedParentAreInTheLab) {
    const double h = std::sqrt(0.5);
    KeyedGltf g;
    g.parent_rotation = {h, 0, 0, h};
    g.channels.push_back(translationKeys({0, 10}, {{0, 0, 6}, {2, 1, 6}}));
    Channel turn;
    turn.path = "rotation";
    turn.times = {0, 10};
    const double angle = 1.2;
    turn.values = {0, 0, 0, 1, 0, 0, float(std::sin(angle / 2)), float(std::cos(angle / 2))};
    g.channels.push_back(turn);
    apparent::Scene scene;
    const apparent::Status st = apparent::loadScene(g.write(dir(), "nested"), &scene);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(scene.objects.size(), 1u);
    const auto& keys = *scene.objects[0].keys;
    ASSERT_EQ(keys.times.size(), 2u);
    EXPECT_NEAR(mesh4d::norm(keys.positions[0] - Vec3{0, -6, 0}), 0, 1e-12);
    EXPECT_NEAR(mesh4d::norm(keys.positions[1] - Vec3{2, -6, 1}), 0, 1e-12);
    const mesh4d::Quat q = keys.turns[1];
    const double s = std::sin(angle / 2), c = std::cos(angle / 2);
    EXPECT_NEAR(q.w, c, 1e-7);
    EXPECT_NEAR(q.x, 0, 1e-7);
    EXPECT_NEAR(q.y, -s, 1e-7);
    EXPECT_NEAR(q.z, 0, 1e-7);
    // The rest pose at t0 = 0 is the parent's turn: the mesh's local z is the lab's -y.
    EXPECT_NEAR(scene.objects[0].linear[7], -1, 1e-12);
}

// CUBICSPLINE (glTF 2.0 appendix C): tangents equal to a constant velocity give a straight line
// at constant speed, the same keys and output as LINEAR; a curved spline is followed through
// linear samples whose chords stay within 1e-6 x the keyed extent of the spline, written out here.
TEST(Keyframes, CubicSplineIsFollowedWithinItsBound) {
    const Vec3 x0{0, 0, -8}, v{0.5, 0.25, 0};
    KeyedGltf linear;
    linear.channels.push_back(translationKeys({-40, 40}, {x0 - v * 40, x0 + v * 40}));
    KeyedGltf cubic = linear;
    Channel& c = cubic.channels[0];
    c.interpolation = "CUBICSPLINE";
    const Vec3 a = x0 - v * 40, b = x0 + v * 40;
    c.values = {0.5f, 0.25f, 0, float(a.x), float(a.y), float(a.z), 0.5f, 0.25f, 0,
                0.5f, 0.25f, 0, float(b.x), float(b.y), float(b.z), 0.5f, 0.25f, 0};
    for (auto* g : {&linear, &cubic}) g->scene_extras["frames"] = {{"start", 2}, {"end", 4}, {"fps", 4}};
    const Cut l = cutAll(linear.write(dir(), "line_linear"), Model::Relativistic);
    const Cut s = cutAll(cubic.write(dir(), "line_cubic"), Model::Relativistic);
    ASSERT_EQ(l.positions.size(), 8u);
    for (size_t k = 0; k < l.positions.size(); ++k) EXPECT_EQ(l.positions[k], s.positions[k]) << k;

    // A curve: from (0, 0, -8) to (4, 0, -8) in 10 s, leaving along +y and arriving along +y.
    KeyedGltf curved;
    Channel ch;
    ch.interpolation = "CUBICSPLINE";
    ch.times = {0, 10};
    ch.values = {0, 0, 0, 0, 0, -8, 0, 0.5f, 0, 0, 0.5f, 0, 4, 0, -8, 0, 0, 0};
    curved.channels.push_back(ch);
    apparent::Scene scene;
    const apparent::Status st = apparent::loadScene(curved.write(dir(), "curve"), &scene);
    ASSERT_TRUE(st.ok) << st.message;
    const mesh4d::KeyPath& keys = *scene.objects[0].keys;
    ASSERT_GT(keys.times.size(), 10u);
    auto spline = [](double t) {  // Hermite with d = 10, p0 = (0, 0, -8), m0 = m1 = (0, 0.5, 0), p1 = (4, 0, -8)
        const double f = t / 10, f2 = f * f, f3 = f2 * f;
        const double h00 = 2 * f3 - 3 * f2 + 1, h10 = f3 - 2 * f2 + f, h01 = -2 * f3 + 3 * f2, h11 = f3 - f2;
        return Vec3{4 * h01, 10 * 0.5 * (h10 + h11), -8 * (h00 + h01)};
    };
    double worst = 0;
    for (size_t i = 0; i < keys.times.size(); ++i) {
        EXPECT_NEAR(mesh4d::norm(keys.positions[i] - spline(keys.times[i])), 0, 1e-12) << i;
        if (i + 1 < keys.times.size()) {
            const double mid = 0.5 * (keys.times[i] + keys.times[i + 1]);
            worst = std::max(worst, mesh4d::norm((keys.positions[i] + keys.positions[i + 1]) * 0.5 - spline(mid)));
        }
    }
    EXPECT_LE(worst, 1e-6 * std::sqrt(80.0));
    EXPECT_GT(worst, 0.1e-6 * std::sqrt(80.0));  // not more samples than the bound needs (within 10x)

    // A rotation spline with zero tangents from (0, 0, 0, 1) to (0, 0, s, c): the components eased
    // by h01 = 3f^2 - 2f^3, then normalised (appendix C); each sampled turn about z by 2 atan2(z, w).
    KeyedGltf turning;
    Channel r;
    r.path = "rotation";
    r.interpolation = "CUBICSPLINE";
    r.times = {0, 10};
    const float sz = float(std::sin(0.6)), cz = float(std::cos(0.6));
    r.values = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, sz, cz, 0, 0, 0, 0};
    turning.channels.push_back(r);
    apparent::Scene ts;
    const apparent::Status tst = apparent::loadScene(turning.write(dir(), "turning"), &ts);
    ASSERT_TRUE(tst.ok) << tst.message;
    const mesh4d::KeyPath& tk = *ts.objects[0].keys;
    ASSERT_GT(tk.times.size(), 2u);
    for (size_t i = 0; i < tk.times.size(); ++i) {
        const double f = tk.times[i] / 10, h = 3 * f * f - 2 * f * f * f;
        const double z = h * double(sz), w = (1 - h) + h * double(cz);
        EXPECT_NEAR(2 * std::atan2(tk.turns[i].z, tk.turns[i].w), 2 * std::atan2(z, w), 1e-12) << i;
    }
}
