// Mirrors seen by a moving camera (pipeline/stage/mirror.h): the mirror is at rest in the lab, so the
// test does the reflection there, with its own maps, independent of the program's: the camera's
// lab event E (this file's inverse boost or shear of (t_c, position)), its image E' through the
// plane, the lab emission event of each rest point on E''s past cone (solved here in long double),
// the virtual source (emission time, reflected position), then mapped into the camera's frame. Every
// vertex of a reflection the mirror shows whole must be that event, to 1e-9 relative, in finite and
// relativistic; in instant and contracted each is the reflection, through the mirror's plane at the
// frame's time in the camera's frame (three of its lab points mapped there by this file), of the
// object's point at that time. Doppler along the reflected path: the classical and relativistic
// forms with the lab velocities and both legs' directions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "mesh4d/motion/motion.h"
#include "mesh4d/light_factors.h"
#include "pipeline/stage/mirror.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"
#include "quiet_stage.h"
#include "run_command.h"
#include "temp_dir.h"

using namespace apparent;
using mesh4d::Event;
using mesh4d::Vec3;
namespace fs = std::filesystem;

namespace {

// This file's camera-frame maps for a camera at p moving at v (about the event t = 0, x = p):
// Lorentz from the textbook form with r split along v, Galilean x' = x - v t.
Event cameraFromLab(const Event& e, const Vec3& v, const Vec3& p, bool lorentz) {
    if (!lorentz) return {e.t, e.x - v * e.t};
    const double b2 = mesh4d::dot(v, v), g = 1 / std::sqrt(1 - b2);
    const Vec3 r = e.x - p;
    const Vec3 r_par = v * (mesh4d::dot(r, v) / b2);
    return {g * (e.t - mesh4d::dot(v, r)), p + (r - r_par) + (r_par - v * e.t) * g};
}
Event labFromCamera(const Event& e, const Vec3& v, const Vec3& p, bool lorentz) {
    if (!lorentz) return {e.t, e.x + v * e.t};
    const double b2 = mesh4d::dot(v, v), g = 1 / std::sqrt(1 - b2);
    const Vec3 r = e.x - p;
    const Vec3 r_par = v * (mesh4d::dot(r, v) / b2);
    return {g * (e.t + mesh4d::dot(v, r)), p + (r - r_par) + (r_par + v * e.t) * g};
}

// The plane z = kMirrorZ (the mirror quad below), and reflection through it.
constexpr double kMirrorZ = -12;
Vec3 reflectZ(const Vec3& x) { return {x.x, x.y, 2 * kMirrorZ - x.z}; }

// The lab emission event of the worldline x(t) = a + u (t - t_a) on the past cone of (t_c, c),
// the non-negative root of (1 - u^2) d^2 + 2 (e.u) d - |e|^2 = 0, e = x(t_c) - c, in long double.
Event labEmission(const Vec3& a, double t_a, const Vec3& u, double t_c, const Vec3& c) {
    using L = long double;
    const L ex = L(a.x) + L(u.x) * (L(t_c) - t_a) - c.x, ey = L(a.y) + L(u.y) * (L(t_c) - t_a) - c.y,
            ez = L(a.z) + L(u.z) * (L(t_c) - t_a) - c.z;
    const L eu = ex * u.x + ey * u.y + ez * u.z, ee = ex * ex + ey * ey + ez * ez;
    const L k = 1 - (L(u.x) * u.x + L(u.y) * u.y + L(u.z) * u.z);
    const L root = std::sqrt(eu * eu + k * ee);
    const L d = eu >= 0 ? ee / (eu + root) : (root - eu) / k;
    return {double(t_c - d), {double(c.x + ex - u.x * d), double(c.y + ey - u.y * d), double(c.z + ez - u.z * d)}};
}

struct Fixture {
    fs::path dir;
    Stage stage;
};

// A scene with a 400 x 400 ls mirror quad in the plane z = -12 facing the camera, and `objects`
// (box.obj) between them; the mirror shows every reflection whole.
void loadScene(const std::string& name, const std::string& camera, const std::string& model, const std::string& objects,
               Fixture* f) {
    f->dir = testio::tempPath() / ("apparent_mirror_camera_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(f->dir);
    fs::create_directories(f->dir);
    fs::copy_file(fs::path(APPARENT_SOURCE_DIR) / "data/meshes/box.obj", f->dir / "box.obj");
    std::ofstream(f->dir / "mirror.obj") << "v -200 -300 0\nv 200 -300 0\nv 200 100 0\nv -200 100 0\nf 1 2 3 4\n";
    std::ofstream(f->dir / "scene.json") << R"({ "camera": { )" << camera << R"( },
        "frames": { "start": 0, "end": 4, "fps": 1 }, "model": ")" << model << R"(", "tolerance": "vertex",
        "objects": [ { "name": "mirror", "mesh": "mirror.obj", "mirror": true, "position": [0, 0, -12] }, )"
                                         << objects << "] }";
    std::string error;
    ASSERT_TRUE(loadQuietStage((f->dir / "scene.json").string(), &f->stage, &error)) << error;
}

const char* kObjects = R"({ "name": "rest", "mesh": "box.obj", "position": [-1, 0, -5] },
    { "name": "moving", "mesh": "box.obj", "position": [-3, 1, -6], "velocity": [0.5, 0.3, -0.2], "rotation_deg": [10, 20, 30] })";

// The reflections of frame k: the scene objects' cuts first (the mirror's is the aperture).
std::vector<mesh4d::ApparentMesh> reflections(const Fixture& f, Model model, long long k, bool factors = false,
                                              double tolerance = 0) {
    const Scene& scene = f.stage.scene;
    const MirrorReflections r(scene, f.stage.objects, f.stage.mirrors, model, k, k);
    const mesh4d::ViewSurface view = viewForFrame(scene, model, k);
    std::vector<mesh4d::ApparentMesh> cut;
    for (const PreparedObject& o : f.stage.objects) {
        cut.push_back(mesh4d::sliceWorld(buildWorld(o, model, scene, k, k), view, {}));
        if (factors) mesh4d::addLightFactors(buildWorld(o, model, scene, k, k), view, &cut.back());
    }
    mesh4d::SliceSettings settings;
    settings.tolerance = tolerance;
    settings.max_segments = 4096;
    r.append(view, settings, &cut);
    return std::vector<mesh4d::ApparentMesh>(cut.begin() + long(f.stage.objects.size()), cut.end());
}

}  // namespace

