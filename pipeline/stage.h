// The stage: a scene loaded once into what every command works from (render, raytrace, figure,
// the benchmarks): the validated scene, the models to run, the frame range, the prepared objects
// (meshes read once, transforms applied) and the mirror planes. One load preamble, so every
// command refuses the same inputs with the same one-line messages (exit code 2).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "pipeline/mesh_input.h"
#include "pipeline/mirror.h"
#include "pipeline/prepared_object.h"
#include "pipeline/scene.h"

namespace apparent {

// Exit codes of every command.
constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitOutputError = 3;

struct StageOptions {
    std::string scene_path;
    std::vector<Model> models;         // --model; empty: the scene's model
    bool all_models = false;           // --model all: instant, finite, relativistic, contracted
    bool has_tolerance = false;        // --tolerance given: overrides the scene's
    double tolerance = 1e-3;           // light-seconds; 0: vertex mode
    long long frame_from = 0;          // --frames A:B, global frame numbers, B exclusive
    long long frame_to = -1;           // -1: to the last frame of the scene
    long long max_frames = kDefaultMaxFrames;  // --max-frames: scenes with more frames are refused
    MeshLimits limits;                 // --max-vertices, --max-faces, --max-file-bytes, --allow-outside
    bool quiet = false;                // no mesh warnings
};

struct Stage {
    Scene scene;                       // with the tolerance override applied
    std::vector<Model> models;         // what to run, each checked with checkSceneForModel
    long long first = 0, last_excl = 0;  // frames [first, last_excl), 0 <= first < last_excl <= frame count
    std::vector<PreparedObject> objects;
    std::vector<MirrorPlane> mirrors;  // the planes of the mirror objects (findMirrors)
};

// Loads and validates the scene, the models, the frame count (against max_frames) and range, every
// mesh and the mirrors, in that order. On failure: false, and the one line to print (without
// "error: ") in `error`; the command exits with kExitBadInput. Mesh warnings go to `log`.
bool loadStage(const StageOptions& options, Stage* stage, std::ostream& log, std::string* error);

}  // namespace apparent
