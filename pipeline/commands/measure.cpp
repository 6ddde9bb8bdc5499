#include "pipeline/commands/measure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <ostream>
#include <string>

#include <CLI/CLI.hpp>

#include "mesh4d/angles.h"
#include "pipeline/commands/command.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/frame_cut.h"

namespace apparent {

using mesh4d::Vec3;

ImageAxes imageAxes(const CameraSpec& camera) {
    ImageAxes a;
    const Vec3 f0 = camera.look_at - camera.position;
    a.forward = f0 / mesh4d::norm(f0);
    const Vec3 r0 = mesh4d::cross(a.forward, camera.up);
    a.right = r0 / mesh4d::norm(r0);
    a.up = mesh4d::cross(a.right, a.forward);
    a.position = camera.position;
    a.orthographic = camera.orthographic();
    return a;
}

std::array<double, 2> imagePoint(const ImageAxes& axes, const Vec3& x) {
    const Vec3 d = x - axes.position;
    const double r = mesh4d::dot(d, axes.right), u = mesh4d::dot(d, axes.up);
    if (axes.orthographic) return {r, u};
    const double f = mesh4d::dot(d, axes.forward);
    return {r / f, u / f};
}

ApparentMeasure measureApparent(const mesh4d::ApparentMesh& mesh, const ImageAxes& axes) {
    ApparentMeasure m;
    const size_t n = mesh.positions.size();
    m.points = n;
    m.triangles = mesh.triangles.size();
    if (n == 0) return m;
    // Step: the extents, lab and image, and the mean image point.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    m.lo = {kInf, kInf, kInf};
    m.hi = {-kInf, -kInf, -kInf};
    m.image_lo = {kInf, kInf};
    m.image_hi = {-kInf, -kInf};
    for (size_t i = 0; i < n; ++i) {
        const Vec3 x = mesh.absolutePosition(i);
        m.lo = {std::min(m.lo.x, x.x), std::min(m.lo.y, x.y), std::min(m.lo.z, x.z)};
        m.hi = {std::max(m.hi.x, x.x), std::max(m.hi.y, x.y), std::max(m.hi.z, x.z)};
        const std::array<double, 2> p = imagePoint(axes, x);
        for (int c = 0; c < 2; ++c) {
            m.image_lo[size_t(c)] = std::min(m.image_lo[size_t(c)], p[size_t(c)]);
            m.image_hi[size_t(c)] = std::max(m.image_hi[size_t(c)], p[size_t(c)]);
            m.mean[size_t(c)] += p[size_t(c)] / double(n);
        }
    }
    for (int c = 0; c < 2; ++c) m.centre[size_t(c)] = 0.5 * (m.image_lo[size_t(c)] + m.image_hi[size_t(c)]);

    // Step: the rotation, from the normal equations of c = n_b C - n_r S (weights: rest areas).
    // Positions relative to the mesh's origin (the projection along f is linear).
    double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0, weight = 0;
    std::vector<std::array<double, 4>> rows;  // n_b, n_r, c, w
    rows.reserve(mesh.triangles.size());
    if (mesh.rest_points.size() == n) {
        for (const auto& t : mesh.triangles) {
            const Vec3 q0 = mesh.rest_points[t[0]], q1 = mesh.rest_points[t[1]], q2 = mesh.rest_points[t[2]];
            const Vec3 rest_cross = mesh4d::cross(q1 - q0, q2 - q0);
            const double rest_area = 0.5 * mesh4d::norm(rest_cross);
            if (!(rest_area > 0)) continue;
            const Vec3 normal = rest_cross / (2 * rest_area);
            const Vec3 e1 = mesh.positions[t[1]] - mesh.positions[t[0]], e2 = mesh.positions[t[2]] - mesh.positions[t[0]];
            // Signed area in the (r, u) plane: > 0 counter-clockwise, i.e. facing -f (r x u = -f).
            const double image_area = 0.5 * (mesh4d::dot(e1, axes.right) * mesh4d::dot(e2, axes.up) -
                                             mesh4d::dot(e2, axes.right) * mesh4d::dot(e1, axes.up));
            const double c = image_area / rest_area;
            const double nb = -mesh4d::dot(normal, axes.forward), nr = mesh4d::dot(normal, axes.right);
            const double w = rest_area;
            a11 += w * nb * nb;
            a12 -= w * nb * nr;
            a22 += w * nr * nr;
            b1 += w * nb * c;
            b2 -= w * nr * c;
            weight += w;
            rows.push_back({nb, nr, c, w});
        }
    }
    const double det = a11 * a22 - a12 * a12;
    if (weight > 0 && det > 1e-12 * (a11 + a22) * (a11 + a22)) {
        const double C = (b1 * a22 - b2 * a12) / det, S = (a11 * b2 - a12 * b1) / det;
        m.has_rotation = true;
        m.rotation_deg = std::atan2(S, C) * 180 / mesh4d::kPi;
        m.rotation_scale = std::hypot(C, S);
        double sum = 0;
        const double ct = C / m.rotation_scale, st = S / m.rotation_scale;
        for (const auto& r : rows) {
            const double e = r[2] - (r[0] * ct - r[1] * st);
            sum += r[3] * e * e;
        }
        m.rotation_residual = std::sqrt(sum / weight);
    }

    // Step: the outline's radius in kOutlineDirections directions about the centre.
    m.rim_radius = 0;
    m.min_radius = kInf;
    for (int k = 0; k < kOutlineDirections; ++k) {
        const double phi = 2 * mesh4d::kPi * k / kOutlineDirections;
        const double r = outlineRadius(mesh, axes, m, std::cos(phi), std::sin(phi));
        m.rim_radius = std::max(m.rim_radius, r);
        m.min_radius = std::min(m.min_radius, r);
    }
    return m;
}

double outlineRadius(const mesh4d::ApparentMesh& mesh, const ImageAxes& axes, const ApparentMeasure& m, double dx,
                     double dy) {
    double support = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const std::array<double, 2> p = imagePoint(axes, mesh.absolutePosition(i));
        support = std::max(support, (p[0] - m.centre[0]) * dx + (p[1] - m.centre[1]) * dy);
    }
    return support;
}

