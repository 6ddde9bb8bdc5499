// The paper's 4D raytracer as a reference renderer: `apparent raytrace` and `apparent figure`.
// Rays leave the camera through each pixel centre and run back along the past lightcone (or along
// the hyperplane t = t_c for the instant and contracted models), meet the 4D tetrahedra of every
// object's history by the barycentric method (mesh4d/ray4d.h), the nearest event wins, and the hit
// is shaded by Lambert's law from the scene's light with the lab-frame normal of the object's
// triangle at the hit instant; mirrors bounce a ray once. No shadows, no Doppler or intensity
// effects: geometry and shading only, as in the paper's comparison figure.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "exporters/png.h"
#include "mesh4d/ray4d.h"
#include "pipeline/mirror.h"
#include "pipeline/stage.h"

namespace apparent {

// Unit direction of the ray from the camera through the centre of pixel (px, py) of a
// width x height image (row 0 at the top); fov_deg is the vertical field of view.
mesh4d::Vec3 pixelDirection(const CameraSpec& camera, int width, int height, int px, int py);

// One traced frame: the picture and, per pixel (row-major), the index of the object the ray hits
// first (-1: none) and of the object seen in it by a mirror bounce (-1: none or not a mirror).
struct TracedFrame {
    RgbImage image;
    std::vector<int32_t> object;
    std::vector<int32_t> reflected;
};

// The scene's worlds for one model, prepared for tracing frames first..last (global numbers).
// Worlds are extruded over the span the camera and each mirror image of it can see.
class SceneTracer {
public:
    // Preconditions: the scene passed checkSceneForModel for `model`; mirrors from findMirrors.
    SceneTracer(const Scene& scene, const std::vector<PreparedObject>& objects, const std::vector<MirrorPlane>& mirrors,
                Model model, long long first_frame, long long last_frame);
    SceneTracer(const SceneTracer&) = delete;
    SceneTracer& operator=(const SceneTracer&) = delete;

    // Traces global frame k at width x height (rows in parallel with TBB; deterministic).
    TracedFrame traceFrame(long long k, int width, int height) const;

    const std::vector<mesh4d::World4D>& worlds() const { return worlds_; }

private:
    struct Hit {
        int32_t object = -1;
        mesh4d::WorldHit hit;
    };
    Hit nearest(const mesh4d::Ray4D& ray, bool skip_mirrors) const;
    std::array<double, 3> shade(const Hit& h) const;

    Scene scene_;
    Model model_;
    std::vector<MirrorPlane> mirrors_;
    std::vector<int32_t> mirror_of_object_;  // index into mirrors_, or -1
    std::vector<std::array<double, 4>> colors_;
    std::vector<mesh4d::World4D> worlds_;
    std::vector<mesh4d::TraceWorld> traces_;
};

struct RaytraceSettings {
    StageOptions stage;            // scene, --model (empty: the scene's), --frames, --max-frames, limits
    std::string out_dir = "out";
    int width = 480, height = 270;
    int threads = 0;
    bool quiet = false;
};

// `apparent raytrace`: DIR/<model>/frame_NNNNN.png per frame. Exit codes as `render`.
int raytrace(const RaytraceSettings& settings, std::ostream& log, std::ostream& err);

struct FigureSettings {
    StageOptions stage;            // scene, --max-frames, limits (the rows fix the models, the columns the frames)
    std::string out_path = "sheet.png";
    int columns = 6;
    int width = 320, height = 180;  // one panel
    int threads = 0;
    bool quiet = false;
};

// The frames a figure shows in its columns: evenly spaced over the scene's frames, first and last included.
std::vector<long long> figureFrames(const Scene& scene, int columns);

// `apparent figure`: the paper's comparison sheet, rows instant, finite, relativistic, columns
// sequential frames (figureFrames), panels separated by 4-pixel grey lines.
int figure(const FigureSettings& settings, std::ostream& log, std::ostream& err);

}  // namespace apparent
