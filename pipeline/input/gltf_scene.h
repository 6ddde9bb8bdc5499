// A scene authored in glTF (docs/SCENES.md "Scenes in glTF"): the camera, the objects and the scene
// settings come from the default scene of a .gltf/.glb file instead of a JSON scene file.
//
// - Objects: every node whose `extras` hold an object field other than name, mesh and position
//   (t0, velocity, direction, gamma, rapidity, rotation_deg, scale, mirror, exists) is an object.
//   Its name is the node name (unique, without '#'), its mesh the node's subtree
//   ("file.gltf#Name"), its position the node's world translation, and its world rotation and
//   scale apply to the rest mesh (ObjectSpec::linear). The extras are read by the JSON scene's own
//   object readers (scene_fields.h), with the same errors at "nodes[i].extras.<field>". Objects
//   cannot nest.
// - Keyframed paths: an object node whose translation or rotation is animated (LINEAR, STEP or
//   CUBICSPLINE channels, gltf_animation.h; a spline through its cubicSamples) follows that path
//   (mesh4d/motion/keyed.h): the keys, composed with the parent's transform as the static values
//   are, give ObjectSpec::keys; the pose at t0 is the rest pose (position, linear) and the path's
//   mean velocity is `velocity`. Refused: a field that states motion in its extras (scene_fields.h
//   ObjectField::states_motion: velocity, direction, gamma, rapidity, angular_velocity,
//   acceleration and the fields of the kinds of mesh4d/motion/kinds.h) or mirror, a matrix, a STEP jump, a turn under a parent that shears
//   or scales unequally, a rotation spline through 0, the centre at >= c on any segment (the speed
//   and the lab time). Channels on nodes that are not objects are warnings.
// - Camera: the first node with a camera (glTF cameras look down local -Z, +Y up; yfov gives
//   fov_deg); its extras may hold instant_delay, velocity, and look_at and up as written (kept
//   when they look the way the node does within 1e-6 rad, else a warning).
// - The scene's extras may hold frames, light, model and tolerance, as in the JSON file.
// Keys the reader does not know are warnings (Scene::warnings), not errors, because other tools
// keep custom properties in extras; a key that looks like a misspelt field names the field, and
// a node left out because its extras hold only such near-misses is reported. The file is parsed
// once (gltf_document.h): the objects' meshes read the same parsed document.
#pragma once

#include <string>

#include "pipeline/input/scene.h"

namespace apparent {

Status loadGltfScene(const std::string& path, Scene* scene);

}  // namespace apparent