// Finite and relativistic: every reflected vertex is the camera-frame image of the lab's virtual
// source of its rest point, to 1e-9 relative; cameras along x at 0.6c and oblique at 0.8c.
TEST(MirrorCamera, ReflectionsAreTheLabsVirtualSourcesMappedIntoTheCameraFrame) {
    const std::vector<std::string> cameras = {R"("position": [0, 0, 0], "velocity": [0.6, 0, 0], "look_at": [0, 0, -12])",
                                              R"("position": [1, -1, 2], "velocity": [0.4, 0.5, -0.45], "look_at": [0, 0, -12])"};
    for (const std::string& camera : cameras)
        for (const char* model_name : {"finite", "relativistic"}) {
            Fixture f;
            loadScene(std::string("virtual_") + model_name, camera, model_name, kObjects, &f);
            const Model model = std::string(model_name) == "finite" ? Model::Finite : Model::Relativistic;
            const bool lorentz = model == Model::Relativistic;
            const Scene& scene = f.stage.scene;
            const Vec3 p = scene.camera.position, v = scene.camera.velocity;
            size_t checked = 0;
            for (long long k = 0; k < 4; ++k) {
                const double t_c = frameTime(scene.frames, k);
                const Event cam = labFromCamera({t_c, p}, v, p, lorentz);
                const std::vector<mesh4d::ApparentMesh> refl = reflections(f, model, k);
                ASSERT_EQ(refl.size(), 2u);
                for (size_t j = 0; j < 2; ++j) {
                    const PreparedObject& o = f.stage.objects[j + 1];
                    const mesh4d::Motion lab = motionOf(o.spec, model);
                    ASSERT_EQ(refl[j].positions.size(), 8u) << "the mirror shows the box whole";
                    for (size_t i = 0; i < refl[j].positions.size(); ++i) {
                        // The rest point's lab worldline, from two of its events.
                        const Vec3 q = refl[j].rest_points[i];
                        const Vec3 a = mesh4d::labPositionAt(lab, q, 0.0), b = mesh4d::labPositionAt(lab, q, 1.0);
                        const Event real = labEmission(a, 0.0, b - a, cam.t, reflectZ(cam.x));
                        const Event want = cameraFromLab({real.t, reflectZ(real.x)}, v, p, lorentz);
                        const Event got{refl[j].absoluteTime(i), refl[j].absolutePosition(i)};
                        const double scale = std::max({1.0, mesh4d::norm(want.x - p), std::fabs(want.t)});
                        EXPECT_NEAR(got.t, want.t, 1e-9 * scale) << model_name << " " << o.spec.name << " frame " << k;
                        EXPECT_LT(mesh4d::norm(got.x - want.x), 1e-9 * scale) << model_name << " " << o.spec.name;
                        if (lorentz)  // on the camera's past cone in its own frame
                            EXPECT_NEAR(t_c - got.t, mesh4d::norm(got.x - p), 1e-9 * scale);
                        ++checked;
                    }
                }
            }
            EXPECT_EQ(checked, 4u * 2u * 8u);
            fs::remove_all(f.dir);
        }
}

