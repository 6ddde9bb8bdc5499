// The raytracer's light is at rest in the lab (pipeline/input/scene.h LightSpec), so the shade of a face
// at rest in the lab does not depend on how the camera moves: only where the face appears does.
// Every pixel is checked against Lambert's law in the lab, from closed forms written here: the
// pixel's camera-frame direction taken back to the lab ray it sees (per model), that ray met with
// the face's plane, the face's rest normal and the light at that point.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "mesh4d/angles.h"
#include "pipeline/trace/raytrace.h"
#include "quiet_stage.h"
#include "srgb.h"
#include "temp_dir.h"

using namespace apparent;
using mesh4d::Vec3;

namespace {

Vec3 unit(const Vec3& v) { return v / mesh4d::norm(v); }

using testio::linearToSrgb8;

// The camera-frame direction k in which a camera at the lab origin, moving at v, sees
// light that reached it along the lab direction d (from the camera towards the source), and back.
// relativistic: aberration, k = (d + (g - 1)(d.n) n + g v) / (g (1 + d.v)), n = v/|v|;
// finite (light at c in the lab, Galilean camera frame): k along d + v; contracted (the camera's
// hyperplane t' = t_c, the lab seen through the boost at one camera time): k along
// d + (1/g - 1)(d.n) n; instant (the hyperplane t = t_c, where x' = x - v t_c is a shift): k = d.
Vec3 seenDirection(Model model, const Vec3& v, const Vec3& d) {
    const double b = mesh4d::norm(v);
    if (b == 0 || model == Model::Instant) return d;
    const double g = 1 / std::sqrt(1 - b * b);
    const Vec3 n = v / b;
    switch (model) {
        case Model::Relativistic:
            return unit((d + (g - 1) * mesh4d::dot(d, n) * n + g * v) / (g * (1 + mesh4d::dot(d, v))));
        case Model::Finite: return unit(d + v);
        case Model::Contracted: return unit(d + (1 / g - 1) * mesh4d::dot(d, n) * n);
        default: return d;
    }
}
Vec3 labDirection(Model model, const Vec3& v, const Vec3& k) {
    const double b = mesh4d::norm(v);
    if (b == 0 || model == Model::Instant) return k;
    const double g = 1 / std::sqrt(1 - b * b);
    const Vec3 n = v / b;
    switch (model) {
        case Model::Relativistic:
            return unit((k + (g - 1) * mesh4d::dot(k, n) * n - g * v) / (g * (1 - mesh4d::dot(k, v))));
        case Model::Finite: {
            // d = a k - v with |d| = 1.
            const double kv = mesh4d::dot(k, v);
            return unit((kv + std::sqrt(kv * kv + 1 - b * b)) * k - v);
        }
        case Model::Contracted: return unit(k + (g - 1) * mesh4d::dot(k, n) * n);
        default: return k;
    }
}

// The camera's basis and a pixel's direction, as a pinhole camera of vertical field fov_deg.
Vec3 pixelRay(const Vec3& forward, double fov_deg, int size, int px, int py) {
    const Vec3 f = unit(forward);
    const Vec3 r = unit(mesh4d::cross(f, Vec3{0, 1, 0}));
    const Vec3 u = mesh4d::cross(r, f);
    const double half = std::tan(fov_deg * mesh4d::kPi / 360);
    return unit(f + (2 * (px + 0.5) / size - 1) * half * r + (1 - 2 * (py + 0.5) / size) * half * u);
}

const char* kFaces[6][4] = {{"0.5 -0.5 -0.5", "0.5 0.5 -0.5", "0.5 0.5 0.5", "0.5 -0.5 0.5"},
                            {"-0.5 -0.5 -0.5", "-0.5 -0.5 0.5", "-0.5 0.5 0.5", "-0.5 0.5 -0.5"},
                            {"-0.5 0.5 -0.5", "-0.5 0.5 0.5", "0.5 0.5 0.5", "0.5 0.5 -0.5"},
                            {"-0.5 -0.5 -0.5", "0.5 -0.5 -0.5", "0.5 -0.5 0.5", "-0.5 -0.5 0.5"},
                            {"-0.5 -0.5 0.5", "0.5 -0.5 0.5", "0.5 0.5 0.5", "-0.5 0.5 0.5"},
                            {"-0.5 -0.5 -0.5", "-0.5 0.5 -0.5", "0.5 0.5 -0.5", "0.5 -0.5 -0.5"}};
const Vec3 kCentre{0, 0, -5};

// A unit cube at rest in the lab at kCentre, rotated, its six faces separate objects, seen by a
// camera moving at `velocity`, looking along `forward`, at its frame 0 (camera time kTime), which
// it spends at the lab origin when it starts from `position`.
constexpr double kTime = 2;
std::string writeScene(const std::filesystem::path& dir, const Vec3& position, const Vec3& velocity,
                       const Vec3& forward, double fov_deg, const std::string& light) {
    std::filesystem::create_directories(dir);
    std::ostringstream scene;
    scene.precision(17);
    scene << R"({ "camera": {"position": [)" << position.x << ", " << position.y << ", " << position.z
          << R"(], "look_at": [)" << position.x + forward.x << ", " << position.y + forward.y << ", " << position.z + forward.z
          << R"(], "up": [0, 1, 0], "fov_deg": )" << fov_deg << R"(, "velocity": [)" << velocity.x << ", " << velocity.y
          << ", " << velocity.z << "]},\n  " << light << R"( "frames": {"start": )" << kTime << R"(, "end": )" << kTime + 0.1
          << R"(, "fps": 10}, "objects": [)";
    for (int f = 0; f < 6; ++f) {
        std::ofstream obj(dir / ("face" + std::to_string(f) + ".obj"));
        for (const char* v : kFaces[f]) obj << "v " << v << "\n";
        obj << "f 1 2 3\nf 1 3 4\n";
        scene << (f ? ", " : "") << R"({"mesh": "face)" << f
              << R"(.obj", "position": [0, 0, -5], "rotation_deg": [20, 30, 10]})";
    }
    scene << "] }";
    const auto path = dir / "scene.json";
    std::ofstream(path) << scene.str();
    return path.string();
}

