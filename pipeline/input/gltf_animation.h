// The animation channels of a parsed glTF file that move one node (glTF 2.0 section 3.11), read and
// checked for the keyframed paths of a glTF-authored scene (gltf_scene.h, mesh4d/motion/keyed.h).
//
// Read: channels whose target is the node's `translation` (VEC3 FLOAT) or `rotation` (VEC4 FLOAT,
// unit quaternions, normalised on reading), with LINEAR or STEP samplers: key times (SCALAR FLOAT,
// finite, strictly increasing) and one value per key. Refused, one line "file: glTF path: problem":
// an index out of range (sampler, accessor, bufferView, buffer), a wrong accessor type, component
// type or count, sparse or integer (normalised) accessors, times that are not finite or not
// increasing, values that are not finite, a quaternion far from unit length (|q| outside
// [0.5, 2]), an unknown interpolation, two channels animating the same property of the node, more
// than kMaxKeys keys (counts are checked before anything is allocated). Not modelled, one warning
// each: channels targeting the node's `scale` or morph `weights`.
// CUBICSPLINE (glTF 2.0 appendix C: in-tangent, value, out-tangent per key; rotations normalised
// after the spline) is read with its tangents; the path follows it through cubicSamples, LINEAR
// keys between which the chord stays within 1e-6 x scale of the spline.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <tiny_gltf.h>

#include "mesh4d/event.h"
#include "mesh4d/motion/keyed.h"
#include "pipeline/input/status.h"

namespace apparent {

constexpr size_t kMaxKeys = 1'000'000;

// One animated property of a node: its keys as written (node-local values).
struct AnimatedProperty {
    bool present = false;
    bool step = false;            // STEP
    bool cubic = false;           // CUBICSPLINE (else LINEAR unless step)
    std::string field;            // "animations[a].channels[c]", for messages
    std::vector<double> times;    // strictly increasing
    std::vector<mesh4d::Vec3> translations;  // translation channel
    std::vector<mesh4d::Quat> rotations;     // rotation channel (unit; CUBICSPLINE: as written)
    // CUBICSPLINE: per key the in-tangent then the out-tangent, 3 (translation) or 4 (rotation, x y
    // z w) components each.
    std::vector<double> tangents;
};

struct NodeAnimation {
    AnimatedProperty translation, rotation;
    bool animated() const { return translation.present || rotation.present; }
};

// The channels that target node `node`; warnings (scale, weights) appended as (glTF path, problem).
Status readNodeAnimation(const std::string& file, const tinygltf::Model& model, int node, NodeAnimation* out,
                         std::vector<std::pair<std::string, std::string>>* warnings);

// The node-local value of a property at time t: LINEAR (lerp; slerp the shorter way round for
// rotations), STEP or CUBICSPLINE between keys, the end value outside the keys.
mesh4d::Vec3 translationAt(const AnimatedProperty& p, double t);
mesh4d::Quat rotationAt(const AnimatedProperty& p, double t);

// The times strictly inside a CUBICSPLINE property's key intervals at which to sample it so that
// the polyline through the samples and the keys stays within 1e-6 x `scale` of the spline: in an
// interval of length d with M = max |p''| (p'' is linear in time there, so M is at an end), n =
// ceil(d / sqrt(8e-6 scale / M)) equal sub-steps (a chord of length h is within h^2 M / 8). Empty for
// LINEAR and STEP; {INFINITY} when more than kMaxKeys samples would be needed.
std::vector<double> cubicSamples(const AnimatedProperty& p, double scale);

}  // namespace apparent
