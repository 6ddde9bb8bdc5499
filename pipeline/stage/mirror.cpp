#include "pipeline/stage/mirror.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <sstream>

#include "mesh4d/box.h"
#include "mesh4d/check.h"
#include "mesh4d/light_factors.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

using mesh4d::Vec3;

Vec3 reflectPoint(const MirrorPlane& m, const Vec3& p) {
    return p - 2 * mesh4d::dot(p - m.point, m.normal) * m.normal;
}

Vec3 reflectDirection(const MirrorPlane& m, const Vec3& d) { return d - 2 * mesh4d::dot(d, m.normal) * m.normal; }

Vec3 reflectRayDirection(const MirrorPlane& m, const mesh4d::CameraMotion& camera, mesh4d::Kinematics kinematics,
                         bool along_cone, const Vec3& d) {
    if (!camera.moving()) return reflectDirection(m, d);
    if (!along_cone) {
        const Vec3 a_n = mesh4d::fromCameraFrameDifference(camera, kinematics, {0, m.normal}).x;
        const Vec3 n = a_n / mesh4d::norm(a_n);
        return d - 2 * mesh4d::dot(d, n) * n;
    }
    const mesh4d::Event lab = mesh4d::fromCameraFrameDifference(camera, kinematics, {-1, d});
    const mesh4d::Event back = mesh4d::toCameraFrameDifference(camera, kinematics, {lab.t, reflectDirection(m, lab.x)});
    const Vec3 r = back.x / -back.t;
    return r / mesh4d::norm(r);
}

mesh4d::ViewSurface imageView(const MirrorPlane& m, const Scene& scene, Model model, double t_c) {
    mesh4d::ViewSurface view = viewAt(scene, model, t_c);
    const mesh4d::CameraMotion camera = cameraMotionOf(scene);
    if (view.kind == mesh4d::ViewKind::Hyperplane) return view;
    if (!camera.moving()) {
        view.apex = reflectPoint(m, view.apex);
        return view;
    }
    const mesh4d::Kinematics kinematics = kinematicsOf(model);
    const mesh4d::Event lab = mesh4d::fromCameraFrame(camera, kinematics, {t_c, scene.camera.position});
    const mesh4d::Event image{lab.t, reflectPoint(m, lab.x)};
    const mesh4d::Event in_cut = model == Model::Finite ? image : mesh4d::toCameraFrame(camera, kinematics, image);
    return {mesh4d::ViewKind::PastCone, in_cut.t, in_cut.x};
}

Status findMirrors(const std::vector<PreparedObject>& objects, const std::string& scene_path,
                   std::vector<MirrorPlane>* mirrors) {
    mirrors->clear();
    for (size_t i = 0; i < objects.size(); ++i) {
        const PreparedObject& o = objects[i];
        if (!o.spec.mirror) continue;
        const std::string where = scene_path + ": " + o.spec.field_path + ".mirror: ";
        // Step: the normal of the largest triangle (a closed mesh's area-weighted normal would
        // vanish); a mirror is at rest, so lab = X0 + q.
        Vec3 n{0, 0, 0};
        for (const auto& t : o.rest.triangles) {
            const Vec3 c = mesh4d::cross(o.rest.positions[t[1]] - o.rest.positions[t[0]],
                                         o.rest.positions[t[2]] - o.rest.positions[t[0]]);
            if (mesh4d::norm(c) > mesh4d::norm(n)) n = c;
        }
        if (!(mesh4d::norm(n) > 0)) return Status::failure(where + "the mesh has no area");
        n = n / mesh4d::norm(n);
        // Step: planarity, to 1e-9 of the mesh's bounding-box diagonal.
        mesh4d::EventBox box;
        for (const Vec3& p : o.rest.positions) box.addPoint(p);
        const Vec3 p0 = o.rest.positions[o.rest.triangles[0][0]];  // on the plane through every vertex, if planar
        double worst = 0;
        for (const auto& t : o.rest.triangles)
            for (uint32_t v : t) worst = std::max(worst, std::fabs(mesh4d::dot(o.rest.positions[v] - p0, n)));
        if (worst > 1e-9 * box.diagonal()) {
            std::ostringstream os;
            os << where << "the mesh is not planar (a vertex lies " << worst << " ls off its plane; a mirror must be flat)";
            return Status::failure(os.str());
        }
        mirrors->push_back({i, o.spec.position + p0, n});
    }
    return Status::success();
}

}  // namespace apparent

