// The web file (`apparent render SCENE --format web`, issue 36; docs/GLTF.md "The web file"):
// everything the cut needs and nothing per frame, as one self-contained .glb that is itself an
// apparent glTF scene (docs/SCENES.md "Scenes in glTF"), so `apparent render DIR/scene.web.glb`
// renders what the scene renders. This writer is the inverse of pipeline/input/gltf_scene.h:
//
// - each object is a root node named as the object, whose mesh is the object's rest mesh as its
//   file gave it (before scale, rotation_deg and the node's linear map), with the look's texture
//   coordinates, vertex colours, materials, textures and images (exporters/surface_look.h); its
//   extras hold the object fields of scene_fields.h (t0, velocity or direction with gamma or
//   rapidity, rotation_deg, scale, mirror, exists, material, angular_velocity, acceleration,
//   orbit); its translation is the position, and a linear map other than the identity (an object
//   of a glTF scene) is the node's matrix. Objects sharing a mesh file share the glTF mesh.
// - a keyframed object (a glTF scene's animated node, a root of its scene) keeps its node's own
//   translation, rotation and scale and its translation and rotation channels, copied value for
//   value (float32 as stored, interpolation as written): the reader derives the same path.
// - the camera is the last root node (its rotation from look_at and up, yfov from fov_deg chosen
//   so that the reader's yfov * 180 / pi gives fov_deg back; xmag = width / 2), its extras
//   instant_delay and velocity;
// - the scene's extras: frames (the scene's, whatever --frames renders), model, tolerance, and
//   light unless it is the default.
//
// Exact: every number of the JSON is written as nlohmann's dump writes doubles (shortest form that
// reads back to the same double), and the vectors the reader normalises (direction, orbit.axis,
// light.direction) as the scene gave them (ObjectSpec::direction_given, ...), so that they
// normalise to the same bits. Vertex positions and attributes are float32 (glTF 2.0 section
// 3.6.2.2): a glTF input's are float32 already; an OBJ or PLY input's doubles are rounded, and the
// report says by how much (largest |float(p) - p| over the mesh's bounding-box diagonal). Vertex
// order is kept: a mesh whose triangles run through contiguous vertex ranges per material (every
// glTF input, and any mesh of one material) is written as one primitive per run over its range;
// a mesh whose materials share vertices (an OBJ's) as primitives that all read one set of vertex
// accessors, which the reader reads once (gltf_reader.h).
//
// Refused (one line naming the file and the field; the command exits with 2): a metre scene
// (`units`: a glTF scene is read in light-seconds), a keyframed node under a parent node, object
// names that repeat or hold '#' (a node name must be unique and name a subtree).
#pragma once

#include <string>
#include <vector>

#include "pipeline/input/mesh_input.h"
#include "pipeline/input/scene.h"

namespace apparent {

// What writing the web file found: one line per mesh whose values changed on the way to float32.
struct WebFileReport {
    size_t bytes = 0;
    bool write_failed = false;  // the failure was the output's (exit code 3), not the scene's
    std::vector<std::string> notes;
};

// Writes `path` (atomically: exporters/atomic_file.h) from `scene` (as loaded, tolerance override
// applied), whose objects' meshes are read again from their files under `limits`; `model` is the
// scene's model to record. Fails with one line for what the file cannot carry or cannot be written.
Status writeWebFile(const Scene& scene, Model model, const MeshLimits& limits, const std::string& path,
                    WebFileReport* report);

}  // namespace apparent