struct Light {
    std::string json;
    bool point = false;
    Vec3 at;  // the unit direction towards a distant light, or a point light's lab position
};

// Traces frame 0 of the cube seen by a camera moving at `velocity` in `model` and checks every
// pixel of every face against Lambert's law in the lab; returns per face its pixels' mean colour.
std::map<int32_t, std::array<double, 3>> checkEveryPixel(Model model, const Vec3& velocity, const Light& light,
                                                         const std::filesystem::path& dir) {
    // Step: look at where the cube's centre appears; a field of view 2.4 times its widest corner.
    const Vec3 forward = seenDirection(model, velocity, unit(kCentre));
    double widest = 0;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 c = kCentre + Vec3{corner & 1 ? 0.9 : -0.9, corner & 2 ? 0.9 : -0.9, corner & 4 ? 0.9 : -0.9};
        widest = std::max(widest, std::acos(std::min(1.0, mesh4d::dot(forward, seenDirection(model, velocity, unit(c))))));
    }
    const double fov = 2.4 * widest * 180 / mesh4d::kPi;
    const int size = 160;
    // The camera's lab event at camera time kTime is (g kTime, position + g v kTime) under Lorentz
    // kinematics (its clock runs slow), (kTime, position + v kTime) under Galilean: at the origin.
    const double b = mesh4d::norm(velocity);
    const bool lorentz = model == Model::Relativistic || model == Model::Contracted;
    const double g = lorentz ? 1 / std::sqrt(1 - b * b) : 1;
    Stage stage;
    std::string error;
    std::map<int32_t, std::array<double, 3>> means;
    if (!loadQuietStage(writeScene(dir, -g * kTime * velocity, velocity, forward, fov, light.json), &stage, &error, {model})) {
        ADD_FAILURE() << error;
        return means;
    }
    SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, model, 0, 0);
    const TracedFrame frame = tracer.traceFrame(0, size, size);
    const std::string what = std::string(modelName(model)) + " camera at [" + std::to_string(velocity.x) + ", " +
                             std::to_string(velocity.y) + ", " + std::to_string(velocity.z) + "]" +
                             (light.point ? " point light" : " distant light");
    std::map<int32_t, int> counts;
    int wrong = 0;
    for (int py = 0; py < size; ++py)
        for (int px = 0; px < size; ++px) {
            const size_t i = size_t(py) * size + size_t(px);
            const int32_t o = frame.object[i];
            if (o < 0) continue;
            // Step: the face's outward rest normal (the cube is centred on the mesh origin) and the
            // lab point the pixel's ray meets on its plane.
            const mesh4d::RestMesh& rest = stage.objects[size_t(o)].rest;
            const Vec3 a = rest.positions[rest.triangles[0][0]];
            Vec3 n = unit(mesh4d::cross(rest.positions[rest.triangles[0][1]] - a, rest.positions[rest.triangles[0][2]] - a));
            if (mesh4d::dot(n, a) < 0) n = -n;
            const Vec3 d = labDirection(model, velocity, pixelRay(forward, fov, size, px, py));
            const double s = mesh4d::dot(n, kCentre + a) / mesh4d::dot(n, d);
            const Vec3 hit = s * d;
            // The point lies on the face: the unit square from corner 0 along its edges to corners
            // 1 and 3 (the geometry of the trace agrees with the closed form).
            const Vec3 e1 = rest.positions[1] - rest.positions[0], e3 = rest.positions[3] - rest.positions[0];
            const Vec3 q = hit - (kCentre + rest.positions[0]);
            const double a1 = mesh4d::dot(q, e1), a3 = mesh4d::dot(q, e3);
            EXPECT_TRUE(a1 > -1e-6 && a1 < 1 + 1e-6 && a3 > -1e-6 && a3 < 1 + 1e-6)
                << what << " face " << o << " pixel (" << px << ", " << py << "): " << a1 << ", " << a3;
            const Vec3 l = light.point ? unit(light.at - hit) : light.at;
            const double lambert = 0.2 + 0.8 * std::max(0.0, mesh4d::dot(n, l));
            const auto color = objectBaseColor(stage.objects, size_t(o));
            const uint8_t* p = frame.image.rgb.data() + 3 * i;
            for (size_t c = 0; c < 3; ++c) {
                const double expect = color[c] * lambert;
                const bool ok = testio::levelShows(p[c], expect);
                if (!ok && wrong++ < 3)
                    ADD_FAILURE() << what << " face " << o << " pixel (" << px << ", " << py << ") channel " << c << ": "
                                  << int(p[c]) << " != " << linearToSrgb8(expect);
                means[o][c] += p[c];
            }
            ++counts[o];
        }
    EXPECT_EQ(wrong, 0) << what << ": pixels off Lambert's law in the lab";
    // The picture shows at least three faces, each over many pixels.
    int shown = 0;
    for (auto& [o, mean] : means) {
        shown += counts[o] >= 100;
        for (double& m : mean) m /= counts[o];
    }
    EXPECT_GE(shown, 3) << what;
    return means;
}

}  // namespace

