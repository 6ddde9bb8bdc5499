// The scene file: camera, frame range, model, tolerance and the moving objects (docs/SCENES.md "Scene
// format"). Units: light-seconds and seconds, c = 1, velocities as fractions of c.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mesh4d/event.h"
#include "mesh4d/motion/keyed.h"
#include "mesh4d/motion/motion.h"
#include "pipeline/input/status.h"
#include "pipeline/input/units.h"

namespace apparent {

enum class Model { Instant, Finite, Relativistic, Contracted };

const char* modelName(Model m);
bool parseModel(const std::string& name, Model* out);

struct CameraSpec {
    mesh4d::Vec3 position{0, 0, 0};
    mesh4d::Vec3 look_at{0, 0, -1};
    mesh4d::Vec3 up{0, 1, 0};
    double fov_deg = 60;
    // The projection: perspective (rays from `position`, fov_deg) or orthographic (parallel rays
    // along the view direction k from the image plane through `position` normal to k, `width`
    // scene units wide). The orthographic camera of the light-speed models (finite, relativistic)
    // sees the light that crosses that plane at the frame's time (mesh4d/lightcone.h, the tilted
    // hyperplane): the far-field view of Terrell's and Penrose's analyses.
    enum class Projection { Perspective, Orthographic } projection = Projection::Perspective;
    double width = 0;  // orthographic: the view's width in scene units (> 0); 0 unset
    bool orthographic() const { return projection == Projection::Orthographic; }
    // Seconds by which the hyperplane models (instant, contracted) look into the past: they view
    // t = t_k - instant_delay, so that with the light delay of the stage centre they show the
    // objects where the light-speed models do (Black et al. 2007 advance their camera so).
    double instant_delay = 0;
    // Lab velocity (fraction of c, |v| < 1): the camera's worldline is position + velocity t, and
    // the outputs are in its rest frame (mesh4d/motion/camera_frame.h; docs/MOTION.md "A moving camera").
    mesh4d::Vec3 velocity{0, 0, 0};
};

// The light that shades the raytracer's pictures, at rest in the lab (docs/SCENES.md):
// position and directions are lab coordinates, and every hit is shaded in the lab (its normal and
// point taken there, pipeline/trace/raytrace.cpp labShading), so with a moving camera (camera.velocity)
// a face at rest in the lab keeps the shade a camera at rest sees; only where it appears changes.
struct LightSpec {
    enum class Kind { Directional, Point } kind = Kind::Directional;
    mesh4d::Vec3 position;              // Point: lab position
    mesh4d::Vec3 direction{0, 1, 0};    // Directional: unit vector towards the light
    mesh4d::Vec3 direction_given{0, 1, 0};  // `direction` as written (the web file writes it back)
    double ambient = 0.2;               // fraction of the base colour lit regardless of the normal
    // A scene without `light` gets two distant lights: overhead (`direction` = camera.up) and a key
    // light from the camera's upper left (`key_direction`), which gets `key_weight` of the diffuse
    // share, so that each visible face of a box shows its own shade. key_weight 0: one light.
    mesh4d::Vec3 key_direction{0, 0, 1};
    double key_weight = 0;
};

struct FrameSpec {
    double start = 0;
    double end = 20;
    double fps = 10;
};

struct ObjectSpec {
    std::string name;
    std::string field_path = "objects[0]";  // where the object is defined, for messages
    std::string mesh_path;             // resolved against the scene file's folder
    std::string mesh_text;             // the mesh field as written (for messages)
    mesh4d::Vec3 position;             // lab position of the mesh origin at lab time t0
    double t0 = 0;
    mesh4d::Vec3 velocity;             // lab frame, units of c (derived when gamma/rapidity is given)
    // The speed may instead be stated exactly: a unit `direction` with `gamma` or `rapidity`.
    enum class Speed { Velocity, Gamma, Rapidity } speed = Speed::Velocity;
    mesh4d::Vec3 direction;            // unit vector (with Speed::Gamma or Speed::Rapidity)
    // `direction` and `orbit.axis` as written, before normalising: the web file
    // (pipeline/run/web_file.h) writes them back, so that the reader normalises them to the same bits.
    mesh4d::Vec3 direction_given, orbit_axis_given;
    double gamma = 1, rapidity = 0;
    // Spin (rad/s) in the object's centre frame about its origin, combined with the velocity
    // (mesh4d/motion/worldline.h); zero: uniform motion.
    mesh4d::Vec3 angular_velocity;
    // Constant proper acceleration of the origin from t0 on (1/ls, c = 1: light-seconds per second
    // squared), Born-rigid, in the frame of `velocity` (mesh4d/motion/worldline.h); zero: uniform.
    mesh4d::Vec3 acceleration;
    // The kinds of motion answered in their own file (mesh4d/motion/kinds.h), read by their rows of
    // scene_fields.cpp's table; empty: none.
    mesh4d::KindParams kinds;
    mesh4d::Vec3 rotation_deg;         // rest-frame rotation, degrees, applied X then Y then Z
    mesh4d::Vec3 scale{1, 1, 1};       // rest-frame scale, applied before the rotation
    // Interval of existence on the object's own clock (0 at t0): proper time for the relativistic
    // and contracted models, lab time since t0 for the instant and finite models.
    double exists_from = -std::numeric_limits<double>::infinity();
    double exists_to = std::numeric_limits<double>::infinity();
    // A further linear map of the rest mesh, applied after scale and rotation (column-major 3x3):
    // the world rotation and scale of a glTF node that carries the object (identity otherwise).
    std::array<double, 9> linear{1, 0, 0, 0, 1, 0, 0, 0, 1};
    // A planar mirror at rest: the raytracer bounces rays off it once, and the mesh pipeline adds
    // the retarded reflections it shows (docs/DESIGN.md section 8).
    bool mirror = false;
    // A keyframed path (glTF animation channels of the object's node: mesh4d/motion/keyed.h), in the
    // lab; null for none. `position` is then the centre at t0 on the path, `velocity` the path's
    // mean velocity, and `linear` holds the pose at t0. keys_field names the channels, for messages.
    std::shared_ptr<const mesh4d::KeyPath> keys;
    std::string keys_field;
    // `color` or `material` (docs/SCENES.md): the object's glTF PBR material, replacing its mesh file's
    // colour and materials; not given: the file's (else a palette colour).
    struct Material {
        bool given = false;
        std::array<double, 4> base_color{1, 1, 1, 1};  // linear RGBA in [0, 1]
        double metallic = 0, roughness = 0.8;           // in [0, 1]
        std::array<double, 3> emissive{0, 0, 0};        // linear RGB in [0, 1]
    } material;
};

// The default tolerance, as a fraction of each object's bounding-box diagonal: an object that fills
// a 1000-pixel-wide view is then within about a pixel of its exact apparent surface, and the
// measured error is 0.85 to 0.99 of it (docs/ACCURACY.md; `apparent trade` rows "T = 0.001 x size").
constexpr double kDefaultToleranceRelative = 1e-3;

struct Scene {
    std::string path;                  // the scene file, as given
    // `units` (pipeline/input/units.h): the scene's lengths as written. Every length below is in
    // light-seconds whatever it is (loadScene converts); the outputs are in these units.
    LengthUnit units = LengthUnit::LightSecond;
    CameraSpec camera;
    LightSpec light;                   // default: overhead (camera.up) plus a key light from the camera
    FrameSpec frames;
    Model model = Model::Relativistic;
    // The tolerance: absolute (`tolerance` light-seconds > 0; 0 = vertex mode) when
    // tolerance_relative is 0, else relative: each object's is tolerance_relative x its
    // bounding-box diagonal (the default when neither the scene nor --tolerance gives one; the stage
    // then sets `tolerance` to the smallest object's, for messages and the outputs' extras).
    double tolerance = 1e-3;
    double tolerance_relative = kDefaultToleranceRelative;
    std::vector<ObjectSpec> objects;
    // What was read but not used, one line each ("file: field: problem"): in a glTF scene, extras
    // keys that are not scene fields (other tools keep custom properties there), misspelt ones
    // with the field they resemble, and nodes left out because their extras hold only such
    // near-misses. A JSON scene refuses unknown keys instead, so it has none. Callers print them.
    std::vector<std::string> warnings;
};

// Maximum number of frames a scene may ask for (a typo such as fps = 1e9 would otherwise run for
// days); raise it with --max-frames.
constexpr long long kDefaultMaxFrames = 100000;

// True for a .gltf or .glb path: a scene authored in glTF (docs/SCENES.md "Scenes in glTF").
bool isGltfPath(const std::string& path);

// Reads and validates a scene file, JSON or glTF (dispatching on the extension). On failure the
// message names the file, the field (a JSON path such as objects[1].velocity, or
// nodes[3].extras.velocity in glTF) and the problem with the valid range. Both forms read their
// fields with the same code (pipeline/input/scene_fields.h); warnings go to scene->warnings.
Status loadScene(const std::string& path, Scene* scene);

// Checks what depends on the model: |velocity| < 1 wherever light or a Lorentz boost is involved.
Status checkSceneForModel(const Scene& scene, Model model);

// Number of frames: k = 0, 1, ... while start + k / fps < end.
long long frameCount(const FrameSpec& frames);
// Camera time of global frame k: start + k / fps (never accumulated).
double frameTime(const FrameSpec& frames, long long k);

}  // namespace apparent
