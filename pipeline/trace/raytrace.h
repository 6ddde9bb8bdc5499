// The paper's 4D raytracer as a reference renderer: `apparent raytrace` and `apparent figure`.
// Rays leave the camera through each pixel centre (or through the centres of a grid of cells of
// the pixel, SceneTracer::setSamplesSide) and run back along the past lightcone (or along
// the hyperplane t = t_c for the instant and contracted models), meet the 4D tetrahedra of every
// object's history by the barycentric method (mesh4d/ray4d.h), the nearest event wins, and the hit
// is shaded by Lambert's law from the scene's light with the lab-frame normal of the object's
// triangle at the hit instant; mirrors bounce a ray once. No shadows. By default geometry and
// shading only, as in the paper's comparison figure; with --shade doppler the object's colour is
// first shifted by the hit's Doppler factor (mesh4d/light_factors.h dopplerFactor from the hit
// event to the camera, or to the mirror point for a reflection, which is at rest in the camera's
// frame) and scaled by the searchlight factor, as `render --shade doppler` bakes it
// (mesh4d/doppler_colour.h): pixel = Lambert * dopplerColour(base, D). For a spinning, accelerated
// or keyframed object D is the worldline's at the hit (worldline.h worldlineDoppler: the rest point
// and own time of the hit, ray4d.h WorldHit). A keyframed path's velocity jumps at a key; a hit
// exactly at a key takes the velocity of the time slab whose tetrahedron it hit (the slabs end at
// the keys, extrude.h), the segment that slab draws, so that the colour, the geometry and the normal
// come from one piece of the history (the hit's own time is kept inside that slab; a ray exactly
// through a key's cap, shared by two slabs, takes the one the hierarchy meets first, deterministic).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "exporters/png.h"
#include "mesh4d/ray4d.h"
#include "pipeline/stage/mirror.h"
#include "pipeline/stage/stage.h"
#include "pipeline/trace/trace_progress.h"