// The closed forms of the test agree with each other: seenDirection and labDirection are inverse.
TEST(RaytraceLight, TheTestsDirectionMapsAreInverse) {
    for (Model model : {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted})
        for (const Vec3& v : {Vec3{0.9, 0, 0}, Vec3{0.3, -0.5, 0.6}}) {
            const Vec3 d = unit(Vec3{0.2, 0.4, -1});
            const Vec3 back = labDirection(model, v, seenDirection(model, v, d));
            EXPECT_NEAR(mesh4d::norm(back - d), 0, 1e-14) << modelName(model);
        }
    // Relativistic: cos t' = (cos t + b) / (1 + b cos t) for a source at t = 90 degrees from v.
    EXPECT_NEAR(mesh4d::dot(seenDirection(Model::Relativistic, {0.5, 0, 0}, {0, 0, -1}), {1, 0, 0}), 0.5, 1e-15);
}

// An object at rest in the lab lit by a distant light and by a point light, seen by a camera at
// rest and moving at 0.5c and 0.9c across and away from it: every pixel of every face has Lambert's
// shade in the lab (the rest normal, the lab light), in every model; so each face shows the shade
// it shows to a camera at rest. Before the fix the light was used with the camera frame's normals
// and points (contracted and displaced under the boost; displaced under the Galilean map).
TEST(RaytraceLight, AFaceAtRestInTheLabHasItsShadeWhateverTheCameraDoes) {
    const auto dir = testio::tempPath() / ("apparent_light_" + std::to_string(::getpid()));
    const Light lights[] = {{R"("light": {"direction": [0.3, 1, 0.6], "ambient": 0.2},)", false, unit({0.3, 1, 0.6})},
                            {R"("light": {"position": [1.5, 2, -3], "ambient": 0.2},)", true, {1.5, 2, -3}}};
    for (Model model : {Model::Relativistic, Model::Contracted, Model::Instant, Model::Finite})
        for (const Light& light : lights) {
            const auto at_rest = checkEveryPixel(model, {0, 0, 0}, light, dir);
            for (double b : {0.5, 0.9})
                for (const Vec3& along : {Vec3{1, 0, 0}, unit({1, 0, 1})}) {
                    const auto moving = checkEveryPixel(model, b * along, light, dir);
                    if (light.point) continue;
                    // A distant light: one shade per face, the camera at rest's.
                    for (const auto& [o, mean] : moving) {
                        if (!at_rest.count(o)) continue;
                        for (size_t c = 0; c < 3; ++c)
                            EXPECT_NEAR(mean[c], at_rest.at(o)[c], 1.0) << modelName(model) << " b " << b << " face " << o;
                    }
                }
        }
    std::filesystem::remove_all(dir);
}
