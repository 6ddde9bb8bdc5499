// Planar mirrors at rest (scene objects with "mirror": true) and the retarded reflections they
// show (docs/DESIGN.md section 8). Light from event X reaching the camera C by way of the mirror plane
// travels |X - M| + |M - C| = |X - C'|, C' the mirror image of C: it lies on the past cone of
// the image camera (t_c, C'). So the reflection is the apparent surface for C', reflected back
// through the plane, where the line of sight from C passes through the mirror polygon.
#pragma once

#include <string>
#include <vector>

#include "mesh4d/event.h"
#include "mesh4d/slice.h"
#include "exporters/frame_mesh.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/prepared_object.h"

namespace apparent {

struct MirrorPlane {
    size_t object = 0;          // index of the mirror object in the scene
    mesh4d::Vec3 point;         // a lab point of the plane
    mesh4d::Vec3 normal;        // unit normal (sign arbitrary)
};

// Reflections through the plane (point, and direction).
mesh4d::Vec3 reflectPoint(const MirrorPlane& m, const mesh4d::Vec3& p);
mesh4d::Vec3 reflectDirection(const MirrorPlane& m, const mesh4d::Vec3& d);

// The direction a backward ray leaves mirror `m` with, in the camera's frame of a moving camera
// (the mirror moves there): the lab's reflection seen in that frame (mesh4d/motion/camera_frame.h). Along
// the cone the null direction (-1, d) is taken to the lab, its spatial part reflected, and taken
// back, d' the spatial part over minus the time part; on a hyperplane (no light travel) d is
// reflected through the mirror's plane as it is in that frame, normal A n (A the spatial part of
// the map to the lab, symmetric). For a camera at rest: reflectDirection.
mesh4d::Vec3 reflectRayDirection(const MirrorPlane& m, const mesh4d::CameraMotion& camera, mesh4d::Kinematics kinematics,
                                 bool along_cone, const mesh4d::Vec3& d);

// The view of the mirror image of the camera at camera time t_c (frame time), in the frame the
// scene's cuts are made in (physics.h cutMotionOf): the past cone of the image of the camera's lab
// event, (E.t, reflection of E.x), mapped into the camera's frame (relativistic) or left in the lab
// (finite); on a hyperplane the view itself (where the camera is does not matter there).
mesh4d::ViewSurface imageView(const MirrorPlane& m, const Scene& scene, Model model, double t_c);

// The planes of the scene's mirror objects, in scene order. A mirror's mesh must be planar to
// 1e-9 of its size; otherwise the message names the object's `mirror` field and the offset.
Status findMirrors(const std::vector<PreparedObject>& objects, const std::string& scene_path,
                   std::vector<MirrorPlane>* mirrors);

// The retarded reflections of a scene's mirrors for one model, as extra output objects: for
// every mirror and every non-mirror object, "<object> (mirror <mirror>)". Worlds are extruded
// once, over the span the image cameras can see; each frame then cuts them with the image
// camera's view, reflects the cut back through the plane (orientation restored) and clips it to
// the pyramid from the camera over each mirror triangle, and to the far side of the plane.
// The clip is to the mirror as the camera sees it in that frame (the mirror's own cut, so its
// `exists` applies: no reflection where the mirror is not yet or no longer there).
// Limits: one bounce (mirrors are not seen in mirrors), the clip is exact on the straight output
// edges (it adds points on them; emission times and rest points of those are interpolated
// linearly along the edge), and a mirror whose existence begins or ends within view is clipped to
// its cut's chords of the cap curve (docs/DESIGN.md section 6), not the curve.
//
// A moving camera (camera.velocity v; mirrors stay at rest in the lab). Light reaching the camera's
// lab event E by way of the mirror lies on the lab's past cone of the image event E' = (E.t,
// reflection of E.x); the camera-frame map (Lorentz or Galilean, mesh4d/motion/camera_frame.h) takes
// cones to cones, so in the camera's frame the apex is the image of E'. The reflections are made
// where the mirror is at rest, then mapped:
//   - finite and relativistic: each object's lab history (its lab motion and rest mesh) is cut by
//     the lab's cone of E', reflected through the plane and clipped in the lab (the camera at E.x,
//     the pyramids over the mirror's own cut taken back to the lab), and every output event, the
//     virtual source (emission time, reflected position), is mapped into the camera's frame, where
//     it lies on the camera's past cone along the direction the reflected light arrives from (the
//     camera's frame sees the mirror move, so this is the mirror's reflection of spacetime, not a
//     reflection of space). The emission time is the virtual source's: in finite the real one; in
//     relativistic the real emission event's differs by the moving mirror's time shift. Refinement
//     bounds the mapped output: the displacement (1, u_R) (u_R the reflected lab velocity) maps to
//     the spatial length g_v sqrt((1 - u_R.v)^2 - (1 - u^2)(1 - v^2)) (relativistic) or |u_R - v|
//     (finite), the factor of the delay's error (SliceSettings::displacement), objects at rest included.
//     Their rest points are the object's unrotated ones (the lab's; no Thomas-Wigner rotation).
//   - instant and contracted (no light travel): in the camera's frame, each object's cut by the
//     frame's hyperplane is reflected through the mirror's plane at that time (the lab plane seen
//     in the camera's frame: contracted across v in contracted) and clipped from the camera.
//   Doppler and proper time: the same factors along the reflected path. The mirror is at rest in
//   the lab and returns the lab frequency, which the camera receives moving: D = g_v (1 - v.n2) /
//   (g_u (1 - u.n1)) (relativistic) or (1 - v.n2) / (1 - u.n1) (finite), n1 the lab direction from
//   the source to the mirror point, n2 from there to the camera (= the direction to the image camera,
//   with the reflected v); the clock at the real emission event. 1 on the hyperplanes.
class MirrorReflections {
public:
    MirrorReflections(const Scene& scene, const std::vector<PreparedObject>& objects,
                      const std::vector<MirrorPlane>& mirrors, Model model, long long first_frame, long long last_frame);