namespace apparent {

// Unit direction of the ray from the camera through the centre of pixel (px, py) of a
// width x height image (row 0 at the top); fov_deg is the vertical field of view.
mesh4d::Vec3 pixelDirection(const CameraSpec& camera, int width, int height, int px, int py);

// The ray of pixel (px, py): from the camera position along pixelDirection (perspective), or, for
// an orthographic camera, from the pixel centre on the image plane through the camera (normal to
// the view direction, camera.width wide, the height in the picture's proportion) along the view
// direction.
struct PixelRay {
    mesh4d::Vec3 origin, direction;
};
PixelRay pixelRay(const CameraSpec& camera, int width, int height, int px, int py);

// One traced frame: the picture and, per pixel (row-major), the index of the object the ray hits
// first (-1: none) and of the object seen in it by a mirror bounce (-1: none or not a mirror).
struct TracedFrame {
    RgbImage image;
    std::vector<int32_t> object;
    std::vector<int32_t> reflected;
};

// Time slabs (mesh4d/extrude.h) of one object whose motion is not uniform held at once, and the
// prisms over every such object's slabs, from a memory budget (raytrace and figure
// --max-slab-memory BYTES) at kTraceBytesPerPrism each: a prism's tetrahedra, caps and its share
// of the hierarchies, as peak memory grows per prism (docs/PERFORMANCE.md, "Memory of time slabs").
constexpr size_t kMaxTraceSlabs = 4096;
constexpr long long kTraceBytesPerPrism = 320;
constexpr long long kDefaultSlabMemory = 2LL << 30;  // one window's slabs: about 6.7M prisms
inline size_t slabPrismLimit(long long slab_memory) { return size_t(std::max(0LL, slab_memory) / kTraceBytesPerPrism); }

struct TracerOptions {
    bool hierarchy = true;     // false: every prism tested for every ray (the benchmarks' peer, ray4d.h)
    // true: a motion that is not uniform is traced over buildWorld's padded span (light-crossing
    // time over 1 - b), not the span its frames see (worlds.h): the tests' peer of the seen span.
    bool padded_span = false;
    // The seen span of such a motion widened by this much of the object's time on both sides
    // (negative: narrowed), before its ends go out to the slab grid: the tests' generous peer.
    double span_margin = 0;
    size_t window_slabs = kMaxTraceSlabs;  // one object's time slabs held at once (windows, below)
    size_t window_prisms = slabPrismLimit(kDefaultSlabMemory);  // every object's slabs' prisms at once
};

class SlabPlanner;  // pipeline/trace/slab_planner.h

// The scene's worlds for one model, prepared for tracing frames first..last (global numbers).
// Uniform motions: one world each, extruded once over the span the camera and each mirror image
// of it can see in first..last. Motions that are not uniform: time slabs on the motion's slab grid
// (extrude.h SlabGrid) over the span a window of frames sees (mesh4d/motion/seen.h slabSpanSeen),
// the window the longest run of frames from the first one traced whose slabs fit in
// options.window_slabs per object and options.window_prisms over all; a frame outside it gets a new window
// from that frame. The grid makes a slab the same in every window that holds it, so each frame's
// picture is the same whichever windows the frames were traced in (and as one window over a short
// range). A new window keeps the slabs it shares with the last one, and their hierarchies in
// chunks of consecutive slabs (TraceChunk), extruding only its new slabs and building the
// hierarchies only of its new chunks and of a kept chunk's remainder. Memory: at most one
// window's slabs at a time (those of the last window it does not hold go first).
class SceneTracer {
public:
    // Preconditions: the scene passed checkSceneForModel for `model` and every frame first..last
    // fits a window alone (raytrace and figure check it: checkTracedMotions); mirrors from
    // findMirrors; `objects` may go after the constructor.
    SceneTracer(const Scene& scene, const std::vector<PreparedObject>& objects, const std::vector<MirrorPlane>& mirrors,
                Model model, long long first_frame, long long last_frame, TracerOptions options = {});
    ~SceneTracer();
    SceneTracer(const SceneTracer&) = delete;
    SceneTracer& operator=(const SceneTracer&) = delete;

    // Traces global frame k (first..last) at width x height (rows in parallel with TBB;
    // deterministic), building the window of time slabs that holds it first when needed. Each row
    // of samples done (height x the samples' side of them) is counted in `progress` when given.
    TracedFrame traceFrame(long long k, int width, int height, TraceProgress* progress = nullptr);

    // --shade doppler (off by default): colours shifted by each hit's Doppler factor.
    void setShadeDoppler(bool on) { shade_doppler_ = on; }
    // --samples: side x side rays per pixel (1, the default: one through the pixel centre), at the
    // centres of a side x side grid of equal strata of the pixel; the pixel is their mean colour in
    // linear light (then sRGB). With one sample the picture is the one-ray picture, byte for byte.
    // The object buffers hold the sample at the pixel centre (side odd) or the one right of and
    // below it (side even).
    void setSamplesSide(int side) { samples_side_ = std::max(1, side); }

    // --gate DEPTH (0: off), the gated camera of the Vienna experiment (Hornof et al. 2025), in
    // finite and relativistic: the picture is composed of exposures of the light-path slices
    // [j DEPTH, (j + 1) DEPTH) along each ray from the camera (its image plane, orthographic), each
    // showing the scene as it is at the slice's middle time t_j = t_c - (j + 1/2) DEPTH: the ray
    // runs through slice j along that lab instant (ray4d.h, along t = const), and the nearest slice
    // with a hit wins (nearer slices hide farther ones, as along the continuous light path). The
    // delay steps by DEPTH at each slice boundary, so a surface crossed by boundaries steps there
    // (the photographs' doubled edges). A surface that moves within itself (its normal across the
    // velocity u) is hit in its own slice: its picture goes to the ungated one as DEPTH goes to 0
    // (an edge within u DEPTH / 2; tests/gated_test.cpp). A face moving through the rays is not:
    // a ray advancing across it at lateral rate a meets it in its own slice only where the
    // continuous crossing lies within DEPTH a / (2 (|u| + a)) of the slice's middle, so it shows as
    // stripes covering a / (|u| + a) of it at every DEPTH (the trailing face of a cube; edge-on, an
    // orthographic camera's side faces vanish). Preconditions (raytrace and figure check them:
    // checkGate): uniform motion, no mirror, DEPTH at most the objects' size.
    void setGate(double depth) { gate_ = depth; }

