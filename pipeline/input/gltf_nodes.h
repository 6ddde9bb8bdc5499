// The node graph of a parsed glTF file: node transforms and the one walker that visits the nodes,
// used by the mesh reader (gltf_reader.h) and the glTF scene reader (gltf_scene.h).
//
// A node's local transform is its matrix, or T * R * S from translation, rotation (unit
// quaternion) and scale (glTF 2.0 section 5.25), composed in double. The walk is depth first
// from the given roots; a node reached through several parents is visited once per path. Refused,
// with "file: where: problem": a node index out of range, a cycle, a hierarchy deeper than
// kMaxNodeDepth, more than kMaxNodeVisits visits in all (a DAG of shared children grows
// exponentially), a world transform that is not finite.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "mesh4d/event.h"
#include "pipeline/input/status.h"

namespace apparent {

constexpr size_t kMaxNodeDepth = 1000;
constexpr size_t kMaxNodeVisits = 1'000'000;

// Column-major 4x4 affine matrix, as glTF stores node matrices.
struct Affine {
    double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    Affine operator*(const Affine& o) const;
    mesh4d::Vec3 apply(const mesh4d::Vec3& p) const;
    double det3() const;  // determinant of the linear part (negative: mirroring)
};

Affine localTransform(const tinygltf::Node& n);

// The scene a file shows: its default scene, else scene 0; -1 when it has none.
int defaultSceneIndex(const tinygltf::Model& model);

// The roots to read a whole file from: the default scene's nodes, else every node that is no
// other node's child.
std::vector<int> rootNodes(const tinygltf::Model& model);

// Called for each visit with the node index, its world transform and the indices of its
// ancestors on this path (root first). Returning a failure stops the walk with it.
using NodeVisitor = std::function<Status(int node, const Affine& world, const std::vector<int>& ancestors)>;

// Walks the subtrees of `roots` depth first. The roots' own transforms are applied when
// `apply_root_transform` (otherwise a root sits at the identity: "file.glb#Node" reads a node in
// its own frame). `file` prefixes messages.
Status walkNodes(const std::string& file, const tinygltf::Model& model, const std::vector<int>& roots,
                 bool apply_root_transform, const NodeVisitor& visit);

}  // namespace apparent
