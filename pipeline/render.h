// The `apparent render` driver: load, validate, build each object's 4D history once per model,
// then per frame cut it with the view surface and export. Exit codes: 0 success, 2 bad input or
// usage, 3 output could not be written.
#pragma once

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

#include "exporters/gltf.h"
#include "pipeline/obj_reader.h"
#include "pipeline/scene.h"

namespace apparent {

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitOutputError = 3;

struct RenderSettings {
    std::string scene_path;
    std::string out_dir = "out";
    std::vector<Model> models;         // empty: the scene's model
    bool all_models = false;           // --model all
    bool write_glb = true;
    bool write_ply = false;
    bool write_obj = false;
    GlbOptions glb;                    // --draco, --draco-bits
    bool has_tolerance = false;        // --tolerance given: overrides the scene's
    double tolerance = 1e-3;
    long long frame_from = 0;          // --frames A:B, global frame numbers, B exclusive
    long long frame_to = -1;           // -1: to the last frame of the scene
    int threads = 0;                   // --threads; 0: all cores
    bool cull_view = false;            // --cull-view: leave objects outside the camera's view empty
    bool quiet = false;
    bool verbose = false;
    long long max_frames = kDefaultMaxFrames;
    long long max_output_bytes = 20LL << 30;  // --max-output-bytes: all files of the run together
    MeshLimits limits;
};

// One object ready for the 4D stage: its rest mesh (rotation and scale applied) and its scene entry.
struct PreparedObject {
    ObjectSpec spec;
    mesh4d::RestMesh rest;
    bool has_color = false;            // the mesh file gave a base colour
    std::array<double, 4> color{1, 1, 1, 1};
};

// The base colour object i is drawn with (linear RGBA): its mesh file's, else a palette colour.
std::array<double, 4> objectBaseColor(const std::vector<PreparedObject>& objects, size_t i);

// Loads every object's mesh and applies rotation and scale. Messages of counted warnings go to `log`.
Status prepareObjects(const Scene& scene, const MeshLimits& limits, std::vector<PreparedObject>* objects,
                      std::ostream& log, bool quiet);

// The 4D history of one object for `model`, extruded over the proper-time span that frames
// [first_frame, last_frame] can see, clipped to the object's existence.
mesh4d::World4D buildWorld(const PreparedObject& object, Model model, const Scene& scene, long long first_frame,
                           long long last_frame);

// View culling (--cull-view): whether a sphere may show in the camera's view, a circular cone
// around the view axis whose half-angle reaches the corners of a kCullAspect:1 frame with the
// camera's vertical field of view (wider than 16:9 and 21:9 screens; a 32:9 screen at the same
// vertical field of view could miss parts at its far left and right).
constexpr double kCullAspect = 2.4;
bool inCameraView(const CameraSpec& camera, const mesh4d::BoundingSphere& bound);

// The view surface of global frame k for `model`, and at any camera time t_c.
mesh4d::ViewSurface viewForFrame(const Scene& scene, Model model, long long k);
mesh4d::ViewSurface viewAt(const Scene& scene, Model model, double t_c);

int render(const RenderSettings& settings, std::ostream& log, std::ostream& err);

}  // namespace apparent