    // The traced worlds of the current window: one per object, or one per time slab of an object
    // whose motion is not uniform.
    size_t worldCount() const;
    // Windows built so far, the time slabs extruded for them (a slab a window shares with the last
    // one is not extruded again), the most one window holds.
    struct SlabCounts {
        size_t windows = 0, built = 0, most = 0;
    };
    const SlabCounts& slabCounts() const { return slab_counts_; }

private:
    struct Hit {
        int32_t object = -1;
        const mesh4d::World4D* world = nullptr;  // the world (time slab) hit
        mesh4d::WorldHit hit;
    };
    // A run of an object's worlds consecutive in time and their traces: one world, or time slabs
    // traced through one hierarchy (ray4d.h prepareSlabsTrace; each scanned alone without it). A
    // window of frames keeps the chunks of the last window that it holds whole, so their slabs and
    // hierarchies are built once; a chunk shares the slabs it has with one it was cut from.
    struct TraceChunk {
        std::vector<std::shared_ptr<const mesh4d::World4D>> worlds;  // in time order
        std::vector<mesh4d::TraceWorld> traces;                      // they point into the worlds
        std::vector<std::vector<const mesh4d::World4D*>> trace_worlds;  // per trace, the world of each of its slabs
    };
    // One object's chunks, in time order.
    struct ObjectTraces {
        std::vector<std::shared_ptr<const TraceChunk>> chunks;
    };
    // Every trace of every object in the order nearest() searches them (objects in scene order,
    // an object's latest first), one flat list as on 648c0a5: the loops over objects, chunks and
    // traces were 5 % of a uniform frame's instructions (callgrind, raytrace_bench BM_TraceFrame/1/0).
    struct TraceRef {
        const mesh4d::TraceWorld* trace = nullptr;
        const std::vector<const mesh4d::World4D*>* worlds = nullptr;  // its slabs' worlds
        int32_t object = -1;
        bool mirror = false;  // the object is a mirror
    };
    void listTraces();
    // The chunk of `worlds` (consecutive in time; slabs: the object's motion is not uniform).
    std::shared_ptr<const TraceChunk> makeChunk(std::vector<std::shared_ptr<const mesh4d::World4D>> worlds,
                                                bool slabs) const;
    // The window of time slabs that holds frame k.
    void buildWindow(long long k);
    Hit nearest(const mesh4d::Ray4D& ray, bool skip_mirrors, double s_limit = INFINITY) const;
    // The gated primary ray of a pixel (setGate): the first slice's hit, slices from depth `near`
    // to `far` (the objects' extent along the rays this frame).
    Hit nearestGated(const mesh4d::ViewSurface& view, const PixelRay& pixel, double near, double far) const;
    // `receiver`: where the light goes from the hit (the camera or the mirror point), for D, and its
    // velocity (light_factors.h dopplerFactor: nonzero only for finite with a moving camera).
    std::array<double, 3> shade(const Hit& h, mesh4d::ViewKind kind, const mesh4d::Vec3& receiver,
                                const mesh4d::Vec3& receiver_velocity = {0, 0, 0}) const;
    // The same with the source's `motion` and emission point given for D (in that motion's frame);
    // a motion that is not uniform has D from the worldline of the hit's rest point.
    std::array<double, 3> shadeWith(const Hit& h, const mesh4d::Motion& motion, const mesh4d::Vec3& emitted_at,
                                    mesh4d::ViewKind kind, const mesh4d::Vec3& receiver,
                                    const mesh4d::Vec3& receiver_velocity) const;
    // A reflection seen by a moving camera: its Doppler factor from the lab (pipeline/stage/mirror.h).
    std::array<double, 3> shadeReflected(const Hit& h, const mesh4d::ViewSurface& view, const MirrorPlane& m,
                                         const mesh4d::CameraMotion& camera) const;

