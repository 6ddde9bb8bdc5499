// The stage: a scene loaded once into what every command works from (render, raytrace, figure,
// the benchmarks): the validated scene, the models to run, the frame range, the prepared objects
// (meshes read once, transforms applied) and the mirror planes. One load preamble, so every
// command refuses the same inputs with the same one-line messages (exit code 2).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "pipeline/input/mesh_input.h"
#include "pipeline/input/scene.h"
#include "pipeline/stage/mirror.h"
#include "pipeline/stage/prepared_object.h"

namespace apparent {

constexpr long long kDefaultMaxObjectFrames = 1'000'000;
// Coordinates and times a scene may reach after every transform, light-seconds (about 32 000
// years): beyond, squares and differences lose all digits a frame needs. Derived quantities
// (scaled and rotated vertices, positions at the frame times, the camera's look-back) are checked.
constexpr double kMaxCoordinate = 1e12;
// --tolerance may not be finer than this fraction of the largest object's size: float32 output
// (relative to a local origin) resolves about 6e-8 of it, and a finer tolerance only multiplies
// triangles (1e-300 made 69M triangles for one frame).
constexpr double kToleranceFloorRelative = 1e-6;

// Exit codes of every command.
constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitOutputError = 3;

struct StageOptions {
    std::string scene_path;
    std::vector<Model> models;         // --model; empty: the scene's model
    bool all_models = false;           // --model all: instant, finite, relativistic, contracted
    bool has_tolerance = false;        // --tolerance given: overrides the scene's
    double tolerance = 1e-3;           // light-seconds; 0: vertex mode (with tolerance_relative 0)
    double tolerance_relative = 0;     // > 0: --tolerance Fx, this fraction of each object's size
    // --attribute-tolerance: the bound of the parametric error (mesh4d/slice.h
    // SliceSettings::attribute_tolerance), light-seconds or (relative > 0) a fraction of each
    // object's size; both 0: none (only the distance is bounded).
    double attribute_tolerance = 0;
    double attribute_tolerance_relative = 0;
    long long frame_from = 0;          // --frames A:B, global frame numbers, B exclusive
    long long frame_to = -1;           // -1: to the last frame of the scene
    long long max_frames = kDefaultMaxFrames;  // --max-frames: scenes with more frames are refused
    MeshLimits limits;                 // --max-vertices, --max-faces, --max-file-bytes, --allow-outside
    // --max-object-frames: objects (each mirror's reflections of them included) times frames in
    // the range; every one is a cut per frame and a primitive of the .glb.
    long long max_object_frames = kDefaultMaxObjectFrames;
    bool quiet = false;                // no mesh warnings
};

struct Stage {
    Scene scene;                       // with the tolerance override applied
    std::vector<Model> models;         // what to run, each checked with checkSceneForModel
    long long first = 0, last_excl = 0;  // frames [first, last_excl), 0 <= first < last_excl <= frame count
    std::vector<PreparedObject> objects;
    // Each object's tolerance, light-seconds (0: vertex mode): the scene's absolute one, or its
    // relative one times the object's bounding-box diagonal (docs/ACCURACY.md).
    std::vector<double> tolerances;
    // Each object's attribute tolerance, light-seconds (INFINITY: none; StageOptions).
    std::vector<double> attribute_tolerances;
    std::vector<MirrorPlane> mirrors;  // the planes of the mirror objects (findMirrors)
};

// Loads and validates the scene, the models, the frame count (against max_frames) and range, every
// mesh and the mirrors, in that order; then what they derive: every transformed vertex finite and
// within kMaxCoordinate, the camera's look-back and frame times within it, each object's tolerance
// (set here; scene.tolerance becomes the smallest) not below kToleranceFloorRelative of the largest object, objects x (1 + mirrors) x frames within
// max_object_frames. On failure: false, and the one line to print (without
// "error: ") in `error`; the command exits with kExitBadInput. Mesh warnings go to `log`.
bool loadStage(const StageOptions& options, Stage* stage, std::ostream& log, std::string* error);

// loadStage's check of one end k of the frame range: the camera time of global frame k, and that
// less camera.instant_delay (the time the instant models view), finite and within kMaxCoordinate;
// the line names frame k. FrameCutter applies it to the frames it builds for a cut outside the range.
Status checkViewedTime(const Scene& scene, long long k);

// The frames a measuring command (trade, measure) takes: every frame of the stage's range when
// `all` (--frames given), else at most five spread over it, its first and last included.
std::vector<long long> sampledFrames(const Stage& stage, bool all);

}  // namespace apparent