namespace {

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

std::string general(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

}  // namespace

int measure(const MeasureSettings& settings, std::ostream& out, std::ostream& err) {
    // Step: the stage, the frames and the marker.
    Stage stage;
    if (std::string error; !loadStage(settings.stage, &stage, err, &error)) {
        err << "error: " << error << "\n";
        return kExitBadInput;
    }
    const Scene& scene = stage.scene;
    long long marker = -1;
    if (!settings.marker.empty()) {
        for (size_t i = 0; i < stage.objects.size(); ++i)
            if (stage.objects[i].spec.name == settings.marker) marker = (long long)i;
        if (marker < 0) {
            std::vector<std::string> names;
            for (const PreparedObject& o : stage.objects) names.push_back(o.spec.name);
            err << "error: --marker: no object named '" << settings.marker << "' in " << scene.path
                << " (objects: " << fieldList(names) << ")\n";
            return kExitBadInput;
        }
    }
    const std::vector<long long> frames = sampledFrames(stage, settings.has_frames);
    const ImageAxes axes = imageAxes(scene.camera);
    if (!settings.quiet)
        out << "Image coordinates: " << (axes.orthographic ? "scene units on the image plane (orthographic camera)"
                                                            : "the tangent plane at distance 1 (perspective camera)")
            << "; rotation about the view's up axis, degrees, positive turning the front towards the right "
               "(pipeline/commands/measure.h)\n";
    out << "model\tframe\tt\tobject\tpoints\timage_x\timage_y\tlab_min\tlab_max\trotation_deg\tresidual\tscale\t"
           "rim_radius\troundness\n";
    // Step: per model and frame, every object's measures, then the marker's position.
    for (Model model : stage.models) {
        FrameCutter cutter(stage, model);
        const SequenceInfo& info = cutter.info();
        for (long long k : frames) {
            ExportFrame frame;
            std::string error;
            if (!cutter.cut(frameTime(scene.frames, k), 0, &frame, &error)) {
                err << "error: " << error << "\n";
                return kExitBadInput;
            }
            std::vector<ApparentMeasure> measures(frame.objects.size());
            for (size_t o = 0; o < frame.objects.size(); ++o) {
                const ApparentMeasure m = measures[o] = measureApparent(frame.objects[o], axes);
                out << modelName(model) << "\t" << k << "\t" << general(frame.t_c) << "\t" << info.objects[o].name << "\t"
                    << m.points;
                if (m.points == 0) {
                    out << "\t(not seen)\n";
                    continue;
                }
                out << "\t" << general(m.image_lo[0]) << ".." << general(m.image_hi[0]) << "\t" << general(m.image_lo[1])
                    << ".." << general(m.image_hi[1]) << "\t[" << general(m.lo.x) << ", " << general(m.lo.y) << ", "
                    << general(m.lo.z) << "]\t[" << general(m.hi.x) << ", " << general(m.hi.y) << ", " << general(m.hi.z)
                    << "]\t" << (m.has_rotation ? fixed(m.rotation_deg, 4) : std::string("-")) << "\t"
                    << (m.has_rotation ? general(m.rotation_residual) : std::string("-")) << "\t"
                    << (m.has_rotation ? general(m.rotation_scale) : std::string("-")) << "\t" << general(m.rim_radius)
                    << "\t" << fixed(m.rim_radius / m.min_radius, 6) << "\n";
            }
            if (marker < 0 || measures[size_t(marker)].points == 0) continue;
            const ApparentMeasure& mk = measures[size_t(marker)];
            for (size_t o = 0; o < measures.size(); ++o) {
                if ((long long)o == marker || measures[o].points == 0) continue;
                const double dx = mk.mean[0] - measures[o].centre[0], dy = mk.mean[1] - measures[o].centre[1];
                const double dist = std::hypot(dx, dy);
                out << modelName(model) << "\t" << k << "\t" << general(frame.t_c) << "\tmarker " << settings.marker
                    << " on " << info.objects[o].name << ": at " << fixed(dist / measures[o].rim_radius, 6)
                    << " of the rim radius (" << general(measures[o].rim_radius) << ") from the outline's centre, towards "
                    << fixed(std::atan2(dy, dx) * 180 / mesh4d::kPi, 2) << " deg (0: the image's right, 90: up)\n";
            }
        }
    }
    return kExitOk;
}


// ---- The command: `apparent measure` ----

namespace {

class MeasureCommand : public Command {
public:
    CLI::App* add(CLI::App* app) override {
        cmd = app->add_subcommand(
            "measure", "Measure the apparent shapes: extent, the rotation of faces about the view's up axis, outline roundness");
        cmd->add_option("scene", mss.stage.scene_path, "Scene file (JSON or glTF)")->required();
        cmd->add_option("--model", measure_model_text, "Model, comma list or all (default: the scene's model)");
        cmd->add_option("--frames", measure_frames_text, "A:B measures frames A..B-1 (default: 5 frames spread over the scene)");
        cmd->add_option("--marker", mss.marker, "An object whose apparent position is given relative to the others' outlines");
        cmd->add_flag("--quiet,-q", mss.quiet, "Only the table");
        addStageLimits(cmd, &mss.stage);
        cmd->footer(
            "Prints per model, frame and object (tab-separated): apparent points, the image extent (orthographic: scene\n"
            "units on the image plane; perspective: the tangent plane at distance 1), the lab bounding box, the rotation\n"
            "about the view's up axis fitted to the projected areas of the faces (degrees; residual; scale, 1 for a pure\n"
            "turn), the outline's largest radius (rim) and roundness (largest over smallest radius). With --marker NAME,\n"
            "NAME's position as a fraction of each other object's rim radius. docs/PICTURES.md, \"Measuring a picture\".");
        return cmd;
    }

    int run(std::ostream& out, std::ostream& err) override {
        if (std::string message; !parseModelList(measure_model_text, &mss.stage, &message)) return usageError(err, message);
        if (!measure_frames_text.empty() && !parseFrames(measure_frames_text, &mss.stage.frame_from, &mss.stage.frame_to))
            return usageError(err, "--frames: '" + measure_frames_text + "' is not A:B with 0 <= A < B");
        mss.has_frames = !measure_frames_text.empty();
        mss.stage.quiet = mss.quiet;
        return guarded([&] { return measure(mss, out, err); }, err);
    }

private:
    MeasureSettings mss;
    std::string measure_model_text, measure_frames_text;
    CLI::App* cmd = nullptr;
};

}  // namespace

std::unique_ptr<Command> measureCommand() { return std::make_unique<MeasureCommand>(); }

}  // namespace apparent
