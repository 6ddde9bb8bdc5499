#include "pipeline/raytrace.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <ostream>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "mesh4d/angles.h"
#include "pipeline/worlds.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

// Linear RGB of pixels where a ray meets nothing (a dark blue-grey, so black objects still show).
constexpr std::array<double, 3> kBackground{0.010, 0.012, 0.020};
// Share of a mirror pixel's colour that is the reflection; the rest is the mirror's own shading.
constexpr double kMirrorReflectance = 0.8;

// Linear [0, 1] to 8-bit sRGB (IEC 61966-2-1 transfer curve).
uint8_t toSrgb8(double linear) {
    const double c = std::clamp(linear, 0.0, 1.0);
    const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
    return uint8_t(std::lround(s * 255));
}

// The world of `object` extruded over the union of the spans seen from the camera and from each
// mirror image of the camera, so that reflected rays, which reach further into the past, stay
// inside the history. Existence caps stay real where they clip either span.
mesh4d::World4D traceWorld(const PreparedObject& object, Model model, const Scene& scene,
                           const std::vector<MirrorPlane>& mirrors, long long first, long long last) {
    mesh4d::World4D direct = buildWorld(object, model, scene, first, last);
    if (mirrors.empty()) return direct;
    double tau_a = direct.empty() ? INFINITY : direct.tau_a, tau_b = direct.empty() ? -INFINITY : direct.tau_b;
    bool real_a = direct.cap_a_real, real_b = direct.cap_b_real;
    for (const MirrorPlane& m : mirrors) {
        Scene image = scene;
        image.camera.position = reflectPoint(m, scene.camera.position);
        const mesh4d::World4D w = buildWorld(object, model, image, first, last);
        if (w.empty()) continue;
        if (w.tau_a < tau_a) { tau_a = w.tau_a; real_a = w.cap_a_real; }
        if (w.tau_b > tau_b) { tau_b = w.tau_b; real_b = w.cap_b_real; }
    }
    if (!(tau_a < tau_b)) return direct;
    return mesh4d::extrude(object.rest, direct.motion, tau_a, tau_b, real_a, real_b);
}


}  // namespace

Vec3 pixelDirection(const CameraSpec& camera, int width, int height, int px, int py) {
    // Step: the camera basis: forward f, right r, up u (right-handed, u = r x f).
    const Vec3 f0 = camera.look_at - camera.position;
    const Vec3 f = f0 / mesh4d::norm(f0);
    const Vec3 r0 = mesh4d::cross(f, camera.up);
    const Vec3 r = r0 / mesh4d::norm(r0);
    const Vec3 u = mesh4d::cross(r, f);
    // Step: the pixel centre on the image plane at distance 1.
    const double half_h = std::tan(camera.fov_deg * mesh4d::kPi / 360);
    const double half_w = half_h * double(width) / double(height);
    const double x = (2 * (px + 0.5) / width - 1) * half_w;
    const double y = (1 - 2 * (py + 0.5) / height) * half_h;
    const Vec3 d = f + x * r + y * u;
    return d / mesh4d::norm(d);
}

SceneTracer::SceneTracer(const Scene& scene, const std::vector<PreparedObject>& objects,
                         const std::vector<MirrorPlane>& mirrors, Model model, long long first_frame,
                         long long last_frame)
    : scene_(scene), model_(model), mirrors_(mirrors), mirror_of_object_(objects.size(), -1) {
    for (size_t m = 0; m < mirrors_.size(); ++m) mirror_of_object_[mirrors_[m].object] = int32_t(m);
    // Step: build the static worlds once, then their per-prism trace data (which points into worlds_).
    worlds_.reserve(objects.size());
    for (size_t i = 0; i < objects.size(); ++i) {
        colors_.push_back(objectBaseColor(objects, i));
        worlds_.push_back(traceWorld(objects[i], model, scene, mirrors_, first_frame, last_frame));
    }
    for (const auto& w : worlds_) traces_.push_back(mesh4d::prepareTrace(w));
}