namespace apparent {

namespace {

// Share of the reflected object's colour a mirror returns (as the raytracer's kMirrorReflectance).
constexpr double kReflectance = 0.8;
// Opacity given to a mirror's own material in the .glb, so the reflections behind it show.
constexpr double kMirrorAlpha = 0.25;

// Absolute lab position and time of output point i, and the reverse (one place knows the layout).
Vec3 absolutePoint(const mesh4d::ApparentMesh& m, size_t i) { return m.absolutePosition(i); }
double absoluteTime(const mesh4d::ApparentMesh& m, size_t i) { return m.absoluteTime(i); }

// A polygon corner while clipping: position, emission time, rest point, and the input point it
// is (-1 for a point the clip made), so that unclipped corners stay shared between triangles.
struct Corner {
    Vec3 p;
    double t = 0;
    Vec3 q;
    int64_t source = -1;
    double doppler = 1, proper_time = 0;  // interpolated along a clipped side, as t is
};

Corner mix(const Corner& a, const Corner& b, double s) {
    return {a.p + s * (b.p - a.p), a.t + s * (b.t - a.t), a.q + s * (b.q - a.q), -1,
            a.doppler + s * (b.doppler - a.doppler), a.proper_time + s * (b.proper_time - a.proper_time)};
}

// Sutherland-Hodgman: keeps the part of `poly` where dot(n, p - o) >= 0.
std::vector<Corner> clipHalfSpace(const std::vector<Corner>& poly, const Vec3& o, const Vec3& n) {
    std::vector<Corner> out;
    for (size_t i = 0; i < poly.size(); ++i) {
        const Corner& a = poly[i];
        const Corner& b = poly[(i + 1) % poly.size()];
        const double da = mesh4d::dot(n, a.p - o), db = mesh4d::dot(n, b.p - o);
        if (da >= 0) out.push_back(a);
        if ((da >= 0) != (db >= 0)) out.push_back(mix(a, b, da / (da - db)));
    }
    return out;
}

}  // namespace

mesh4d::ApparentMesh reflectAndClip(const mesh4d::ApparentMesh& cut, const MirrorPlane& mirror,
                                    const std::vector<std::array<Vec3, 3>>& polygon, const Vec3& camera) {
    mesh4d::ApparentMesh out;
    // Step: the half-spaces: beyond the mirror plane as seen from the camera, and inside the
    // pyramid from the camera over each mirror triangle.
    const Vec3 beyond = mesh4d::dot(camera - mirror.point, mirror.normal) > 0 ? -mirror.normal : mirror.normal;
    // Each pyramid also has its triangle's box in plane coordinates (u, v): a clipped triangle,
    // beyond the plane, is seen through the plane within the box of its corners' central
    // projections onto it, so pyramids whose box misses that are skipped (a mirror of many
    // triangles costs little more than one).
    struct Pyramid {
        std::array<Vec3, 3> n;
        double lo[2], hi[2];
    };
    const Vec3 across = mesh4d::cross(mirror.normal, std::fabs(mirror.normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0});
    const Vec3 axis_u = across / mesh4d::norm(across);
    const Vec3 axis_v = mesh4d::cross(mirror.normal, axis_u);
    const double camera_height = mesh4d::dot(camera - mirror.point, mirror.normal);
    // A camera in the mirror's plane sees it edge on: no reflection.
    if (!(std::fabs(camera_height) > 1e-12 * (mesh4d::norm(camera - mirror.point) + 1))) return out;
    auto planeCoordinates = [&](const Vec3& p, double uv[2]) {  // p's central projection from the camera
        const double h = mesh4d::dot(p - mirror.point, mirror.normal);
        const Vec3 m = camera + (camera_height / (camera_height - h)) * (p - camera);
        uv[0] = mesh4d::dot(m - mirror.point, axis_u);
        uv[1] = mesh4d::dot(m - mirror.point, axis_v);
    };
    std::vector<Pyramid> pyramids;
    for (const auto& tri : polygon) {
        Pyramid py{};
        py.lo[0] = py.lo[1] = INFINITY;
        py.hi[0] = py.hi[1] = -INFINITY;
        for (size_t e = 0; e < 3; ++e) {
            Vec3 n = mesh4d::cross(tri[e] - camera, tri[(e + 1) % 3] - camera);
            if (mesh4d::dot(n, tri[(e + 2) % 3] - camera) < 0) n = -n;
            py.n[e] = n;
            double uv[2];
            planeCoordinates(tri[e], uv);  // on the plane to rounding (findMirrors): through the camera, exact
            for (int c = 0; c < 2; ++c) {
                py.lo[c] = std::min(py.lo[c], uv[c]);
                py.hi[c] = std::max(py.hi[c], uv[c]);
            }
        }
        // Widened by a relative 1e-9: the box only skips work, the half-spaces decide.
        const double pad = 1e-9 * (std::fabs(py.lo[0]) + std::fabs(py.hi[0]) + std::fabs(py.lo[1]) + std::fabs(py.hi[1]) + 1);
        for (int c = 0; c < 2; ++c) {
            py.lo[c] -= pad;
            py.hi[c] += pad;
        }
        pyramids.push_back(py);
    }
    std::vector<uint32_t> shared(cut.positions.size(), UINT32_MAX);  // output index of each input point
    // Step: reflect each triangle back (swapping two corners keeps its orientation), then clip.
    for (size_t t = 0; t < cut.triangles.size(); ++t) {
        std::vector<Corner> tri;
        for (size_t c : {size_t(0), size_t(2), size_t(1)}) {
            const uint32_t v = cut.triangles[t][c];
            const bool factors = cut.doppler.size() == cut.positions.size();
            tri.push_back({reflectPoint(mirror, absolutePoint(cut, v)), absoluteTime(cut, v), cut.rest_points[v], int64_t(v),
                           factors ? cut.doppler[v] : 1.0, factors ? cut.proper_time[v] : 0.0});
        }
        tri = clipHalfSpace(tri, mirror.point, beyond);
        if (tri.size() < 3) continue;
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (const Corner& c : tri) {
            double uv[2];
            planeCoordinates(c.p, uv);
            for (int k = 0; k < 2; ++k) {
                lo[k] = std::min(lo[k], uv[k]);
                hi[k] = std::max(hi[k], uv[k]);
            }
        }
        for (const Pyramid& py : pyramids) {
            if (lo[0] > py.hi[0] || hi[0] < py.lo[0] || lo[1] > py.hi[1] || hi[1] < py.lo[1]) continue;
            std::vector<Corner> poly = tri;
            for (size_t e = 0; e < 3 && poly.size() >= 3; ++e) poly = clipHalfSpace(poly, camera, py.n[e]);
            if (poly.size() < 3) continue;
            // Step: fan-triangulate the clipped convex polygon into the output.
            std::vector<uint32_t> index;
            for (const Corner& c : poly) {
                if (c.source >= 0 && shared[size_t(c.source)] != UINT32_MAX) {
                    index.push_back(shared[size_t(c.source)]);
                    continue;
                }
                index.push_back(uint32_t(out.positions.size()));
                if (c.source >= 0) shared[size_t(c.source)] = index.back();
                out.positions.push_back(c.p);
                out.emission_times.push_back(c.t);
                out.rest_points.push_back(c.q);
                if (cut.doppler.size() == cut.positions.size()) {
                    out.doppler.push_back(c.doppler);
                    out.proper_time.push_back(c.proper_time);
                }
            }
            for (size_t i = 1; i + 1 < poly.size(); ++i) {
                out.triangles.push_back({index[0], index[i], index[i + 1]});
                out.source_triangles.push_back(cut.source_triangles[t]);
            }
        }
    }
    return out;
}

MirrorReflections::MirrorReflections(const Scene& scene, const std::vector<PreparedObject>& objects,
                                     const std::vector<MirrorPlane>& mirrors, Model model, long long first_frame,
                                     long long last_frame)
    : mirrors_(mirrors),
      camera_(scene.camera.position),
      camera_motion_(cameraMotionOf(scene)),
      model_(model),
      scene_objects_(objects.size()) {
    for (const MirrorPlane& m : mirrors_) names_.push_back(objects[m.object].spec.name);
    // Step (moving camera, cone models): each object's lab history over the span the lab image
    // camera can see, and the speed its refinement bounds (the class comment).
    const bool cone = model == Model::Finite || model == Model::Relativistic;
    if (camera_motion_.moving() && cone) {
        const mesh4d::Event first = cameraInLab(frameTime(scene.frames, first_frame));
        const mesh4d::Event last = cameraInLab(frameTime(scene.frames, last_frame));
        const Vec3& v = camera_motion_.velocity;
        for (size_t mi = 0; mi < mirrors_.size(); ++mi) {
            const MirrorPlane& m = mirrors_[mi];
            const mesh4d::ViewSurface view_first{mesh4d::ViewKind::PastCone, first.t, reflectPoint(m, first.x)};
            const mesh4d::ViewSurface view_last{mesh4d::ViewKind::PastCone, last.t, reflectPoint(m, last.x)};
            for (size_t i = 0; i < objects.size(); ++i) {
                if (objects[i].spec.mirror) continue;
                const mesh4d::Motion lab = motionOf(objects[i].spec, model);
                Target target{mi, i, extrudeSeen(objects[i].spec, objects[i].rest, lab, view_first, view_last)};
                const Vec3 u_r = reflectDirection(m, lab.velocity);
                if (model == Model::Finite) {
                    target.displacement = mesh4d::norm(u_r - v);
                } else {
                    const double one_minus_uv = camera_motion_.one_minus_b2 + mesh4d::dot(v, v - u_r);
                    const double w2 = one_minus_uv * one_minus_uv - lab.one_minus_beta2 * camera_motion_.one_minus_b2;
                    target.displacement = std::sqrt(std::max(w2, 0.0) / camera_motion_.one_minus_b2);
                }
                targets_.push_back(std::move(target));
            }
        }
        return;
    }
    // Step: each non-mirror object's history over the span the image camera can see, once (with a
    // moving camera, the hyperplane models: in the camera's frame, where the apex does not matter).
    if (camera_motion_.moving()) {
        for (size_t mi = 0; mi < mirrors_.size(); ++mi)
            for (size_t i = 0; i < objects.size(); ++i)
                if (!objects[i].spec.mirror)
                    targets_.push_back({mi, i, buildWorld(objects[i], model, scene, first_frame, last_frame)});
        return;
    }
    for (size_t mi = 0; mi < mirrors_.size(); ++mi) {
        Scene image = scene;
        image.camera.position = reflectPoint(mirrors_[mi], scene.camera.position);
        for (size_t i = 0; i < objects.size(); ++i) {
            if (objects[i].spec.mirror) continue;
            targets_.push_back({mi, i, buildWorld(objects[i], model, image, first_frame, last_frame)});
        }
    }
}

void MirrorReflections::append(const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings,
                               std::vector<mesh4d::ApparentMesh>* objects, const std::vector<double>* object_tolerances,
                               bool light_factors, const std::vector<double>* object_attribute_tolerances) const {
    // Step: each mirror as the camera sees it in this frame (its own cut, `exists` included):
    // what is seen through it is clipped to these triangles. Slivers give no pyramid.
    APPARENT_CHECK(objects->size(), >=, scene_objects_);  // the frame's scene objects come first
    std::vector<std::vector<std::array<Vec3, 3>>> seen(mirrors_.size());
    for (size_t mi = 0; mi < mirrors_.size(); ++mi) {
        const mesh4d::ApparentMesh& m = (*objects)[mirrors_[mi].object];
        for (const auto& t : m.triangles) {
            const std::array<Vec3, 3> tri{m.absolutePosition(t[0]), m.absolutePosition(t[1]), m.absolutePosition(t[2])};
            const double area2 = mesh4d::norm(mesh4d::cross(tri[1] - tri[0], tri[2] - tri[0]));
            const double longest = std::max({mesh4d::norm(tri[1] - tri[0]), mesh4d::norm(tri[2] - tri[1]),
                                             mesh4d::norm(tri[0] - tri[2])});
            if (area2 > 1e-12 * longest * longest) seen[mi].push_back(tri);
        }
    }
    if (camera_motion_.moving()) {
        appendMoving(view, settings, objects, object_tolerances, seen, light_factors, object_attribute_tolerances);
        return;
    }
    for (const Target& target : targets_) {
        const MirrorPlane& m = mirrors_[target.mirror];
        if (seen[target.mirror].empty()) {  // the mirror shows nothing: not in view or not existing
            objects->emplace_back();
            continue;
        }
        mesh4d::ViewSurface image = view;
        image.apex = reflectPoint(m, view.apex);
        mesh4d::SliceSettings own = settings;
        if (object_tolerances) own.tolerance = (*object_tolerances)[target.object];
        if (object_attribute_tolerances) own.attribute_tolerance = (*object_attribute_tolerances)[target.object];
        mesh4d::ApparentMesh cut = mesh4d::sliceWorld(target.world, image, own);
        // The light factors of the path through the mirror: a mirror at rest changes no frequency,
        // so they are those seen by the image of the camera.
        if (light_factors) mesh4d::addLightFactors(target.world, image, &cut);
        objects->push_back(reflectAndClip(cut, m, seen[target.mirror], camera_));
    }
}

mesh4d::Event MirrorReflections::cameraInLab(double t_c) const {
    return mesh4d::fromCameraFrame(camera_motion_, kinematicsOf(model_), {t_c, camera_});
}

void MirrorReflections::appendMoving(const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings,
                                     std::vector<mesh4d::ApparentMesh>* objects,
                                     const std::vector<double>* object_tolerances,
                                     const std::vector<std::vector<std::array<Vec3, 3>>>& seen,
                                     bool light_factors, const std::vector<double>* object_attribute_tolerances) const {
    const mesh4d::Kinematics kinematics = kinematicsOf(model_);
    const bool cone = view.kind == mesh4d::ViewKind::PastCone;
    // Step (cone models): the camera's lab event at this frame's camera time, and each mirror as
    // the camera sees it, taken back to the lab (the events of its cut; slivers give no pyramid).
    const mesh4d::Event camera_lab = cameraInLab(view.t_c);  // used on the cone only
    std::vector<std::vector<std::array<Vec3, 3>>> seen_lab(mirrors_.size());
    for (size_t mi = 0; mi < mirrors_.size() && cone; ++mi) {
        const mesh4d::ApparentMesh& m = (*objects)[mirrors_[mi].object];
        auto lab = [&](uint32_t i) {
            return mesh4d::fromCameraFrame(camera_motion_, kinematics, {m.absoluteTime(i), m.absolutePosition(i)}).x;
        };
        for (const auto& t : m.triangles) {
            const std::array<Vec3, 3> tri{lab(t[0]), lab(t[1]), lab(t[2])};
            const double area2 = mesh4d::norm(mesh4d::cross(tri[1] - tri[0], tri[2] - tri[0]));
            const double longest = std::max({mesh4d::norm(tri[1] - tri[0]), mesh4d::norm(tri[2] - tri[1]),
                                             mesh4d::norm(tri[0] - tri[2])});
            if (area2 > 1e-12 * longest * longest) seen_lab[mi].push_back(tri);
        }
    }
    for (const Target& target : targets_) {
        const MirrorPlane& m = mirrors_[target.mirror];
        if (seen[target.mirror].empty() || (cone && seen_lab[target.mirror].empty())) {
            objects->emplace_back();
            continue;
        }
        mesh4d::SliceSettings own = settings;
        if (object_tolerances) own.tolerance = (*object_tolerances)[target.object];
        if (object_attribute_tolerances) own.attribute_tolerance = (*object_attribute_tolerances)[target.object];
        if (!cone) {
            // Step (hyperplane models): the mirror's plane at the view's time in the camera's frame:
            // x' with n.(lab position - point) = 0, lab position = A x' + b(t'), A symmetric: normal
            // A n through the point of the line from the camera along it.
            const Vec3 a_n = mesh4d::fromCameraFrameDifference(camera_motion_, kinematics, {0, m.normal}).x;
            const double off = mesh4d::dot(m.normal, mesh4d::fromCameraFrame(camera_motion_, kinematics, {view.t_c, camera_}).x - m.point);
            const MirrorPlane now{m.object, camera_ - a_n * (off / mesh4d::norm2(a_n)), a_n / mesh4d::norm(a_n)};
            mesh4d::ApparentMesh cut = mesh4d::sliceWorld(target.world, view, own);
            if (light_factors) mesh4d::addLightFactors(target.world, view, &cut);
            objects->push_back(reflectAndClip(cut, now, seen[target.mirror], camera_));
            continue;
        }
        // Step (cone models): the lab cut for the image camera, its light factors with the image
        // camera moving at the reflected velocity, the reflection and clip in the lab.
        const mesh4d::ViewSurface image{mesh4d::ViewKind::PastCone, camera_lab.t, reflectPoint(m, camera_lab.x)};
        own.displacement = target.displacement;
        mesh4d::ApparentMesh cut = mesh4d::sliceWorld(target.world, image, own);
        const Vec3 v_r = reflectDirection(m, camera_motion_.velocity);
        cut.doppler.resize(light_factors ? cut.positions.size() : 0);
        cut.proper_time.resize(light_factors ? cut.positions.size() : 0);
        for (size_t i = 0; i < cut.doppler.size(); ++i) {
            cut.doppler[i] = mesh4d::dopplerFactor(target.world.motion, image.kind, image.apex, cut.absolutePosition(i), v_r);
            cut.proper_time[i] = mesh4d::properTimeAt(target.world.motion, cut.rest_points[i], cut.absoluteTime(i));
        }
        mesh4d::ApparentMesh out = reflectAndClip(cut, m, seen_lab[target.mirror], camera_lab.x);
        // Step: every output event (the virtual source) into the camera's frame, origin and local
        // parts apart (the map is affine).
        const mesh4d::Event origin = mesh4d::toCameraFrame(camera_motion_, kinematics, {out.time_origin, out.origin});
        out.origin = origin.x;
        out.time_origin = origin.t;
        for (size_t i = 0; i < out.positions.size(); ++i) {
            const mesh4d::Event d =
                mesh4d::toCameraFrameDifference(camera_motion_, kinematics, {out.emission_times[i], out.positions[i]});
            out.positions[i] = d.x;
            out.emission_times[i] = d.t;
        }
        objects->push_back(std::move(out));
    }
}

void MirrorReflections::describe(SequenceInfo* info) const {
    const std::vector<ExportObject> originals = info->objects;
    for (const MirrorPlane& m : mirrors_) info->objects[m.object].base_color[3] = kMirrorAlpha;
    for (const Target& target : targets_) {
        ExportObject o = originals[target.object];
        o.name = o.name + " (mirror " + names_[target.mirror] + ")";
        o.mirror_index = int(target.mirror);
        o.mirror = names_[target.mirror];
        for (int c = 0; c < 3; ++c) o.base_color[size_t(c)] *= kReflectance;
        info->objects.push_back(o);
    }
}

}  // namespace apparent