// Instant and contracted: at the frame's time t' in the camera's frame, each reflected vertex is
// the reflection of the object's point through the mirror's plane as it is at t' in that frame
// (through three of the plane's lab points, each at rest, mapped to t' by this file's maps).
TEST(MirrorCamera, HyperplaneReflectionsAreThroughTheMirrorsPlaneAtThatTime) {
    for (const char* model_name : {"instant", "contracted"}) {
        Fixture f;
        loadScene(std::string("plane_") + model_name, R"("position": [0.5, 0, 1], "velocity": [0.5, 0.2, -0.6])",
                  model_name, kObjects, &f);
        const Model model = std::string(model_name) == "instant" ? Model::Instant : Model::Contracted;
        const bool lorentz = model == Model::Contracted;
        const Scene& scene = f.stage.scene;
        const Vec3 p = scene.camera.position, v = scene.camera.velocity;
        for (long long k = 0; k < 4; ++k) {
            const double t = frameTime(scene.frames, k);
            // A lab point at rest x seen in the camera's frame at its time t: the lab event at x whose
            // camera time is t (lab time t / g + v.(x - p) for Lorentz, t for Galilean).
            auto at = [&](const Vec3& x) {
                const double g = 1 / std::sqrt(1 - mesh4d::dot(v, v));
                const double t_lab = lorentz ? t / g + mesh4d::dot(v, x - p) : t;
                return cameraFromLab({t_lab, x}, v, p, lorentz).x;
            };
            const Vec3 m0 = at({0, 0, kMirrorZ}), m1 = at({7, 0, kMirrorZ}), m2 = at({0, 5, kMirrorZ});
            const Vec3 nn = mesh4d::cross(m1 - m0, m2 - m0);
            const Vec3 n = nn / mesh4d::norm(nn);
            const std::vector<mesh4d::ApparentMesh> refl = reflections(f, model, k);
            for (size_t j = 0; j < 2; ++j) {
                const PreparedObject& o = f.stage.objects[j + 1];
                const mesh4d::Motion lab = motionOf(o.spec, model);
                ASSERT_EQ(refl[j].positions.size(), 8u);
                for (size_t i = 0; i < 8; ++i) {
                    const Vec3 y = refl[j].absolutePosition(i);
                    EXPECT_NEAR(refl[j].absoluteTime(i), t, 1e-12 * (1 + t));
                    const Vec3 real = y - n * (2 * mesh4d::dot(y - m0, n));  // reflected back through the plane
                    const Event lab_event = labFromCamera({t, real}, v, p, lorentz);
                    // On the lab worldline of one of the rest vertices (the camera's frame turns a
                    // moving object's rest frame in contracted: its rest points are rotated there).
                    double best = INFINITY;
                    for (const Vec3& q : o.rest.positions)
                        best = std::min(best, mesh4d::norm(mesh4d::labPositionAt(lab, q, lab_event.t) - lab_event.x));
                    EXPECT_LT(best, 1e-9 * (1 + mesh4d::norm(lab_event.x))) << model_name << " " << o.spec.name;
                }
            }
        }
        fs::remove_all(f.dir);
    }
}

// Doppler along the reflected path with a moving camera: D = g_v (1 - v.n2) / (g_u (1 - u.n1))
// (relativistic; finite without the gammas), n1 the lab direction from the real emission point to
// its mirror point, n2 from the mirror point to the camera's lab position at reception (which is
// n1 reflected), computed here from the test's own lab events; and the object's clock at the real
// emission event.
TEST(MirrorCamera, DopplerUsesBothLegsAndTheClockReadsAtTheRealEmission) {
    for (const char* model_name : {"finite", "relativistic"}) {
        Fixture f;
        loadScene(std::string("doppler_") + model_name, R"("position": [0, 0, 0], "velocity": [0.3, 0.1, -0.5])",
                  model_name, kObjects, &f);
        const Model model = std::string(model_name) == "finite" ? Model::Finite : Model::Relativistic;
        const bool lorentz = model == Model::Relativistic;
        const Scene& scene = f.stage.scene;
        const Vec3 p = scene.camera.position, v = scene.camera.velocity;
        const double t_c = frameTime(scene.frames, 2);
        const Event cam = labFromCamera({t_c, p}, v, p, lorentz);
        const std::vector<mesh4d::ApparentMesh> refl = reflections(f, model, 2, true);
        const mesh4d::Motion lab = motionOf(f.stage.objects[2].spec, model);
        const mesh4d::ApparentMesh& m = refl[1];  // the moving box
        ASSERT_EQ(m.doppler.size(), 8u);
        for (size_t i = 0; i < 8; ++i) {
            const Event virt = labFromCamera({m.absoluteTime(i), m.absolutePosition(i)}, v, p, lorentz);
            const Vec3 n2 = (cam.x - virt.x) / mesh4d::norm(cam.x - virt.x);  // the last leg, from the mirror
            const Vec3 n1{n2.x, n2.y, -n2.z};                                    // the first leg
            const Vec3 u = lab.velocity;
            const double gu = lorentz ? 1 / std::sqrt(1 - mesh4d::dot(u, u)) : 1;
            const double gv = lorentz ? 1 / std::sqrt(1 - mesh4d::dot(v, v)) : 1;
            const double want = gv * (1 - mesh4d::dot(v, n2)) / (gu * (1 - mesh4d::dot(u, n1)));
            EXPECT_NEAR(m.doppler[i], want, 1e-12 * want) << model_name << " vertex " << i;
            // The clock at the real emission event (the virtual one reflected back, same lab time):
            // (t - t0)/g - g u.z (relativistic) or t - t0 (finite), z its offset from the origin's worldline.
            const ObjectSpec& spec = f.stage.objects[2].spec;
            const Vec3 z = reflectZ(virt.x) - (spec.position + u * (virt.t - spec.t0));
            const double clock = lorentz ? (virt.t - spec.t0) / gu - gu * mesh4d::dot(u, z) : virt.t - spec.t0;
            EXPECT_NEAR(m.proper_time[i], clock, 1e-9 * (1 + std::fabs(clock))) << model_name << " vertex " << i;
        }
        fs::remove_all(f.dir);
    }
}