    bool empty() const { return mirrors_.empty(); }
    // Appends the reflections for `view` to `objects`, mirror by mirror, object by object (the
    // order of describe()). `view` is the frame's view for the camera; its apex is replaced.
    // `objects` must already hold the frame's cut of every scene object, in scene order: each
    // mirror's cut is what its reflections are clipped to (empty cut: empty reflections).
    // `object_tolerances` (one per scene object), when given, replaces settings.tolerance for each
    // object's reflections (the stage's per-object tolerances), and `object_attribute_tolerances`
    // settings.attribute_tolerance (Stage::attribute_tolerances). `light_factors`: whether the
    // reflections get their Doppler factors and proper times (false: left empty, as no sink reads them).
    void append(const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings,
                std::vector<mesh4d::ApparentMesh>* objects, const std::vector<double>* object_tolerances = nullptr,
                bool light_factors = true, const std::vector<double>* object_attribute_tolerances = nullptr) const;
    // Appends the reflections' names and colours (the object's, darkened by the mirror's
    // reflectance) to info->objects, and makes the mirrors themselves translucent so that the
    // reflections behind them show from the camera.
    void describe(SequenceInfo* info) const;

private:
    struct Target {
        size_t mirror = 0, object = 0;
        mesh4d::World4D world;  // the object's history over the span the image camera sees
        double displacement = -1;  // moving camera, cone models: SliceSettings::displacement
    };
    std::vector<MirrorPlane> mirrors_;
    std::vector<std::string> names_;
    mesh4d::Vec3 camera_;
    mesh4d::CameraMotion camera_motion_;  // moving: the reflections are made as the class comment says
    Model model_ = Model::Relativistic;
    // The camera's lab event at camera time t_c (its proper time; the lab's in Galilean models).
    mesh4d::Event cameraInLab(double t_c) const;
    // append() for a moving camera (the class comment); `seen`: each mirror's cut triangles.
    void appendMoving(const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings,
                      std::vector<mesh4d::ApparentMesh>* objects, const std::vector<double>* object_tolerances,
                      const std::vector<std::vector<std::array<mesh4d::Vec3, 3>>>& seen, bool light_factors,
                      const std::vector<double>* object_attribute_tolerances) const;
    size_t scene_objects_ = 0;
    std::vector<Target> targets_;
};

// The part of `cut` (an apparent mesh in absolute lab coordinates, as cut for the image camera)
// reflected through `mirror` and clipped to what `camera` sees through the triangles `polygon`.
mesh4d::ApparentMesh reflectAndClip(const mesh4d::ApparentMesh& cut, const MirrorPlane& mirror,
                                    const std::vector<std::array<mesh4d::Vec3, 3>>& polygon, const mesh4d::Vec3& camera);

}  // namespace apparent