SceneTracer::Hit SceneTracer::nearest(const mesh4d::Ray4D& ray, bool skip_mirrors) const {
    Hit best;
    double s_max = INFINITY;
    for (size_t i = 0; i < traces_.size(); ++i) {
        if (skip_mirrors && mirror_of_object_[i] >= 0) continue;
        if (const auto h = mesh4d::intersectWorld(traces_[i], ray, s_max)) {
            s_max = h->s;
            best.object = int32_t(i);
            best.hit = *h;
        }
    }
    return best;
}

std::array<double, 3> SceneTracer::shade(const Hit& h) const {
    // Lambert: base * (ambient + (1 - ambient) max(0, n . l)), n already turned towards the side
    // the ray arrives from (the surfaces are two-sided, as in the exported glTF).
    const Vec3 n = h.hit.lab_normal;
    const LightSpec& light = scene_.light;
    Vec3 l = light.direction;
    if (light.kind == LightSpec::Kind::Point) {
        const Vec3 to_light = light.position - h.hit.event.x;
        const double len = mesh4d::norm(to_light);
        l = len > 0 ? to_light / len : Vec3{0, 0, 0};
    }
    const double lambert = light.ambient + (1 - light.ambient) * std::max(0.0, mesh4d::dot(n, l));
    const auto& c = colors_[size_t(h.object)];
    return {c[0] * lambert, c[1] * lambert, c[2] * lambert};
}

TracedFrame SceneTracer::traceFrame(long long k, int width, int height) const {
    TracedFrame frame;
    frame.image = RgbImage(width, height);
    frame.object.assign(size_t(width) * size_t(height), -1);
    frame.reflected.assign(size_t(width) * size_t(height), -1);
    const mesh4d::ViewSurface view = viewForFrame(scene_, model_, k);
    tbb::parallel_for(0, height, [&](int py) {
        for (int px = 0; px < width; ++px) {
            const size_t idx = size_t(py) * size_t(width) + size_t(px);
            // Step: the primary ray, back along the past cone (or along t = t_c).
            mesh4d::Ray4D ray;
            ray.origin = {view.t_c, scene_.camera.position};
            ray.direction = pixelDirection(scene_.camera, width, height, px, py);
            ray.along_cone = view.kind == mesh4d::ViewKind::PastCone;
            const Hit hit = nearest(ray, false);
            std::array<double, 3> color = kBackground;
            if (hit.object >= 0) {
                frame.object[idx] = hit.object;
                color = shade(hit);
                const int32_t mirror = mirror_of_object_[size_t(hit.object)];
                if (mirror >= 0) {
                    // Step: one bounce: restart at the hit event with the reflected direction,
                    // still running back in time; other mirrors are not seen in a mirror.
                    mesh4d::Ray4D bounce = ray;
                    bounce.origin = hit.hit.event;
                    bounce.direction = reflectDirection(mirrors_[size_t(mirror)], ray.direction);
                    const Hit second = nearest(bounce, true);
                    std::array<double, 3> reflected = kBackground;
                    if (second.object >= 0) {
                        frame.reflected[idx] = second.object;
                        reflected = shade(second);
                    }
                    for (int c = 0; c < 3; ++c)
                        color[size_t(c)] = (1 - kMirrorReflectance) * color[size_t(c)] + kMirrorReflectance * reflected[size_t(c)];
                }
            }
            uint8_t* p = frame.image.pixel(px, py);
            for (int c = 0; c < 3; ++c) p[c] = toSrgb8(color[size_t(c)]);
        }
    });
    return frame;
}

