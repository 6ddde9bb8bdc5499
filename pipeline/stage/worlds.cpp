#include "pipeline/stage/worlds.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "mesh4d/angles.h"
#include "mesh4d/motion/seen.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

// The rest mesh `*mesh` in the frame of the cut, rotated in place where that needs it (as
// restInCameraFrame, without the copy).
const mesh4d::RestMesh& rotateInCameraFrame(mesh4d::RestMesh* mesh, const mesh4d::MotionInCameraFrame& m) {
    if (m.rotated)
        for (Vec3& p : mesh->positions) p = mesh4d::apply(m.rotation, p);
    return *mesh;
}

// extrudeSeen; with `take` (then `rest` is *take) the mesh is handed to the world, not copied.
mesh4d::World4D extrudeSeenFrom(const ObjectSpec& s, const mesh4d::RestMesh& rest, mesh4d::RestMesh* take,
                                const mesh4d::Motion& motion, const mesh4d::ViewSurface& first,
                                const mesh4d::ViewSurface& last) {
    // Step: the proper-time span the requested frames can see, padded (mesh4d/motion/seen.h).
    const mesh4d::ProperTimeSpan open = mesh4d::paddedSpanSeen(rest, motion, first, last);
    // Step: clip the span to the object's existence; only those ends are real caps.
    const bool cap_a_real = s.exists_from > open.lo;
    const bool cap_b_real = s.exists_to < open.hi;
    const double tau_a = cap_a_real ? s.exists_from : open.lo;
    const double tau_b = cap_b_real ? s.exists_to : open.hi;
    if (!(tau_a < tau_b)) {
        mesh4d::World4D empty;
        empty.motion = motion;
        return empty;
    }
    if (take) return mesh4d::extrude(std::move(*take), motion, tau_a, tau_b, cap_a_real, cap_b_real);
    return mesh4d::extrude(rest, motion, tau_a, tau_b, cap_a_real, cap_b_real);
}

}  // namespace

namespace {

// buildWorld; with `take` (object.rest itself) the rest mesh is moved into the world, rotated in
// place into the camera's frame where that needs it, instead of copied.
mesh4d::World4D buildWorldFrom(const PreparedObject& object, mesh4d::RestMesh* take, Model model, const Scene& scene,
                               long long first_frame, long long last_frame) {
    // In the frame the cut is made in (the camera's rest frame; the lab for finite): its motion
    // and rest points.
    const mesh4d::MotionInCameraFrame in_camera = cutMotionOf(object.spec, model, scene);
    mesh4d::RestMesh rotated;
    const mesh4d::RestMesh& rest = take ? rotateInCameraFrame(take, in_camera) : restInCameraFrame(object.rest, in_camera, &rotated);
    return extrudeSeenFrom(object.spec, rest, take, in_camera.motion, viewForFrame(scene, model, first_frame),
                           viewForFrame(scene, model, last_frame));
}

}  // namespace

mesh4d::World4D buildWorld(const PreparedObject& object, Model model, const Scene& scene, long long first_frame,
                           long long last_frame) {
    return buildWorldFrom(object, nullptr, model, scene, first_frame, last_frame);
}

mesh4d::World4D extrudeSeen(const ObjectSpec& s, const mesh4d::RestMesh& rest, const mesh4d::Motion& motion,
                            const mesh4d::ViewSurface& first, const mesh4d::ViewSurface& last) {
    return extrudeSeenFrom(s, rest, nullptr, motion, first, last);
}

std::vector<mesh4d::World4D> buildWorlds(const std::vector<PreparedObject>& objects, Model model, const Scene& scene,
                                         long long first_frame, long long last_frame) {
    std::vector<mesh4d::World4D> worlds;
    worlds.reserve(objects.size());
    for (const PreparedObject& o : objects) worlds.push_back(buildWorld(o, model, scene, first_frame, last_frame));
    return worlds;
}

std::vector<mesh4d::World4D> takeWorlds(std::vector<PreparedObject>* objects, Model model, const Scene& scene,
                                        long long first_frame, long long last_frame) {
    std::vector<mesh4d::World4D> worlds;
    worlds.reserve(objects->size());
    for (PreparedObject& o : *objects) {
        worlds.push_back(buildWorldFrom(o, &o.rest, model, scene, first_frame, last_frame));
        o.rest = {};  // left valid and empty whether or not the world took it
    }
    return worlds;
}

bool inCameraView(const CameraSpec& camera, const mesh4d::BoundingSphere& bound) {
    if (camera.orthographic()) {
        // The orthographic view: a cylinder along the view axis from the image plane on, as wide
        // as the view's corners in a frame no narrower than 1:kCullAspect (portrait).
        const Vec3 f0 = camera.look_at - camera.position;
        const Vec3 f = f0 / mesh4d::norm(f0);
        const Vec3 d = bound.center - camera.position;
        const double depth = mesh4d::dot(d, f);
        const double off_axis = mesh4d::norm(d - f * depth);
        const double half_w = 0.5 * camera.width, half_h = half_w * kCullAspect;
        if (!(depth >= -bound.radius) && std::isfinite(depth)) return false;  // behind the image plane
        return !(off_axis - bound.radius > std::sqrt(half_w * half_w + half_h * half_h));
    }
    const Vec3 d = bound.center - camera.position;
    const double dist = mesh4d::norm(d);
    if (!(dist > bound.radius)) return true;  // the camera is inside the sphere (or NaN: keep it)
    const Vec3 f = camera.look_at - camera.position;
    const double cos_angle = std::clamp(mesh4d::dot(d, f) / (dist * mesh4d::norm(f)), -1.0, 1.0);
    const double angle = std::acos(cos_angle);                  // centre off the view axis
    const double angular_radius = std::asin(bound.radius / dist);
    const double half_fov = 0.5 * camera.fov_deg * mesh4d::kPi / 180.0;
    const double half_diagonal = std::atan(std::tan(half_fov) * std::sqrt(1 + kCullAspect * kCullAspect));
    return angle - angular_radius <= half_diagonal;
}

}  // namespace apparent
