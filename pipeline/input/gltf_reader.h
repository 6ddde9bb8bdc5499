// glTF 2.0 meshes (.gltf and .glb), read with tinygltf and converted to our types.
//
// What is read: every TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN primitive reached from the
// default scene (or the first scene, or every root node when there is no scene) through the node
// hierarchy, with node transforms (matrix or TRS) applied in double; indexed and non-indexed;
// any byteStride; sparse accessors; KHR_draco_mesh_compression (decoded by tinygltf built with
// TINYGLTF_ENABLE_DRACO). POINTS and LINES primitives are skipped and counted. "file.glb#Name"
// reads only the subtree of the node called Name, in that node's own frame (its transform and its
// ancestors' are not applied: the scene places the object). Primitives of one mesh that read the
// same vertex accessors (POSITION and any TEXCOORD_0, TEXCOORD_1, COLOR_0) share those vertices,
// as one mesh of several materials whose faces meet at shared vertices is written (the web file,
// pipeline/run/web_file.h); other primitives each add their own.
//
// What is refused, with a one-line message naming the file and the glTF path (for example
// "meshes[0].primitives[0].indices: index 9 out of range (8 vertices)"): buffer URIs that leave
// the glTF file's folder (absolute paths, "..") or name missing files, accessors or views that
// reach outside their buffers, POSITION that is not FLOAT VEC3, non-finite positions, cycles in
// the node graph, counts over the limits. tinygltf indexes some arrays without checking them
// while it decodes Draco (tiny_gltf.h 2.7.0, ParseDracoExtension), so those references are
// checked on the JSON before tinygltf sees the file.
//
// The file is read and parsed once per run (gltf_document.h): reading several nodes of one file,
// as the objects of a glTF scene do, parses it once. The node graph is walked by gltf_nodes.h.
#pragma once

#include <string>

#include "pipeline/input/mesh_input.h"

namespace apparent {

Status readGltf(const std::string& path, const MeshLimits& limits, LoadedMesh* out, MeshWarnings* warnings);

}  // namespace apparent