int raytrace(const RaytraceSettings& settings, std::ostream& log, std::ostream& err) {
    // Step: the stage: scene, models, frames, meshes, mirrors.
    Stage stage;
    StageOptions stage_options = settings.stage;
    stage_options.quiet = settings.quiet;
    std::string error;
    if (!loadStage(stage_options, &stage, err, &error)) {
        err << "error: " << error << "\n";
        return kExitBadInput;
    }
    const long long first = stage.first, last_excl = stage.last_excl;

    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    for (Model model : stage.models) {
        const auto start = std::chrono::steady_clock::now();
        // Step: the folder, then the static worlds once per model, then every frame.
        const std::string dir = (std::filesystem::path(settings.out_dir) / modelName(model)).string();
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        if (ec) {
            err << "error: " << dir << ": cannot create output folder: " << ec.message() << "\n";
            return kExitOutputError;
        }
        const SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, model, first, last_excl - 1);
        for (long long k = first; k < last_excl; ++k) {
            TracedFrame frame;
            arena.execute([&] { frame = tracer.traceFrame(k, settings.width, settings.height); });
            if (!writePng((std::filesystem::path(dir) / (frameName(k) + ".png")).string(), frame.image, &error)) {
                err << "error: " << error << "\n";
                return kExitOutputError;
            }
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!settings.quiet)
            log << modelName(model) << ": " << (last_excl - first) << " frames of " << settings.width << "x"
                << settings.height << " in " << std::fixed << std::setprecision(2) << seconds << " s, " << dir << "/\n"
                << std::defaultfloat;
    }
    return kExitOk;
}

std::vector<long long> figureFrames(const Scene& scene, int columns) {
    const long long total = frameCount(scene.frames);
    std::vector<long long> frames;
    for (int j = 0; j < columns; ++j)
        frames.push_back(columns == 1 ? total / 2 : (long long)std::llround(double(j) * double(total - 1) / (columns - 1)));
    return frames;
}

int figure(const FigureSettings& settings, std::ostream& log, std::ostream& err) {
    // Step: the stage, for the three rows' models and all frames.
    Stage stage;
    StageOptions stage_options = settings.stage;
    stage_options.models = {Model::Instant, Model::Finite, Model::Relativistic};
    stage_options.all_models = false;
    stage_options.frame_from = 0;
    stage_options.frame_to = -1;
    stage_options.quiet = settings.quiet;
    std::string error;
    if (!loadStage(stage_options, &stage, err, &error)) {
        err << "error: " << error << "\n";
        return kExitBadInput;
    }
    const Scene& scene = stage.scene;
    const std::vector<Model>& rows = stage.models;
    // Step: lay out the sheet: rows instant, finite, relativistic; columns sequential frames.
    constexpr int kGap = 4;
    constexpr uint8_t kGapGrey = 96;
    const std::vector<long long> frames = figureFrames(scene, settings.columns);
    RgbImage sheet(settings.columns * settings.width + (settings.columns + 1) * kGap,
                   int(rows.size()) * settings.height + (int(rows.size()) + 1) * kGap);
    std::fill(sheet.rgb.begin(), sheet.rgb.end(), kGapGrey);
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    for (size_t r = 0; r < rows.size(); ++r) {
        const SceneTracer tracer(scene, stage.objects, stage.mirrors, rows[r], frames.front(), frames.back());
        for (size_t c = 0; c < frames.size(); ++c) {
            TracedFrame frame;
            arena.execute([&] { frame = tracer.traceFrame(frames[c], settings.width, settings.height); });
            const int x0 = kGap + int(c) * (settings.width + kGap), y0 = kGap + int(r) * (settings.height + kGap);
            for (int y = 0; y < settings.height; ++y)
                std::copy_n(frame.image.pixel(0, y), 3 * settings.width, sheet.pixel(x0, y0 + y));
        }
    }
    const std::filesystem::path parent = std::filesystem::path(settings.out_path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (ec || !writePng(settings.out_path, sheet, &error)) {
        err << "error: " << (ec ? settings.out_path + ": cannot create folder: " + ec.message() : error) << "\n";
        return kExitOutputError;
    }
    if (!settings.quiet) {
        log << settings.out_path << ": " << sheet.width << "x" << sheet.height << ", rows instant, finite, relativistic;"
            << " frames";
        for (long long k : frames) log << " " << k << " (t = " << frameTime(scene.frames, k) << " s)";
        log << "\n";
    }
    return kExitOk;
}

}  // namespace apparent
