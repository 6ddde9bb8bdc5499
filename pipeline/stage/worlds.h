// The 4D histories of a scene's objects for one model (Black et al. 2007, section III): each
// object's rest mesh extruded along its worldlines over the proper-time span the requested frames
// can see, clipped to the object's existence (docs/DESIGN.md section 7); and the view cull
// (--cull-view) that leaves an object outside the camera's view uncut in a frame.
#pragma once

#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/slice.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/prepared_object.h"

namespace apparent {

// The 4D history of one object for `model`, extruded over the proper-time span that frames
// [first_frame, last_frame] (global numbers, both included) can see from the scene's camera,
// padded by the object's light-crossing time over 1 - b (b its speed; for an acceleration the
// fastest over the span, the pad at most 64 / |a|, and the span never short of the one
// pathSpanSeen proves: mesh4d/motion/seen.h paddedSpanSeen); only ends of the object's existence
// are real caps.
// Empty (motion set, no tetrahedra) when the object does not exist within that span. In the frame
// the cut is made in (physics.h cutMotionOf: the camera's, or the lab for finite).
mesh4d::World4D buildWorld(const PreparedObject& object, Model model, const Scene& scene, long long first_frame,
                           long long last_frame);

// The same from the parts: `rest` moving with `motion`, extruded over the span that the views
// `first` and `last` (a frame range's first and last) can see, cut to the `exists` of `spec`.
mesh4d::World4D extrudeSeen(const ObjectSpec& spec, const mesh4d::RestMesh& rest, const mesh4d::Motion& motion,
                            const mesh4d::ViewSurface& first, const mesh4d::ViewSurface& last);

// buildWorld for every object, in scene order.
std::vector<mesh4d::World4D> buildWorlds(const std::vector<PreparedObject>& objects, Model model, const Scene& scene,
                                         long long first_frame, long long last_frame);

// buildWorlds for the last use of the objects' rest meshes: each mesh is handed to its world (and
// rotated there in place into the frame of the cut) instead of copied, so the world holds the
// only copy; every objects[i].rest is left empty. The worlds are equal to buildWorlds'.
std::vector<mesh4d::World4D> takeWorlds(std::vector<PreparedObject>* objects, Model model, const Scene& scene,
                                        long long first_frame, long long last_frame);

// View culling (--cull-view): whether a sphere may show in the camera's view, a circular cone
// around the view axis whose half-angle reaches the corners of a kCullAspect:1 frame with the
// camera's vertical field of view (wider than 16:9 and 21:9 screens; a 32:9 screen at the same
// vertical field of view could miss parts at its far left and right).
// An orthographic camera's view (camera.width wide): a cylinder along the view axis in front of
// its image plane, reaching the corners of a frame up to kCullAspect times as tall as wide.
constexpr double kCullAspect = 2.4;
bool inCameraView(const CameraSpec& camera, const mesh4d::BoundingSphere& bound);

}  // namespace apparent