    Scene scene_;
    Model model_;
    TracerOptions options_;
    long long first_ = 0, last_ = 0;
    long long window_first_ = 1, window_last_ = 0;  // the current window of slabs (empty at first)
    std::vector<MirrorPlane> mirrors_;
    std::vector<int32_t> mirror_of_object_;  // index into mirrors_, or -1
    std::vector<std::array<double, 4>> colors_;
    std::vector<mesh4d::Motion> motions_;       // per object
    std::vector<mesh4d::Motion> lab_motions_;   // each object's lab motion (reflections' Doppler)
    std::vector<ObjectTraces> objects_;         // per object
    std::vector<TraceRef> trace_refs_;          // listTraces
    std::unique_ptr<SlabPlanner> planner_;      // the objects whose motion is not uniform
    SlabCounts slab_counts_;
    bool shade_doppler_ = false;
    int samples_side_ = 1;
    double gate_ = 0;
    std::vector<double> rest_radius_;  // per object, max |q| of its rest points (the gate's slice range)
};

// --samples N: the side of the square grid of N samples per pixel (N = side x side, side 1..16);
// 0 when N is not such a square.
int samplesSide(int samples);

// Rays per pixel by default (--samples; docs/PICTURES.md "Anti-aliasing" says why): a frame of
// `raytrace` or of a video 2 x 2, a figure's sheet, a picture for a slide, 3 x 3.
constexpr int kDefaultRaytraceSamples = 4;
constexpr int kDefaultFigureSamples = 9;

struct RaytraceSettings {
    StageOptions stage;            // scene, --model (empty: the scene's), --frames, --max-frames, limits
    std::string out_dir = "out";
    bool write_png = true;         // DIR/<model>/frame_NNNNN.png (with --video: only when --out is given)
    std::string video_path;        // --video: the frames as an H.264 MP4 at the scene's fps (one model)
    int width = 480, height = 270;
    int threads = 0;
    bool quiet = false;            // no summary, no progress
    bool shade_doppler = false;    // --shade doppler (SceneTracer::setShadeDoppler)
    double gate = 0;               // --gate DEPTH (SceneTracer::setGate; 0: off)
    long long max_slab_memory = kDefaultSlabMemory;  // --max-slab-memory: one window's time slabs
    int samples = kDefaultRaytraceSamples;  // --samples: rays per pixel, a square (SceneTracer::setSamplesSide)
};

// `apparent raytrace`: DIR/<model>/frame_NNNNN.png per frame and/or one video (exporters/video.h).
// Progress on stderr (trace_progress.h) unless quiet. Exit codes as `render`; --video with several
// models or without ffmpeg in PATH: 2.
int raytrace(const RaytraceSettings& settings, std::ostream& log, std::ostream& err);

// --gate's needs: every object moving uniformly, no mirror, the depth > 0 and at most the
// smallest object's size (the histories are extruded over the span the ungated view sees, padded
// by each object's light-crossing time). One line naming the problem otherwise.
Status checkGate(const Stage& stage, double depth);

// The checks of a traced stage (raytrace and figure, before any tracing): every frame's time slabs
// within `slab_memory` (SceneTracer's preconditions), checkGate, and a warning on `err` (unless
// quiet) for a gate asked of the models without light delay. One line naming the problem otherwise.
Status checkTracedStage(const Stage& stage, long long slab_memory, double gate, bool quiet, std::ostream& err);

}  // namespace apparent
