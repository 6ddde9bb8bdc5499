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
#include "pipeline/prepared_object.h"

namespace apparent {

struct MirrorPlane {
    size_t object = 0;          // index of the mirror object in the scene
    mesh4d::Vec3 point;         // a lab point of the plane
    mesh4d::Vec3 normal;        // unit normal (sign arbitrary)
};

// Reflections through the plane (point, and direction).
mesh4d::Vec3 reflectPoint(const MirrorPlane& m, const mesh4d::Vec3& p);
mesh4d::Vec3 reflectDirection(const MirrorPlane& m, const mesh4d::Vec3& d);

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
    // object's reflections (the stage's per-object tolerances).
    void append(const mesh4d::ViewSurface& view, const mesh4d::SliceSettings& settings,
                std::vector<mesh4d::ApparentMesh>* objects, const std::vector<double>* object_tolerances = nullptr) const;
    // Appends the reflections' names and colours (the object's, darkened by the mirror's
    // reflectance) to info->objects, and makes the mirrors themselves translucent so that the
    // reflections behind them show from the camera.
    void describe(SequenceInfo* info) const;

private:
    struct Target {
        size_t mirror = 0, object = 0;
        mesh4d::World4D world;  // the object's history over the span the image camera sees
    };
    std::vector<MirrorPlane> mirrors_;
    std::vector<std::string> names_;
    mesh4d::Vec3 camera_;
    size_t scene_objects_ = 0;
    std::vector<Target> targets_;
};

// The part of `cut` (an apparent mesh in absolute lab coordinates, as cut for the image camera)
// reflected through `mirror` and clipped to what `camera` sees through the triangles `polygon`.
mesh4d::ApparentMesh reflectAndClip(const mesh4d::ApparentMesh& cut, const MirrorPlane& mirror,
                                    const std::vector<std::array<mesh4d::Vec3, 3>>& polygon, const mesh4d::Vec3& camera);

}  // namespace apparent