// Refined reflections with a moving camera are within T of the exact mapped virtual sources
// (sampled over every output triangle, each sample's rest point mapped as the test maps vertices):
// a box at rest in the lab, affine there but curved in the camera's frame, and a moving one, in
// relativistic and finite; vertex mode is off by more than T, so the test can fail.
TEST(MirrorCamera, RefinedReflectionsAreWithinTheTolerance) {
    static const double kSamples[7][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
                                          {1. / 3, 1. / 3, 1. / 3}};
    for (const char* model_name : {"finite", "relativistic"}) {
        Fixture f;
        loadScene(std::string("refined_") + model_name, R"("position": [0, 0, 0], "velocity": [0.8, 0, -0.1])", model_name,
                  R"({ "name": "rest", "mesh": "box.obj", "scale": 2, "position": [-1, 0, -4] },
                     { "name": "moving", "mesh": "box.obj", "scale": 2, "position": [-3, 1, -6], "velocity": [0.5, 0.3, -0.2] })",
                  &f);
        const Model model = std::string(model_name) == "finite" ? Model::Finite : Model::Relativistic;
        const bool lorentz = model == Model::Relativistic;
        const Scene& scene = f.stage.scene;
        const Vec3 p = scene.camera.position, v = scene.camera.velocity;
        const long long k = 2;
        const Event cam = labFromCamera({frameTime(scene.frames, k), p}, v, p, lorentz);
        auto worst = [&](const mesh4d::ApparentMesh& m, const mesh4d::Motion& lab) {
            double e = 0;
            for (const auto& t : m.triangles)
                for (const auto& b : kSamples) {
                    Vec3 q{0, 0, 0}, out{0, 0, 0};
                    for (int c = 0; c < 3; ++c) {
                        q += m.rest_points[t[c]] * b[c];
                        out += m.absolutePosition(t[c]) * b[c];
                    }
                    const Vec3 a = mesh4d::labPositionAt(lab, q, 0.0), a1 = mesh4d::labPositionAt(lab, q, 1.0);
                    const Event real = labEmission(a, 0.0, a1 - a, cam.t, reflectZ(cam.x));
                    e = std::max(e, mesh4d::norm(cameraFromLab({real.t, reflectZ(real.x)}, v, p, lorentz).x - out));
                }
            return e;
        };
        const std::vector<mesh4d::ApparentMesh> coarse = reflections(f, model, k);
        for (double tol : {1e-2, 1e-3}) {
            const std::vector<mesh4d::ApparentMesh> fine = reflections(f, model, k, false, tol);
            for (size_t j = 0; j < 2; ++j) {
                const mesh4d::Motion lab = motionOf(f.stage.objects[j + 1].spec, model);
                const double vertex_error = worst(coarse[j], lab), error = worst(fine[j], lab);
                EXPECT_GT(vertex_error, tol) << model_name << " " << j << ": the test must be able to fail";
                EXPECT_LE(error, tol) << model_name << " object " << j << ", " << fine[j].triangles.size() << " triangles";
                std::cout << "[mirror camera] " << model_name << " " << f.stage.objects[j + 1].spec.name << ", T = " << tol
                          << ": " << fine[j].triangles.size() << " triangles, error " << error / tol << " T (vertex mode "
                          << vertex_error / tol << " T)\n";
            }
        }
        fs::remove_all(f.dir);
    }
}
