// What the exporters receive: one frame of apparent geometry, one mesh per scene object, plus
// what the sequence is. Exporters make no geometric decisions; they convert and write.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "exporters/surface_look.h"
#include "mesh4d/slice.h"

namespace apparent {

struct ExportFrame {
    long long index = 0;                        // global frame number (file names use it)
    double t_c = 0;                             // camera time of the frame
    std::vector<mesh4d::ApparentMesh> objects;  // one per scene object, in scene order
    // The units of the positions when they are not light-seconds (a scene in metres: "metres,
    // seconds, ...", pipeline/input/units.h), for the PLY and OBJ comments; empty: light-seconds.
    std::string units;

    size_t triangleCount() const {
        size_t n = 0;
        for (const auto& o : objects) n += o.triangles.size();
        return n;
    }
};

struct ExportObject {
    std::string name;
    std::array<double, 4> base_color{0.8, 0.8, 0.8, 1.0};  // linear RGBA
    // A reflection: the mirror it is seen in, as an index among the scene's mirrors (-1: one of the
    // scene's own objects) and by name (for node names).
    int mirror_index = -1;
    std::string mirror;
    // The look its input file gives (texture coordinates, vertex colours, materials: surface_look.h)
    // and the rest mesh its cut's rest points and source triangles refer to; null: none.
    std::shared_ptr<const SurfaceLook> look;
    std::shared_ptr<const mesh4d::RestMesh> rest;
    // The material's other PBR factors (the scene's `material`).
    double metallic = 0, roughness = 0.8;
    std::array<double, 3> emissive{0, 0, 0};  // linear RGB
};

struct ExportCamera {
    mesh4d::Vec3 position{0, 0, 0};
    mesh4d::Vec3 look_at{0, 0, -1};
    mesh4d::Vec3 up{0, 1, 0};
    double fov_deg = 60;  // vertical field of view
    double width = 0;     // > 0: an orthographic camera this wide (scene camera.width); 0: perspective
    bool orthographic() const { return width > 0; }
};

// The scene's light (pipeline/input/scene.h LightSpec, resolved: a scene without `light` gets its two
// default distant lights), at rest in the lab, in the outputs' axes and units, for viewers that
// light the files as the raytracer does (scene extras "light"; scripts/blender_import.py).
struct ExportLight {
    bool point = false;                   // a point light at `position`, else distant towards `direction`
    mesh4d::Vec3 position{0, 0, 0};
    mesh4d::Vec3 direction{0, 1, 0};      // unit vector towards the light
    double ambient = 0.2;                 // share of the base colour lit whatever the normal, [0, 1]
    mesh4d::Vec3 key_direction{0, 0, 1};  // the default key light (unit, towards it), when key_weight > 0
    double key_weight = 0;                // its share of the diffuse light, [0, 1]
};

struct SequenceInfo {
    std::string model;            // instant, finite, relativistic, contracted
    double tolerance = 0;         // requested tolerance (in the scene's units of length)
    std::string units = "light-seconds, seconds, c = 1";  // the scene's (pipeline/input/units.h unitsText)
    double fps = 1;
    std::string scene_path;
    std::vector<ExportObject> objects;  // parallel to ExportFrame::objects
    ExportCamera camera;
    ExportLight light;
};

// "frame_00042": the name of global frame k in file and node names.
inline std::string frameName(long long k) {
    std::string digits = std::to_string(k);
    return "frame_" + std::string(digits.size() < 5 ? 5 - digits.size() : 0, '0') + digits;
}

// All objects of a frame in one mesh with absolute lab positions and times (origin 0): PLY and
// OBJ hold every object in one file.
mesh4d::ApparentMesh mergeObjects(const ExportFrame& frame);

}  // namespace apparent
