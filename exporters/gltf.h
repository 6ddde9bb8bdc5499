// One animated binary glTF (.glb) per model, holding every frame of the sequence.
//
// Layout (glTF 2.0): node k carries mesh k (frame k, all objects merged) and its translation is
// the frame's local origin (the centre of its bounding box, as JSON doubles); POSITION is float32
// relative to that origin, so scenes far from the world origin keep their precision. A per-vertex
// float attribute _EMISSION_TIME holds the lab time the light left each point. One animation with
// STEP-interpolated scale channels shows exactly frame k's node during [k/fps, (k+1)/fps): n + 1
// keys, the last one closing the final frame (../shared/notes/dependencies.md section 4). A frame
// with nothing visible gets a node without a mesh (glTF forbids empty accessors).
// Scene extras record the model, tolerance, units and the camera time of every frame.
#pragma once

#include <string>
#include <vector>

#include "exporters/frame_mesh.h"

namespace apparent {

struct GlbStats {
    size_t bytes = 0;
    double max_position_error = 0;  // largest |float32 - double| over all exported positions, light-seconds
};

bool writeAnimatedGlb(const std::string& path, const std::vector<ExportFrame>& frames, const SequenceInfo& info,
                      GlbStats* stats, std::string* error);

}  // namespace apparent
