#include "pipeline/stage/framing.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mesh4d/angles.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/physics.h"

namespace apparent {

using mesh4d::Vec3;

std::vector<size_t> framedObjects(const Stage& stage) {
    std::vector<size_t> moving, all;
    for (size_t i = 0; i < stage.objects.size(); ++i) {
        const ObjectSpec& spec = stage.objects[i].spec;
        if (spec.mirror) continue;
        all.push_back(i);
        const mesh4d::Motion m = motionOf(spec, Model::Relativistic);
        if (!mesh4d::isUniform(m) || mesh4d::norm(m.velocity) > 0) moving.push_back(i);
    }
    return moving.empty() ? all : moving;
}

Status frameObjects(const Stage& stage, const std::vector<Model>& models, const std::vector<long long>& frames,
                    int width, int height, CameraSpec* camera) {
    if (camera->orthographic())
        return Status::failure("--frame-objects: not with an orthographic camera (set camera.width and its position)");
    // Step: the unit directions from the camera to every point of the framed objects' shapes.
    const std::vector<size_t> framed = framedObjects(stage);
    const Vec3 eye = camera->position * unitsPerLightSecond(stage.scene.units);  // where the cut's outputs have it
    std::vector<Vec3> dirs;
    Vec3 sum{0, 0, 0};
    for (Model model : models) {
        const FrameCutter cutter(stage, model);
        for (long long k : frames) {
            ExportFrame frame;
            std::string error;
            if (!cutter.cut(frameTime(stage.scene.frames, k), 0, &frame, &error))
                return Status::failure("--frame-objects: " + error);
            for (size_t i : framed) {
                const mesh4d::ApparentMesh& m = frame.objects[i];
                for (size_t v = 0; v < m.positions.size(); ++v) {
                    const Vec3 d = m.absolutePosition(v) - eye;
                    const double len = mesh4d::norm(d);
                    if (!(len > 0)) continue;
                    dirs.push_back(d / len);
                    sum = sum + dirs.back();
                }
            }
        }
    }
    if (dirs.empty() || !(mesh4d::norm(sum) > 0))
        return Status::failure("--frame-objects: no object to frame is seen in the figure's frames");
    // Step: turn the forward direction towards the centre of the points' box on the image plane.
    Vec3 f = sum / mesh4d::norm(sum), r, u;
    double hx = 0, hy = 0;
    for (int turn = 0; turn <= kFramingTurns; ++turn) {
        const Vec3 r0 = mesh4d::cross(f, camera->up);
        if (!(mesh4d::norm(r0) > 1e-9))
            return Status::failure("--frame-objects: the objects lie along camera.up; the view cannot be framed");
        r = r0 / mesh4d::norm(r0);
        u = mesh4d::cross(r, f);
        double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
        for (const Vec3& d : dirs) {
            const double z = mesh4d::dot(d, f);
            if (!(z > std::cos(85 * mesh4d::kPi / 180)))
                return Status::failure("--frame-objects: the objects span too wide an angle from the camera to frame");
            const double x = mesh4d::dot(d, r) / z, y = mesh4d::dot(d, u) / z;
            x_lo = std::min(x_lo, x);
            x_hi = std::max(x_hi, x);
            y_lo = std::min(y_lo, y);
            y_hi = std::max(y_hi, y);
        }
        hx = std::max(-x_lo, x_hi);
        hy = std::max(-y_lo, y_hi);
        if (turn == kFramingTurns) break;
        const Vec3 g = f + 0.5 * (x_lo + x_hi) * r + 0.5 * (y_lo + y_hi) * u;
        f = g / mesh4d::norm(g);
    }
    // Step: the field of view with the margin, and the look_at at its old distance.
    const double half_h = (1 + kFramingMargin) * std::max(hy, hx * double(height) / double(width));
    const double fov = 2 * std::atan(half_h) * 180 / mesh4d::kPi;
    if (!(fov <= kMaxFramingFovDeg)) {
        std::ostringstream msg;
        msg << "--frame-objects: the objects would need a field of view of " << fov << " degrees (at most "
            << kMaxFramingFovDeg << ")";
        return Status::failure(msg.str());
    }
    const double dist = mesh4d::norm(camera->look_at - camera->position);
    camera->look_at = camera->position + (dist > 0 ? dist : 1) * f;
    camera->fov_deg = std::max(fov, 1e-6);
    return Status::success();
}

}  // namespace apparent
