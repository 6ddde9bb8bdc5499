// A glTF file (.gltf or .glb) read, checked and parsed by tinygltf once per run.
//
// openGltf reads the file (size-limited), checks on the JSON what tinygltf would not (buffer URIs
// that leave the file's folder, the Draco references and payloads tinygltf 2.7 follows unchecked:
// every Draco bufferView is decoded once here), then parses it with tinygltf, whose file access
// is confined to the file's folder (gltf_reader.h lists what is refused). The parsed document is
// kept in a small cache keyed by the resolved path, so that a scene whose objects are nodes of one
// file (a glTF scene, or many "file.glb#Node" meshes) parses it once, not once per object.
//
// The cache: an entry is reused only while every file it was read from (the glTF file and its
// external buffers) has the same bytes, compared by size and a 64-bit hash after reading them
// again (reading is cheap next to the JSON parse and the Draco decoding), and while each is within
// the caller's limits.max_file_bytes. Failures are not kept. At most kMaxCachedBytes of file bytes
// are kept (least recently used dropped first); a larger file is parsed and not kept. Thread-safe:
// one lock, held while parsing. clearGltfCache() releases everything (for example once a scene's
// meshes are loaded).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "pipeline/input/mesh_input.h"

namespace apparent {

constexpr size_t kMaxCachedBytes = size_t(1) << 30;

struct GltfDocument {
    tinygltf::Model model;
    std::vector<std::string> warnings;  // tinygltf's warnings, first line
    // The `extras` of each node and scene as written (null where absent), indexed like
    // model.nodes and model.scenes: tinygltf's Value drops null elements of arrays, and a scene
    // field such as exists: [null, 5] needs them.
    std::vector<nlohmann::json> node_extras, scene_extras;
    // The arrays "materials", "textures", "samplers" and "images" as written (empty arrays where
    // absent), for the outputs that carry the model's look (gltf_reader.h); each image's file
    // bytes (PNG or JPEG, not decoded) are in model.images[i].image.
    nlohmann::json looks;
};

// Opens `path` (no "#Node" suffix) as above. On failure the message is one line naming the file,
// the glTF path and the problem.
Status openGltf(const std::string& path, const MeshLimits& limits, std::shared_ptr<const GltfDocument>* out);

// Number of times a glTF file was parsed by this process (cache misses), for tests.
size_t gltfParseCount();

// Drops every cached document (documents still held by callers stay alive).
void clearGltfCache();

}  // namespace apparent
