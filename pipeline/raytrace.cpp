#include "pipeline/raytrace.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <memory>
#include <ostream>
#include <sstream>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "exporters/video.h"
#include "mesh4d/angles.h"
#include "mesh4d/doppler_colour.h"
#include "mesh4d/box.h"
#include "mesh4d/light_factors.h"
#include "pipeline/distribute.h"
#include "pipeline/framing.h"
#include "mesh4d/motion/kinds.h"
#include "mesh4d/motion/seen.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/scene_fields.h"
#include "pipeline/view_hints.h"
#include "pipeline/worlds.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

// Linear RGB of pixels where a ray meets nothing (a dark blue-grey, so black objects still show).
constexpr std::array<double, 3> kBackground{0.010, 0.012, 0.020};
// Share of a mirror pixel's colour that is the reflection; the rest is the mirror's own shading.
constexpr double kMirrorReflectance = 0.8;

// Linear [0, 1] to 8-bit sRGB (IEC 61966-2-1 transfer curve).
uint8_t toSrgb8(double linear) {
    const double c = std::clamp(linear, 0.0, 1.0);
    const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
    return uint8_t(std::lround(s * 255));
}

// Time slabs for a motion that is not uniform (mesh4d/extrude.h): each vertex's sampled worldline
// within kSlabChordRelative of the object's bounding-box diagonal of its true one in the lab (the
// own-frame chord divided by the boost's or carry's largest stretch, gamma (1 + b)).
constexpr double kSlabChordRelative = 1e-3;

// The slabs' chord in the object's own frame (above) for `mesh` moving with `motion`.
double slabChord(const mesh4d::RestMesh& mesh, const mesh4d::Motion& motion) {
    mesh4d::EventBox box;
    for (const Vec3& p : mesh.positions) box.addPoint(p);
    const double g = 1 / std::sqrt(motion.one_minus_beta2);
    return kSlabChordRelative * box.diagonal() / (g * (1 + motion.beta));
}

// The world of `object` extruded over the union of the spans seen from the camera and from each
// mirror image of the camera, so that reflected rays, which reach further into the past, stay
// inside the history. Existence caps stay real where they clip either span. buildWorld's span,
// padded by the light-crossing time over 1 - b: what a uniform motion is traced over.
mesh4d::World4D traceWorld(const PreparedObject& object, Model model, const Scene& scene,
                           const std::vector<MirrorPlane>& mirrors, long long first, long long last) {
    mesh4d::World4D direct = buildWorld(object, model, scene, first, last);
    if (mirrors.empty()) return direct;
    double tau_a = direct.empty() ? INFINITY : direct.tau_a, tau_b = direct.empty() ? -INFINITY : direct.tau_b;
    bool real_a = direct.cap_a_real, real_b = direct.cap_b_real;
    // A moving camera: the image cameras' views in the frame traced (mirror.h imageView), the rest
    // points as that frame has them (the Thomas-Wigner rotation).
    const bool moving = cameraMotionOf(scene).moving();
    const mesh4d::MotionInCameraFrame in_cut = cutMotionOf(object.spec, model, scene);
    mesh4d::RestMesh rotated;
    const mesh4d::RestMesh& rest = restInCameraFrame(object.rest, in_cut, &rotated);
    for (const MirrorPlane& m : mirrors) {
        Scene image = scene;
        image.camera.position = reflectPoint(m, scene.camera.position);
        const mesh4d::World4D w =
            moving ? extrudeSeen(object.spec, rest, in_cut.motion, imageView(m, scene, model, frameTime(scene.frames, first)),
                                 imageView(m, scene, model, frameTime(scene.frames, last)))
                   : buildWorld(object, model, image, first, last);
        if (w.empty()) continue;
        if (w.tau_a < tau_a) { tau_a = w.tau_a; real_a = w.cap_a_real; }
        if (w.tau_b > tau_b) { tau_b = w.tau_b; real_b = w.cap_b_real; }
    }
    if (!(tau_a < tau_b)) return direct;
    return mesh4d::extrude(rest, direct.motion, tau_a, tau_b, real_a, real_b);
}

bool isSlabbed(const mesh4d::Motion& motion) { return !mesh4d::isUniform(motion); }

// The scene field that states a slabbed object's motion (for messages).
std::string motionField(const ObjectSpec& spec, const mesh4d::Motion& motion) {
    switch (mesh4d::kindOf(motion)) {
        case mesh4d::MotionKind::Keyed:
            return spec.keys_field;
        case mesh4d::MotionKind::Spin:
            return spec.field_path + ".angular_velocity";
        case mesh4d::MotionKind::Uniform:
        case mesh4d::MotionKind::Hyperbolic:
            break;
        default:  // a kind answered in its own file (mesh4d/motion/kinds.h)
            return spec.field_path + "." + mesh4d::answersOf(motion)->field;
    }
    return spec.field_path + ".acceleration";
}

// The hit's normal and point in the lab, where the scene's light is at rest (scene.h LightSpec):
// Lambert's law is stated in the light's frame, so the shade of a face does not depend on how the
// camera moves, only where the face appears does.
//
// The hit is traced in a frame F: the camera's rest frame for relativistic, contracted and instant
// with a moving camera (camera_frame.h), the lab for finite (its cut is made there, physics.h
// viewAt) and for every model with a camera at rest. Where F is the lab nothing is mapped, so those
// pictures keep their bytes. Otherwise, term by term:
// - the point: the hit event e_F in the lab, e_L = fromCameraFrame(e_F); a point light at rest at
//   P_L has, in the lab, always been at P_L, so the light reaching the hit left it along
//   l_L = (P_L - x_L) / |P_L - x_L| (in F the light moves, and this is the direction to its
//   retarded event seen from the hit, aberrated into F);
// - a directional light (and the default pair, scene.h): l_L = direction, as given (in F it is
//   aberrated as a star's direction is, docs/MOTION.md "A moving camera");
// - the normal: the hit's prism lies in a 3-flat {E : N . E = const} of spacetime. Its F form is
//   N_F = (-(n_F . w), n_F): n_F = lab_normal (ray4d.h: the spatial part of the flat's normal,
//   turned so that N_F . D_F < 0 for the ray's 4D direction D_F) annihilates the triangle's
//   tangents (0, a) at one F instant, and the time part makes N_F . (1, w) = 0 for the
//   worldlines of the rest points, all of F velocity w (a moving camera only with uniform
//   motions, physics.h checkObjectMotion). Lab differences map to F differences by the linear
//   M = toCameraFrameDifference, so N_F . (M E_L) = N_L . E_L with N_L's component mu equal to
//   N_F . (M e_mu) for the lab unit vectors e_t, e_x, e_y, e_z. The spatial part of N_L
//   annihilates the triangle's tangents at one lab instant: the lab normal n_L, normalised; it
//   keeps its side, N_L . D_L = N_F . D_F < 0. Under a boost this undoes the contraction
//   (an object at rest in the lab gets its rest normal back); under the Galilean map M keeps
//   spatial vectors, n_L = n_F, and only the point moves (x_L = x_F + v t).
struct LabShading {
    Vec3 normal;  // unit, towards the side the ray arrives from
    Vec3 point;   // the hit's lab position
};

LabShading labShading(const mesh4d::WorldHit& hit, const mesh4d::Motion& traced_motion,
                      const mesh4d::CameraMotion& camera, Model model) {
    if (!camera.moving() || model == Model::Finite) return {hit.lab_normal, hit.event.x};
    const mesh4d::Kinematics kinematics = kinematicsOf(model);
    const Vec3& n = hit.lab_normal;
    const std::array<double, 4> normal_f{-mesh4d::dot(n, traced_motion.velocity), n.x, n.y, n.z};
    const mesh4d::Event units[4] = {{1, {0, 0, 0}}, {0, {1, 0, 0}}, {0, {0, 1, 0}}, {0, {0, 0, 1}}};
    std::array<double, 4> normal_l{};
    for (size_t mu = 0; mu < 4; ++mu) {
        const mesh4d::Event m = mesh4d::toCameraFrameDifference(camera, kinematics, units[mu]);
        normal_l[mu] = normal_f[0] * m.t + normal_f[1] * m.x.x + normal_f[2] * m.x.y + normal_f[3] * m.x.z;
    }
    const Vec3 spatial{normal_l[1], normal_l[2], normal_l[3]};
    return {spatial / mesh4d::norm(spatial), mesh4d::fromCameraFrame(camera, kinematics, hit.event).x};
}

}  // namespace

// The objects of a scene whose motion is not uniform, for one model: the span of their time a
// window of frames sees, and its slabs on each motion's grid (mesh4d/extrude.h SlabGrid).
class SlabPlanner {
public:
    struct Slabbed {
        size_t object = 0;          // index among the scene's objects
        PreparedObject prepared;    // as given (the padded peer builds from it)
        mesh4d::RestMesh rest;      // in the frame of the cut
        mesh4d::Motion motion;      // there
        double chord = 0;           // slabChord
        mesh4d::SlabGrid grid;
    };
    // A span of the object's time to extrude; a real cap is one of the object's existence.
    struct Span {
        double tau_a = 0, tau_b = 0;
        bool real_a = false, real_b = false;
        bool empty() const { return !(tau_a < tau_b); }
    };

    SlabPlanner(const Scene& scene, const std::vector<PreparedObject>& objects, const std::vector<MirrorPlane>& mirrors,
                Model model, bool padded, double margin = 0)
        : scene_(scene), mirrors_(mirrors), model_(model), padded_(padded), margin_(margin) {
        for (size_t i = 0; i < objects.size(); ++i) {
            if (!isSlabbed(motionOf(objects[i].spec, model))) continue;
            Slabbed o;
            o.object = i;
            o.prepared = objects[i];
            const mesh4d::MotionInCameraFrame in_cut = cutMotionOf(objects[i].spec, model, scene);
            mesh4d::RestMesh rotated;
            o.rest = restInCameraFrame(objects[i].rest, in_cut, &rotated);
            o.motion = in_cut.motion;
            o.chord = slabChord(o.rest, o.motion);
            o.grid = mesh4d::SlabGrid(o.rest, o.motion, o.chord);
            slabbed_.push_back(std::move(o));
        }
    }
    const std::vector<Slabbed>& objects() const { return slabbed_; }

    // The span frames a..b see of o, from the camera and from each mirror image of it (the camera
    // is at rest for these motions), its open ends moved out to the grid, cut to o's existence.
    Span span(const Slabbed& o, long long a, long long b) const {
        double lo = INFINITY, hi = -INFINITY;
        bool padded = padded_;
        if (!padded) {
            std::vector<Scene> views{scene_};
            for (const MirrorPlane& m : mirrors_) {
                views.push_back(scene_);
                views.back().camera.position = reflectPoint(m, scene_.camera.position);
            }
            for (const Scene& v : views) {
                const mesh4d::ViewSurface first = viewForFrame(v, model_, a), last = viewForFrame(v, model_, b);
                const mesh4d::SeenSpan seen = mesh4d::slabSpanSeen(o.rest, o.motion, first, last, o.chord);
                padded = padded || !seen.ok;
                lo = std::min(lo, seen.span.lo - margin_);
                hi = std::max(hi, seen.span.hi + margin_);
            }
        }
        if (padded) {  // the peer, or a seen span that did not close: buildWorld's padded span
            const mesh4d::World4D w = traceWorld(o.prepared, model_, scene_, mirrors_, a, b);
            if (w.empty()) return {};
            lo = w.tau_a;
            hi = w.tau_b;
        }
        // Step: open ends out to the grid (where it has a point beyond), then the existence.
        const double grid_lo = o.grid.atOrBefore(lo), grid_hi = o.grid.atOrAfter(hi);
        if (grid_lo > -INFINITY) lo = grid_lo;
        if (grid_hi < INFINITY) hi = grid_hi;
        const ObjectSpec& s = o.prepared.spec;
        Span out;
        out.real_a = s.exists_from > lo;
        out.real_b = s.exists_to < hi;
        out.tau_a = out.real_a ? s.exists_from : lo;
        out.tau_b = out.real_b ? s.exists_to : hi;
        return out;
    }

    // The sample times of o's slabs over `span` (empty beyond max_slabs; none for an empty span).
    std::vector<double> samples(const Slabbed& o, const Span& span, size_t max_slabs) const {
        if (span.empty()) return {};
        return o.grid.samples(span.tau_a, span.tau_b, max_slabs);
    }

    // Whether every object's slabs for frames a..b fit max_slabs, and their prisms together
    // max_prisms; if not, *worst is the first object that does not fit (or the one with the most
    // prisms), *count its slabs (max_slabs + 1: more), *prisms the prisms of all counted so far.
    bool fits(long long a, long long b, size_t max_slabs, size_t max_prisms, size_t* worst = nullptr,
              size_t* count = nullptr, size_t* prisms = nullptr) const {
        size_t total = 0, most = 0;
        for (size_t i = 0; i < slabbed_.size(); ++i) {
            const Span sp = span(slabbed_[i], a, b);
            if (sp.empty()) continue;
            const std::vector<double> times = samples(slabbed_[i], sp, max_slabs);
            const size_t n = times.empty() ? max_slabs + 1 : times.size() - 1;
            const size_t p = n * slabbed_[i].rest.triangles.size();
            total += p;
            if (p > most) {
                most = p;
                if (worst) *worst = i;
                if (count) *count = n;
            }
            if (n > max_slabs) {
                if (worst) *worst = i;
                if (count) *count = n;
                if (prisms) *prisms = total;
                return false;
            }
        }
        if (prisms) *prisms = total;
        return total <= max_prisms;
    }

    // The last frame of the longest window k..end (end <= last) that fits (fits above); k - 1 when
    // frame k alone does not. The spans grow with the window, so a window that fits holds every
    // shorter one: doubling, then bisection.
    long long windowEnd(long long k, long long last, size_t max_slabs, size_t max_prisms) const {
        if (!fits(k, k, max_slabs, max_prisms)) return k - 1;
        long long good = k, bad = last + 1;
        for (long long step = 1; good + step <= last; step *= 2) {
            if (!fits(k, good + step, max_slabs, max_prisms)) {
                bad = good + step;
                break;
            }
            good += step;
        }
        while (bad - good > 1) {
            const long long mid = good + (bad - good) / 2;
            if (fits(k, mid, max_slabs, max_prisms)) good = mid;
            else bad = mid;
        }
        return good;
    }

private:
    Scene scene_;
    std::vector<MirrorPlane> mirrors_;
    Model model_;
    bool padded_;
    double margin_;  // TracerOptions::span_margin
    std::vector<Slabbed> slabbed_;
};

namespace {

// One line when some frame alone would need more slabs than the limits allow (a window of one
// frame, SceneTracer): more than kMaxTraceSlabs of one object, or more prisms than `slab_memory`
// holds; longer ranges are traced in windows.
Status checkTraceSlabs(const Stage& stage, const std::vector<Model>& models, long long first, long long last,
                       long long slab_memory) {
    const size_t max_prisms = slabPrismLimit(slab_memory);
    for (Model model : models) {
        const SlabPlanner planner(stage.scene, stage.objects, stage.mirrors, model, false);
        if (planner.objects().empty()) continue;
        for (long long k = first; k <= last;) {
            const long long end = planner.windowEnd(k, last, kMaxTraceSlabs, max_prisms);
            if (end >= k) {
                k = end + 1;
                continue;
            }
            size_t worst = 0, n = 0, prisms = 0;
            planner.fits(k, k, kMaxTraceSlabs, max_prisms, &worst, &n, &prisms);
            const SlabPlanner::Slabbed& o = planner.objects()[worst];
            const std::string where = stage.scene.path + ": " + motionField(o.prepared.spec, o.motion) + ": the raytracer would need ";
            const std::string model_name = std::string(" for model ") + modelName(model);
            if (n > kMaxTraceSlabs)
                return Status::failure(where + "more than " + std::to_string(kMaxTraceSlabs) + " time slabs of " +
                                       std::to_string(o.rest.triangles.size()) + " prisms for frame " + std::to_string(k) +
                                       " alone (at most " + std::to_string(kMaxTraceSlabs) + " for one object)" +
                                       model_name + ": use `apparent render`");
            return Status::failure(where + std::to_string(n) + " time slabs of " + std::to_string(o.rest.triangles.size()) +
                                   " prisms for frame " + std::to_string(k) + " alone (" + std::to_string(prisms) +
                                   " prisms of time slabs in all, about " +
                                   std::to_string((long long)prisms * kTraceBytesPerPrism >> 20) +
                                   " MiB, more than --max-slab-memory " + std::to_string(slab_memory) + " bytes holds: " +
                                   std::to_string(max_prisms) + " prisms)" + model_name +
                                   ": raise it, or use `apparent render`");
        }
    }
    return Status::success();
}

// What the raytracer needs of motions beyond uniform: slabs within the limits (their Doppler
// factors are the worldlines', shadeWith).
Status checkTracedMotions(const Stage& stage, long long slab_memory) {
    return checkTraceSlabs(stage, stage.models, stage.first, stage.last_excl - 1, slab_memory);
}

}  // namespace

int samplesSide(int samples) {
    for (int side = 1; side <= 16; ++side)
        if (side * side == samples) return side;
    return 0;
}

Vec3 pixelDirection(const CameraSpec& camera, int width, int height, int px, int py) {
    // Step: the camera basis: forward f, right r, up u (right-handed, u = r x f).
    const Vec3 f0 = camera.look_at - camera.position;
    const Vec3 f = f0 / mesh4d::norm(f0);
    const Vec3 r0 = mesh4d::cross(f, camera.up);
    const Vec3 r = r0 / mesh4d::norm(r0);
    const Vec3 u = mesh4d::cross(r, f);
    // Step: the pixel centre on the image plane at distance 1.
    const double half_h = std::tan(camera.fov_deg * mesh4d::kPi / 360);
    const double half_w = half_h * double(width) / double(height);
    const double x = (2 * (px + 0.5) / width - 1) * half_w;
    const double y = (1 - 2 * (py + 0.5) / height) * half_h;
    const Vec3 d = f + x * r + y * u;
    return d / mesh4d::norm(d);
}

Status checkGate(const Stage& stage, double depth) {
    if (depth == 0) return Status::success();
    if (!(depth > 0) || !std::isfinite(depth)) return Status::failure("--gate: the slice depth must be > 0");
    for (const PreparedObject& o : stage.objects) {
        const std::string field = stage.scene.path + ": " + o.spec.field_path;
        if (o.spec.mirror) return Status::failure(field + ".mirror: --gate does not trace mirrors");
        for (Model m : stage.models)
            if (!mesh4d::isUniform(motionOf(o.spec, m)))
                return Status::failure(field + ": --gate traces uniform motion only (this object spins, accelerates, "
                                               "orbits or follows keys)");
        mesh4d::EventBox box;
        for (const Vec3& q : o.rest.positions) box.addPoint(q);
        if (depth > box.diagonal())
            return Status::failure("--gate: the slice depth " + formatNumber(depth) + " is more than " + field + "'s size (" +
                                   formatNumber(box.diagonal()) + ", its bounding-box diagonal)");
    }
    return Status::success();
}

namespace {

// The checks of a traced stage (raytrace, figure): the slabs' memory, the gate, and the gate's
// warning for the models without light delay.
Status checkTracedStage(const Stage& stage, long long slab_memory, double gate, bool quiet, std::ostream& err) {
    if (Status s = checkTracedMotions(stage, slab_memory); !s.ok) return s;
    if (Status g = checkGate(stage, gate); !g.ok) return g;
    if (gate > 0 && !quiet)
        for (Model m : stage.models)
            if (m == Model::Instant || m == Model::Contracted)
                err << "warning: --gate: model " << modelName(m) << " has no light delay to gate; drawn ungated\n";
    return Status::success();
}

}  // namespace

PixelRay pixelRay(const CameraSpec& camera, int width, int height, int px, int py) {
    if (!camera.orthographic()) return {camera.position, pixelDirection(camera, width, height, px, py)};
    // Step: the camera basis, as pixelDirection's.
    const Vec3 f0 = camera.look_at - camera.position;
    const Vec3 f = f0 / mesh4d::norm(f0);
    const Vec3 r0 = mesh4d::cross(f, camera.up);
    const Vec3 r = r0 / mesh4d::norm(r0);
    const Vec3 u = mesh4d::cross(r, f);
    // Step: the pixel centre on the image plane through the camera, width scene units wide.
    const double half_w = 0.5 * camera.width;
    const double half_h = half_w * double(height) / double(width);
    const double x = (2 * (px + 0.5) / width - 1) * half_w;
    const double y = (1 - 2 * (py + 0.5) / height) * half_h;
    return {camera.position + x * r + y * u, f};
}

SceneTracer::SceneTracer(const Scene& scene, const std::vector<PreparedObject>& objects,
                         const std::vector<MirrorPlane>& mirrors, Model model, long long first_frame,
                         long long last_frame, TracerOptions options)
    : scene_(scene), model_(model), options_(options), first_(first_frame), last_(last_frame), mirrors_(mirrors),
      mirror_of_object_(objects.size(), -1) {
    for (size_t m = 0; m < mirrors_.size(); ++m) mirror_of_object_[mirrors_[m].object] = int32_t(m);
    // Step: the uniform motions' worlds once, over the whole range, with their traces (which point
    // into the worlds); the others' time slabs per window of frames (buildWindow), the first now.
    objects_.resize(objects.size());
    for (size_t i = 0; i < objects.size(); ++i) {
        colors_.push_back(objectBaseColor(objects, i));
        double radius = 0;
        for (const Vec3& q : objects[i].rest.positions) radius = std::max(radius, mesh4d::norm(q));
        rest_radius_.push_back(radius);
        lab_motions_.push_back(motionOf(objects[i].spec, model));
        motions_.push_back(cutMotionOf(objects[i].spec, model, scene).motion);
        if (isSlabbed(lab_motions_.back())) continue;
        objects_[i].chunks = {
            makeChunk({std::make_shared<const mesh4d::World4D>(traceWorld(objects[i], model, scene, mirrors_, first_frame, last_frame))},
                      false)};
    }
    planner_ = std::make_unique<SlabPlanner>(scene, objects, mirrors_, model, options_.padded_span,
                                            options_.span_margin);
    if (!planner_->objects().empty()) buildWindow(first_frame);
    listTraces();
}

void SceneTracer::listTraces() {
    trace_refs_.clear();
    for (size_t object = 0; object < objects_.size(); ++object) {
        const ObjectTraces& o = objects_[object];
        for (size_t c = o.chunks.size(); c-- > 0;)
            for (size_t i = o.chunks[c]->traces.size(); i-- > 0;)
                trace_refs_.push_back({&o.chunks[c]->traces[i], &o.chunks[c]->trace_worlds[i], int32_t(object),
                                       mirror_of_object_[object] >= 0});
    }
}

SceneTracer::~SceneTracer() = default;

size_t SceneTracer::worldCount() const {
    size_t n = 0;
    for (const ObjectTraces& o : objects_)
        for (const auto& c : o.chunks) n += c->worlds.size();
    return n;
}

std::shared_ptr<const SceneTracer::TraceChunk> SceneTracer::makeChunk(
    std::vector<std::shared_ptr<const mesh4d::World4D>> worlds, bool slabs) const {
    auto chunk = std::make_shared<TraceChunk>();
    chunk->worlds = std::move(worlds);
    // Several time slabs are traced through one hierarchy over all of them (ray4d.h
    // prepareSlabsTrace); without the hierarchy (the benchmarks' peer) each slab is scanned alone.
    if (slabs && chunk->worlds.size() > 1 && options_.hierarchy) {
        std::vector<const mesh4d::World4D*> all;
        std::vector<const mesh4d::World4D*> world_of_slab;  // the trace leaves out empty slabs: its slab numbers to worlds
        for (const auto& w : chunk->worlds) {
            all.push_back(w.get());
            if (!w->empty()) world_of_slab.push_back(w.get());
        }
        chunk->traces.push_back(mesh4d::prepareSlabsTrace(all));
        chunk->trace_worlds.push_back(std::move(world_of_slab));
        return chunk;
    }
    for (const auto& w : chunk->worlds) {
        chunk->traces.push_back(mesh4d::prepareTrace(*w, options_.hierarchy));
        chunk->trace_worlds.push_back({w.get()});
    }
    return chunk;
}

namespace {

// Prisms of one hierarchy over consecutive time slabs (TraceChunk): enough that a ray crossing
// thousands of slabs meets few chunks' roots, few enough that the chunk a window cuts and
// rebuilds costs little beside the window. At most kChunkSlabs slabs. Measured on the rolling
// wheel (792 prisms a slab, docs/PERFORMANCE.md): 2^16 (82 slabs) to 2^18 prisms trace a frame
// about as fast, and faster than one hierarchy over the window's 2587 slabs (which is also slower
// to build); 2^13 slower.
constexpr size_t kChunkPrisms = size_t(1) << 16;
constexpr size_t kChunkSlabs = 256;

}  // namespace

void SceneTracer::buildWindow(long long k) {
    // Step: the window from k: the longest run of frames whose slabs fit (the callers checked that
    // frame k alone does).
    const long long end = std::max(k, planner_->windowEnd(k, last_, options_.window_slabs, options_.window_prisms));
    size_t slabs = 0, built = 0;
    for (const SlabPlanner::Slabbed& o : planner_->objects()) {
        ObjectTraces& traces = objects_[o.object];
        const SlabPlanner::Span span = planner_->span(o, k, end);
        const std::vector<double> times = planner_->samples(o, span, std::numeric_limits<size_t>::max());
        if (times.size() < 2) {  // the object does not exist in the window
            auto empty = std::make_shared<mesh4d::World4D>();
            empty->motion = o.motion;
            traces.chunks = {makeChunk({std::move(empty)}, false)};
            continue;
        }
        const size_t n = times.size() - 1;
        slabs += n;
        // Step: the last window's slabs that this one has (the same times and caps: the grid makes
        // them the same slabs), and its chunks made only of them, at their places among the n.
        auto wanted = [&](const mesh4d::World4D& w, size_t i) {
            return w.tau_a == times[i] && w.tau_b == times[i + 1] && w.cap_a_real == (span.real_a && i == 0) &&
                   w.cap_b_real == (span.real_b && i + 1 == n);
        };
        std::vector<std::shared_ptr<const mesh4d::World4D>> slab(n);
        std::vector<std::shared_ptr<const TraceChunk>> kept(n);  // by the place of its first slab
        for (const auto& chunk : traces.chunks) {
            bool whole = true;
            for (const auto& w : chunk->worlds) {
                const size_t i = size_t(std::lower_bound(times.begin(), times.end() - 1, w->tau_a) - times.begin());
                if (i < n && wanted(*w, i)) slab[i] = w;
                else whole = false;
            }
            if (whole) kept[size_t(std::lower_bound(times.begin(), times.end() - 1, chunk->worlds.front()->tau_a) - times.begin())] = chunk;
        }
        // Step: the rest of the last window goes before anything new is built.
        traces.chunks.clear();
        // Step: the new slabs, in runs of consecutive places.
        for (size_t i = 0; i < n;) {
            if (slab[i]) {
                ++i;
                continue;
            }
            size_t j = i;
            while (j < n && !slab[j]) ++j;
            const std::vector<double> run(times.begin() + long(i), times.begin() + long(j) + 1);
            std::vector<mesh4d::World4D> made =
                mesh4d::extrudeSlabs(o.rest, o.motion, run, span.real_a && i == 0, span.real_b && j == n);
            for (size_t m = 0; m < made.size(); ++m) slab[i + m] = std::make_shared<const mesh4d::World4D>(std::move(made[m]));
            built += j - i;
            i = j;
        }
        // Step: the chunks: the kept ones, and the places between them cut into new chunks of at
        // most kChunkPrisms prisms (kChunkSlabs slabs).
        const size_t per_chunk =
            std::clamp<size_t>(kChunkPrisms / std::max<size_t>(1, o.rest.triangles.size()), 1, kChunkSlabs);
        for (size_t i = 0; i < n;) {
            if (kept[i]) {
                traces.chunks.push_back(std::move(kept[i]));
                i += traces.chunks.back()->worlds.size();
                continue;
            }
            std::vector<std::shared_ptr<const mesh4d::World4D>> worlds;
            for (; i < n && !kept[i] && worlds.size() < per_chunk; ++i) worlds.push_back(slab[i]);
            traces.chunks.push_back(makeChunk(std::move(worlds), true));
        }
    }
    window_first_ = k;
    window_last_ = end;
    ++slab_counts_.windows;
    slab_counts_.built += built;
    slab_counts_.most = std::max(slab_counts_.most, slabs);
}

SceneTracer::Hit SceneTracer::nearest(const mesh4d::Ray4D& ray, bool skip_mirrors, double s_limit) const {
    Hit best;
    double s_max = s_limit;
    // Objects in scene order; an object's chunks and traces (its time slabs, when scanned one by
    // one) latest first: the ray runs back in time, so the first slab it hits holds that object's
    // nearest hit, and the earlier slabs then fail their root box at once.
    for (const TraceRef& r : trace_refs_) {
        if (skip_mirrors && r.mirror) continue;
        if (const auto h = mesh4d::intersectWorld(*r.trace, ray, s_max)) {
            s_max = h->s;
            best.object = r.object;
            best.world = (*r.worlds)[h->slab];
            best.hit = *h;
        }
    }
    return best;
}

SceneTracer::Hit SceneTracer::nearestGated(const mesh4d::ViewSurface& view, const PixelRay& pixel, double near,
                                           double far) const {
    // Slices j from the first that reaches `near` to the last that starts before `far`, nearest
    // first; each traced within itself along its middle's lab instant.
    const long long j0 = std::max(0LL, (long long)std::floor(near / gate_));
    const long long j1 = (long long)std::floor(far / gate_);
    for (long long j = j0; j <= j1; ++j) {
        mesh4d::Ray4D ray;
        ray.origin = {view.t_c - (double(j) + 0.5) * gate_, pixel.origin + pixel.direction * (double(j) * gate_)};
        ray.direction = pixel.direction;
        ray.along_cone = false;
        Hit h = nearest(ray, false, gate_);
        if (h.object >= 0) {
            h.hit.s += double(j) * gate_;  // from the pixel's origin
            return h;
        }
    }
    return {};
}

std::array<double, 3> SceneTracer::shade(const Hit& h, mesh4d::ViewKind kind, const Vec3& receiver,
                                         const Vec3& receiver_velocity) const {
    return shadeWith(h, motions_[size_t(h.object)], h.hit.event.x, kind, receiver, receiver_velocity);
}

std::array<double, 3> SceneTracer::shadeWith(const Hit& h, const mesh4d::Motion& motion, const Vec3& emitted_at,
                                             mesh4d::ViewKind kind, const Vec3& receiver,
                                             const Vec3& receiver_velocity) const {
    // Lambert: base * (ambient + (1 - ambient) max(0, n . l)), summed over the lights with their
    // weights (the default key light, scene.h), n already turned towards the side
    // the ray arrives from (the surfaces are two-sided, as in the exported glTF). In the lab, where
    // the light is at rest (labShading: the hit's normal and point taken there).
    const LabShading lab = labShading(h.hit, motions_[size_t(h.object)], cameraMotionOf(scene_), model_);
    const Vec3 n = lab.normal;
    const LightSpec& light = scene_.light;
    Vec3 l = light.direction;
    if (light.kind == LightSpec::Kind::Point) {
        const Vec3 to_light = light.position - lab.point;
        const double len = mesh4d::norm(to_light);
        l = len > 0 ? to_light / len : Vec3{0, 0, 0};
    }
    const double diffuse = (1 - light.key_weight) * std::max(0.0, mesh4d::dot(n, l)) +
                           light.key_weight * std::max(0.0, mesh4d::dot(n, light.key_direction));
    const double lambert = light.ambient + (1 - light.ambient) * diffuse;
    std::array<double, 3> c{colors_[size_t(h.object)][0], colors_[size_t(h.object)][1], colors_[size_t(h.object)][2]};
    if (shade_doppler_) {
        double d = 1;
        if (mesh4d::isUniform(motion)) {
            d = mesh4d::dopplerFactor(motion, kind, receiver, emitted_at, receiver_velocity);
        } else {
            // The hit's own time kept inside its slab, short of its closing key, so that the segment
            // is this slab's (keyed.h gives a key to the segment it starts); the camera is at
            // rest for these motions.
            const mesh4d::World4D& slab = *h.world;
            const double s = std::max(slab.tau_a, std::min(h.hit.own_time, std::nextafter(slab.tau_b, slab.tau_a)));
            d = mesh4d::worldlineDoppler(motion, kind, receiver, s, h.hit.rest_point, emitted_at);
        }
        c = mesh4d::dopplerColour(c, d);
    }
    return {c[0] * lambert, c[1] * lambert, c[2] * lambert};
}

std::array<double, 3> SceneTracer::shadeReflected(const Hit& h, const mesh4d::ViewSurface& view, const MirrorPlane& m,
                                                  const mesh4d::CameraMotion& camera) const {
    // Doppler from the lab (mirror.h): the hit and the camera's reception in the lab, the source's
    // lab motion, seen from the image camera moving at the reflected velocity.
    const mesh4d::Kinematics kinematics = kinematicsOf(model_);
    const bool lab = view.sheared();  // finite: traced in the lab already
    const Vec3 emitted_at = lab ? h.hit.event.x : mesh4d::fromCameraFrame(camera, kinematics, h.hit.event).x;
    const mesh4d::Event receiver =
        lab ? mesh4d::Event{view.t_c, view.apex} : mesh4d::fromCameraFrame(camera, kinematics, {view.t_c, scene_.camera.position});
    return shadeWith(h, lab_motions_[size_t(h.object)], emitted_at, view.kind, reflectPoint(m, receiver.x),
                     reflectDirection(m, camera.velocity));
}

TracedFrame SceneTracer::traceFrame(long long k, int out_width, int out_height, TraceProgress* progress) {
    if (!planner_->objects().empty() && (k < window_first_ || k > window_last_)) {
        buildWindow(k);
        listTraces();
    }
    TracedFrame frame;
    frame.image = RgbImage(out_width, out_height);
    frame.object.assign(size_t(out_width) * size_t(out_height), -1);
    frame.reflected.assign(size_t(out_width) * size_t(out_height), -1);
    const mesh4d::ViewSurface view = viewForFrame(scene_, model_, k);
    const mesh4d::CameraMotion camera = cameraMotionOf(scene_);
    // The gated camera (setGate) in the light-speed models: the objects' extent along the rays,
    // from their apparent bounds widened by the slices' stepped delay (|u| DEPTH at most).
    const bool gated = gate_ > 0 && (model_ == Model::Finite || model_ == Model::Relativistic);
    std::vector<mesh4d::BoundingSphere> gate_bounds;
    if (gated) {
        for (size_t i = 0; i < motions_.size(); ++i) {
            mesh4d::World4D w;
            w.motion = motions_[i];
            w.shape_radius = rest_radius_[i];
            gate_bounds.push_back(mesh4d::apparentBound(w, view));
            gate_bounds.back().radius += gate_;
        }
    }
    // Step: the samples: the pixels of the picture s times as wide and high (s x s per pixel, their
    // centres the strata's), summed per pixel in linear light; row py of it is pass py mod s.
    const int s = samples_side_, width = out_width * s, height = out_height * s;
    std::vector<std::array<double, 3>> sum(size_t(out_width) * size_t(out_height), {0, 0, 0});
    const auto trace_row = [&](int py) {
        for (int px = 0; px < width; ++px) {
            const size_t idx = size_t(py / s) * size_t(out_width) + size_t(px / s);
            const bool centre = px % s == s / 2 && py % s == s / 2;  // the sample the object buffers hold
            if (gated) {
                // Step: the gated primary ray: the first slice with a hit (nearestGated).
                const PixelRay pixel = pixelRay(scene_.camera, width, height, px, py);
                // The part of the ray within the widened bounds: where a slice may hit.
                double near = INFINITY, far = -INFINITY;
                for (const mesh4d::BoundingSphere& b : gate_bounds) {
                    const Vec3 oc = b.center - pixel.origin;
                    const double mid = mesh4d::dot(oc, pixel.direction);
                    const double half2 = b.radius * b.radius - (mesh4d::norm2(oc) - mid * mid);
                    if (!(half2 >= 0)) continue;
                    near = std::min(near, mid - std::sqrt(half2));
                    far = std::max(far, mid + std::sqrt(half2));
                }
                const Hit hit = far >= 0 ? nearestGated(view, pixel, near, far) : Hit{};
                std::array<double, 3> color = kBackground;
                if (hit.object >= 0) {
                    if (centre) frame.object[idx] = hit.object;
                    color = shade(hit, mesh4d::ViewKind::PastCone, pixel.origin);
                }
                for (size_t c = 0; c < 3; ++c) sum[idx][c] += color[c];
                continue;
            }
            // Step: the primary ray, back along the past cone (or along t = t_c). A sheared view
            // (finite, moving camera) is traced in the lab from the camera's lab position, along
            // the lab direction the pixel's camera-frame direction sees (camera_frame.h).
            // An orthographic camera's ray leaves its pixel on the image plane along the view
            // direction, at t_c: along the tilted hyperplane's null rays in finite and relativistic.
            mesh4d::Ray4D ray;
            ray.origin = {view.t_c, view.apex};
            if (scene_.camera.orthographic()) {
                const PixelRay p = pixelRay(scene_.camera, width, height, px, py);
                ray.origin = {view.t_c, p.origin};
                ray.direction = p.direction;
            } else {
                ray.direction = pixelDirection(scene_.camera, width, height, px, py);
            }
            if (view.sheared()) ray.direction = mesh4d::labRayDirection(camera, ray.direction);
            const bool tilted = view.kind == mesh4d::ViewKind::Hyperplane && view.tilted();
            ray.along_cone = view.kind == mesh4d::ViewKind::PastCone || tilted;
            const mesh4d::ViewKind light_kind = tilted ? mesh4d::ViewKind::PastCone : view.kind;
            const Hit hit = nearest(ray, false);
            std::array<double, 3> color = kBackground;
            if (hit.object >= 0) {
                if (centre) frame.object[idx] = hit.object;
                color = shade(hit, light_kind, ray.origin.x, view.shear);
                const int32_t mirror = mirror_of_object_[size_t(hit.object)];
                if (mirror >= 0) {
                    // Step: one bounce: restart at the hit event with the reflected direction,
                    // still running back in time; other mirrors are not seen in a mirror.
                    // With a moving camera the mirror moves in the frame traced (not in finite's lab).
                    const MirrorPlane& plane = mirrors_[size_t(mirror)];
                    mesh4d::Ray4D bounce = ray;
                    bounce.origin = hit.hit.event;
                    bounce.direction = view.sheared() ? reflectDirection(plane, ray.direction)
                                                      : reflectRayDirection(plane, camera, kinematicsOf(model_),
                                                                            ray.along_cone, ray.direction);
                    const Hit second = nearest(bounce, true);
                    std::array<double, 3> reflected = kBackground;
                    if (second.object >= 0) {
                        if (centre) frame.reflected[idx] = second.object;
                        reflected = camera.moving() ? shadeReflected(second, view, plane, camera)
                                                    : shade(second, view.kind, bounce.origin.x);
                    }
                    for (int c = 0; c < 3; ++c)
                        color[size_t(c)] = (1 - kMirrorReflectance) * color[size_t(c)] + kMirrorReflectance * reflected[size_t(c)];
                }
            }
            for (size_t c = 0; c < 3; ++c) sum[idx][c] += color[c];
        }
        if (progress) progress->rowDone();
    };
    for (int pass = 0; pass < s; ++pass) tbb::parallel_for(0, out_height, [&](int row) { trace_row(row * s + pass); });
    // Step: each pixel the mean of its samples, to 8-bit sRGB.
    const double n = double(s) * double(s);
    for (int py = 0; py < out_height; ++py)
        for (int px = 0; px < out_width; ++px) {
            uint8_t* p = frame.image.pixel(px, py);
            const std::array<double, 3>& c = sum[size_t(py) * size_t(out_width) + size_t(px)];
            for (size_t i = 0; i < 3; ++i) p[i] = toSrgb8(c[i] / n);
        }
    return frame;
}

int raytrace(const RaytraceSettings& settings, std::ostream& log_out, std::ostream& err_out) {
    // Under mpirun the ranks share the frames as render's do (pipeline/distribute.h): rank r traces
    // frames k with k - first = r mod N and sends each picture to rank 0, which writes the PNG files
    // and the video in frame order; the other ranks print nothing.
    FrameGroup& group = frameGroup();
    const bool sender = group.rank() > 0, receiver = group.rank() == 0 && group.size() > 1;
    std::ostringstream silent;
    std::ostream& log = sender ? silent : log_out;
    std::ostream& err = sender ? silent : err_out;
    // Step: the stage: scene, models, frames, meshes, mirrors; then the video's one model and ffmpeg.
    Stage stage;
    StageOptions stage_options = settings.stage;
    stage_options.quiet = settings.quiet || sender;
    std::string error;
    int code = loadStage(stage_options, &stage, err, &error) ? kExitOk : kExitBadInput;
    if (!code)
        if (Status s = checkTracedStage(stage, settings.max_slab_memory, settings.gate, settings.quiet, err); !s.ok) {
            error = s.message;
            code = kExitBadInput;
        }
    const bool video = !settings.video_path.empty();
    if (!code && !sender && video && stage.models.size() != 1) {
        error = "--video: a video shows one model (" + std::to_string(stage.models.size()) +
                " asked); `apparent figure --video` shows several side by side";
        code = kExitBadInput;
    }
    if (!code && !sender && video && findInPath("ffmpeg").empty()) {
        error = ffmpegMissingMessage("--video");
        code = kExitBadInput;
    }
    if ((code = group.agree(code, &error))) {
        err << "error: " << error << "\n";
        return code;
    }
    const long long first = stage.first, last_excl = stage.last_excl;
    const FrameSplit split{group.rank(), group.size()};

    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    const int side = samplesSide(settings.samples);
    TraceProgress progress(err, !settings.quiet && !sender,
                           (long long)stage.models.size() * (last_excl - first) * settings.height * side);
    for (Model model : stage.models) {
        const auto start = std::chrono::steady_clock::now();
        TracerOptions options;
        options.window_prisms = slabPrismLimit(settings.max_slab_memory);
        SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, model, first, last_excl - 1, options);
        tracer.setShadeDoppler(settings.shade_doppler);
        tracer.setSamplesSide(side);
        tracer.setGate(settings.gate);
        if (sender) {
            // Step (rank r > 0): trace this rank's frames and send each picture, until rank 0 says END.
            for (long long k = first + split.part; k < last_excl && !group.stopRequested(); k += split.parts) {
                TracedFrame frame;
                arena.execute([&] { frame = tracer.traceFrame(k, settings.width, settings.height, nullptr); });
                group.sendFrame(std::string(frame.image.rgb.begin(), frame.image.rgb.end()));
            }
            if (const int end = group.finishSending()) return end;
            continue;
        }
        // Rank 0 (or one process): a failure ends every rank's frames with its code.
        auto fail = [&](int c, const std::string& message) {
            if (receiver) group.endFrames(c);
            err << "error: " << message << "\n";
            return c;
        };
        // Hints instead of blanks: an object no frame shows in the camera's view (view_hints.h).
        if (!settings.quiet)
            for (const std::string& w : outOfViewWarnings(stage, model, frameRange(first, last_excl))) err << "warning: " << w << "\n";
        // Step: the folder, then the static worlds once per model, then every frame.
        const std::string dir = (std::filesystem::path(settings.out_dir) / modelName(model)).string();
        if (settings.write_png) {
            std::error_code ec;
            std::filesystem::create_directories(dir, ec);
            if (ec) return fail(kExitOutputError, dir + ": cannot create output folder: " + ec.message());
        }
        VideoWriter writer;
        if (video && !writer.open(settings.video_path, settings.width, settings.height, stage.scene.frames.fps, &error))
            return fail(kExitOutputError, error);
        for (long long k = first; k < last_excl; ++k) {
            progress.setLabel(std::string(modelName(model)) + " frame " + std::to_string(k));
            TracedFrame frame;
            if (split.partOf(k, first) == 0) {
                arena.execute([&] { frame = tracer.traceFrame(k, settings.width, settings.height, &progress); });
            } else {
                std::string bytes;
                int remote = 0;
                if (!group.receiveFrame(split.partOf(k, first), &bytes, &remote, &error))
                    return fail(remote ? remote : 1, error);
                frame.image = RgbImage(settings.width, settings.height);
                if (bytes.size() != frame.image.rgb.size())
                    return fail(1, "internal: rank " + std::to_string(split.partOf(k, first)) + " sent a picture of " +
                                       std::to_string(bytes.size()) + " bytes for frame " + std::to_string(k));
                std::copy(bytes.begin(), bytes.end(), frame.image.rgb.begin());
                for (int row = 0; row < settings.height * side; ++row) progress.rowDone();
            }
            if (settings.write_png &&
                !writePng((std::filesystem::path(dir) / (frameName(k) + ".png")).string(), frame.image, &error))
                return fail(kExitOutputError, error);
            if (video && !writer.addFrame(frame.image, &error)) return fail(kExitOutputError, error);
        }
        if (video && !writer.finish(&error)) return fail(kExitOutputError, error);
        if (receiver) group.endFrames(0);
        progress.finish();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!settings.quiet) {
            log << modelName(model) << ": " << (last_excl - first) << " frames of " << settings.width << "x"
                << settings.height << (side > 1 ? ", " + std::to_string(side * side) + " samples a pixel," : "") << " in "
                << std::fixed << std::setprecision(2) << seconds << " s" << std::defaultfloat << std::setprecision(6);
            if (settings.write_png) log << ", " << dir << "/";
            if (video) log << ", " << settings.video_path << " (H.264, " << stage.scene.frames.fps << " fps)";
            if (receiver) log << ", " << group.size() << " processes shared the frames";
            const SceneTracer::SlabCounts& slabs = tracer.slabCounts();
            if (slabs.windows == 1 && slabs.built > 0) log << ", " << slabs.built << " time slabs";
            if (slabs.windows > 1)
                log << ", " << slabs.built << " time slabs in " << slabs.windows << " windows of frames (at most "
                    << slabs.most << " at once)";
            log << "\n";
        }
    }
    return kExitOk;
}

std::vector<long long> figureFrames(const Scene& scene, int columns) {
    const long long total = frameCount(scene.frames);
    std::vector<long long> frames;
    for (int j = 0; j < columns; ++j)
        frames.push_back(columns == 1 ? total / 2 : (long long)std::llround(double(j) * double(total - 1) / (columns - 1)));
    return frames;
}

bool framesAtTimes(const Scene& scene, const std::vector<double>& times, std::vector<long long>* frames,
                   std::string* error) {
    const long long total = frameCount(scene.frames);
    frames->clear();
    for (double t : times) {
        const double k = std::round((t - scene.frames.start) * scene.frames.fps);
        if (!(k >= 0 && k < double(total))) {
            std::ostringstream msg;
            msg << "--times: t = " << t << " s is outside the scene's frames (" << scene.frames.start << " to "
                << frameTime(scene.frames, total - 1) << " s)";
            *error = msg.str();
            return false;
        }
        frames->push_back((long long)k);
    }
    return true;
}

TimePrefix cameraTimePrefix(const Scene& scene) {
    const double last = frameTime(scene.frames, std::max(0LL, frameCount(scene.frames) - 1));
    return timePrefixFor(std::max(std::fabs(scene.frames.start), std::fabs(last)));
}

std::string cameraTimeLabel(const Scene& scene, long long k) {
    // As many decimals as the frame rate needs in the prefix's unit (10 fps: one), so labels keep
    // their width in a video.
    const TimePrefix prefix = cameraTimePrefix(scene);
    const double rate = scene.frames.fps * prefix.seconds;
    const int decimals = rate <= 1 ? 0 : std::min(6, int(std::ceil(std::log10(rate) - 1e-9)));
    return "t = " + timeText(frameTime(scene.frames, k), prefix, decimals);
}

namespace {

// Under mpirun (pipeline/distribute.h) a figure's pictures are shared as raytrace's frames are:
// picture i (a panel of the sheet, or a frame of the video) is traced by rank i mod N, which
// sends it to rank 0; rank 0 places or encodes them in order and writes the one output.
// The group's side of a figure: `fail` ends the ranks' loop with a code (rank 0), `picture`
// makes picture i here or receives it from its rank (false: failed, the code returned).
struct FigureGroup {
    FrameGroup& group = frameGroup();
    bool sender = group.rank() > 0;
    bool receiver = group.rank() == 0 && group.size() > 1;
    FrameSplit split{group.rank(), group.size()};
    std::ostream* err = nullptr;

    int fail(int code, const std::string& message) {
        if (receiver) group.endFrames(code);
        *err << "error: " << message << "\n";
        return code;
    }
    // Rank 0: picture i of `width` x `height` into *image, made by `make` here or received; the
    // progress counts a received picture's rows (`rows` of them).
    template <typename Make>
    int picture(long long i, int width, int height, long long rows, TraceProgress* progress, RgbImage* image,
                const Make& make) {
        const int from = split.partOf(i, 0);
        if (from == 0) {
            *image = make(progress);
            return kExitOk;
        }
        std::string bytes, error;
        int remote = 0;
        if (!group.receiveFrame(from, &bytes, &remote, &error)) return fail(remote ? remote : 1, error);
        *image = RgbImage(width, height);
        if (bytes.size() != image->rgb.size())
            return fail(1, "internal: rank " + std::to_string(from) + " sent a picture of " + std::to_string(bytes.size()) +
                               " bytes for picture " + std::to_string(i));
        std::copy(bytes.begin(), bytes.end(), image->rgb.begin());
        for (long long row = 0; row < rows; ++row) progress->rowDone();
        return kExitOk;
    }
    // Rank r > 0: picture i made and sent when it is this rank's; false once rank 0 said END.
    template <typename Make>
    bool send(long long i, const Make& make) {
        if (!split.owns(i, 0)) return true;
        if (group.stopRequested()) return false;
        const RgbImage image = make(nullptr);
        group.sendFrame(std::string(image.rgb.begin(), image.rgb.end()));
        return true;
    }
};

// The side-by-side video of `figure --video`: one video frame per scene frame in the stage's range,
// the models in columns under their names, the camera time (after the title) above.
int figureVideo(const FigureSettings& settings, const Stage& stage, const TextPainter* painter, FigureGroup& fg,
                std::ostream& log, std::ostream& err) {
    const Scene& scene = stage.scene;
    std::string error;
    SheetText base_text;
    if (painter)
        for (size_t m = 0; m < stage.models.size(); ++m)
            base_text.column_labels.push_back(settings.row_labels.empty() ? modelName(stage.models[m]) : settings.row_labels[m]);
    base_text.title = "t";  // a title band for the time, filled per frame
    const auto title_at = [&](long long k) {
        return (settings.title.empty() ? "" : settings.title + "   ") + cameraTimeLabel(scene, k);
    };
    SheetLayout base(1, int(stage.models.size()), settings.width, settings.height, base_text, painter != nullptr);
    // Step: the title band as high as the longest title of any frame wraps to (one size for the video).
    if (painter)
        for (long long k = stage.first; k < stage.last_excl; ++k)
            base.min_title_lines = std::max(base.min_title_lines,
                                            int(wrapText(*painter, title_at(k), base.title_px, base.width - 2 * base.pad).size()));
    const int extra_lines = painter ? base.min_title_lines - 1 : 0;
    const int sheet_width = base.width, sheet_height = base.height + extra_lines * base.titleStep();
    const int side = samplesSide(settings.samples > 0 ? settings.samples : kDefaultRaytraceSamples);
    std::vector<std::unique_ptr<SceneTracer>> tracers;
    for (Model m : stage.models) {
        TracerOptions options;  // the models' tracers at once share the budget
        options.window_prisms = slabPrismLimit(settings.max_slab_memory / (long long)stage.models.size());
        tracers.push_back(
            std::make_unique<SceneTracer>(scene, stage.objects, stage.mirrors, m, stage.first, stage.last_excl - 1, options));
        tracers.back()->setShadeDoppler(settings.shade_doppler);
        tracers.back()->setSamplesSide(side);
        tracers.back()->setGate(settings.gate);
    }
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    // Video frame k: the title band with its time, then every model's panel.
    long long k = stage.first;
    auto make = [&](TraceProgress* progress) {
        SheetText text = base_text;
        text.title = title_at(k);
        SheetLayout layout = base;
        RgbImage sheet = drawSheet(text, painter, &layout);
        for (size_t m = 0; m < tracers.size(); ++m) {
            if (progress) progress->setLabel(std::string(modelName(stage.models[m])) + " frame " + std::to_string(k));
            TracedFrame frame;
            arena.execute([&] { frame = tracers[m]->traceFrame(k, settings.width, settings.height, progress); });
            placePanel(&sheet, layout, 0, int(m), frame.image);
        }
        return sheet;
    };
    if (fg.sender) {
        for (; k < stage.last_excl && fg.send(k - stage.first, make); ++k) {}
        return fg.group.finishSending();
    }
    VideoWriter writer;
    if (!writer.open(settings.video_path, sheet_width, sheet_height, scene.frames.fps, &error))
        return fg.fail(kExitOutputError, error);
    TraceProgress progress(err, !settings.quiet,
                           (long long)stage.models.size() * (stage.last_excl - stage.first) * settings.height * side);
    for (; k < stage.last_excl; ++k) {
        RgbImage sheet;
        if (const int code = fg.picture(k - stage.first, sheet_width, sheet_height,
                                        (long long)stage.models.size() * settings.height * side, &progress, &sheet, make))
            return code;
        if (!writer.addFrame(sheet, &error)) return fg.fail(kExitOutputError, error);
    }
    if (!writer.finish(&error)) return fg.fail(kExitOutputError, error);
    if (fg.receiver) fg.group.endFrames(0);
    progress.finish();
    if (!settings.quiet) {
        log << settings.video_path << ": " << writer.frames() << " frames of " << sheet_width << "x" << sheet_height
            << " at " << scene.frames.fps << " fps (H.264), frames " << stage.first << ".." << stage.last_excl - 1;
        if (side > 1) log << ", " << side * side << " samples a pixel";
        if (settings.frame_objects) {
            const Vec3 at = scene.camera.look_at * unitsPerLightSecond(scene.units);  // in the scene's units
            log << ", framed: camera.look_at [" << at.x << ", " << at.y << ", " << at.z << "], camera.fov_deg "
                << scene.camera.fov_deg;
        }
        if (fg.receiver) log << ", " << fg.group.size() << " processes shared the frames";
        log << "\n";
    }
    return kExitOk;
}

}  // namespace

int figure(const FigureSettings& settings, std::ostream& log_out, std::ostream& err_out) {
    // Under mpirun the ranks share the pictures (FigureGroup above); the others print nothing.
    FigureGroup fg;
    std::ostringstream silent;
    std::ostream& log = fg.sender ? silent : log_out;
    std::ostream& err = fg.sender ? silent : err_out;
    fg.err = &err;
    // Step: the stage, for the rows' models (instant, finite, relativistic unless --models) and
    // all frames (a video: the --frames range).
    const bool video = !settings.video_path.empty();
    Stage stage;
    StageOptions stage_options = settings.stage;
    stage_options.models = settings.models.empty() ? std::vector<Model>{Model::Instant, Model::Finite, Model::Relativistic}
                                                   : settings.models;
    stage_options.all_models = false;
    stage_options.frame_from = video && settings.frame_from >= 0 ? settings.frame_from : 0;
    stage_options.frame_to = video && settings.frame_from >= 0 ? settings.frame_to : -1;
    stage_options.quiet = settings.quiet || fg.sender;
    std::string error;
    int code = loadStage(stage_options, &stage, err, &error) ? kExitOk : kExitBadInput;
    if (!code) {
        const long long memory = video ? settings.max_slab_memory / (long long)stage.models.size() : settings.max_slab_memory;
        if (Status s = checkTracedStage(stage, memory, settings.gate, settings.quiet, err); !s.ok) {
            error = s.message;
            code = kExitBadInput;
        }
    }
    const Scene& scene = stage.scene;
    const std::vector<Model>& rows = stage.models;
    // Step: the columns: --times, --frames A:B, or --columns evenly spaced.
    std::vector<long long> frames;
    if (!code && !video) {
        if (!settings.times.empty()) {
            if (!framesAtTimes(scene, settings.times, &frames, &error)) code = kExitBadInput;
        } else if (settings.frame_from >= 0) {
            const long long total = frameCount(scene.frames);
            const long long to = settings.frame_to < 0 ? total : settings.frame_to;
            if (settings.frame_from >= total || to > total) {
                error = "--frames: " + std::to_string(settings.frame_from) + ":" + std::to_string(to) +
                        " is outside the scene's " + std::to_string(total) + " frames";
                code = kExitBadInput;
            } else if (to - settings.frame_from > kMaxFigureColumns) {
                error = "--frames: " + std::to_string(to - settings.frame_from) + " columns, more than " +
                        std::to_string(kMaxFigureColumns);
                code = kExitBadInput;
            }
            for (long long k = settings.frame_from; !code && k < to; ++k) frames.push_back(k);
        } else {
            frames = figureFrames(scene, settings.columns);
        }
    }
    // Step: the labels given for the rows and columns, one each.
    if (!code && !settings.row_labels.empty() && settings.row_labels.size() != rows.size()) {
        error = "--row-labels: " + std::to_string(settings.row_labels.size()) + " labels for " +
                std::to_string(rows.size()) + " models";
        code = kExitBadInput;
    }
    if (!code && !settings.column_labels.empty() && settings.column_labels.size() != frames.size()) {
        error = "--column-labels: " + std::to_string(settings.column_labels.size()) + " labels for " +
                std::to_string(frames.size()) + " columns";
        code = kExitBadInput;
    }
    // Step: --frame-objects: the camera aimed and its view fitted to the objects in these frames.
    if (!code && settings.frame_objects) {
        std::vector<long long> framed = frames;
        for (long long k = stage.first; video && k < stage.last_excl; ++k) framed.push_back(k);
        if (Status s = frameObjects(stage, rows, framed, settings.width, settings.height, &stage.scene.camera); !s.ok) {
            error = s.message;
            code = kExitBadInput;
        }
    }
    // Step: the font (labels and title) and ffmpeg (video), before any tracing.
    TextPainter painter;
    const bool with_text = settings.labels || !settings.title.empty();
    if (!code && with_text && !painter.open(kLabelFontPath, &error)) code = kExitBadInput;
    if (!code && !fg.sender && video && findInPath("ffmpeg").empty()) {
        error = ffmpegMissingMessage("--video");
        code = kExitBadInput;
    }
    if ((code = fg.group.agree(code, &error))) {
        err << "error: " << error << "\n";
        return code;
    }
    if (video) return figureVideo(settings, stage, with_text ? &painter : nullptr, fg, log, err);
    // Step: lay out the sheet: a row per model, a column per frame, labels in bands left and above.
    SheetText text;
    text.title = settings.title;
    if (settings.labels) {
        text.row_labels = settings.row_labels;
        text.column_labels = settings.column_labels;
        for (size_t r = 0; settings.row_labels.empty() && r < rows.size(); ++r) text.row_labels.push_back(modelName(rows[r]));
        for (size_t c = 0; settings.column_labels.empty() && c < frames.size(); ++c)
            text.column_labels.push_back(cameraTimeLabel(scene, frames[c]));
    }
    SheetLayout layout(int(rows.size()), int(frames.size()), settings.width, settings.height, text, with_text);
    RgbImage sheet = fg.sender ? RgbImage() : drawSheet(text, with_text ? &painter : nullptr, &layout);
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    const int side = samplesSide(settings.samples > 0 ? settings.samples : kDefaultFigureSamples);
    TraceProgress progress(err, !settings.quiet && !fg.sender,
                           (long long)rows.size() * (long long)frames.size() * settings.height * side);
    // Panel i = r * columns + c: row r's model at column c's frame.
    const auto [lo, hi] = std::minmax_element(frames.begin(), frames.end());
    for (size_t r = 0; r < rows.size(); ++r) {
        // Hints instead of an empty row: an object no column shows in the camera's view (view_hints.h).
        if (!settings.quiet && !fg.sender)
            for (const std::string& w : outOfViewWarnings(stage, rows[r], frames)) err << "warning: " << w << "\n";
        TracerOptions options;
        options.window_prisms = slabPrismLimit(settings.max_slab_memory);
        SceneTracer tracer(scene, stage.objects, stage.mirrors, rows[r], *lo, *hi, options);
        tracer.setShadeDoppler(settings.shade_doppler);
        tracer.setSamplesSide(side);
        tracer.setGate(settings.gate);
        for (size_t c = 0; c < frames.size(); ++c) {
            auto make = [&](TraceProgress* p) {
                if (p) p->setLabel(std::string(modelName(rows[r])) + " frame " + std::to_string(frames[c]));
                TracedFrame frame;
                arena.execute([&] { frame = tracer.traceFrame(frames[c], settings.width, settings.height, p); });
                return frame.image;
            };
            const long long i = (long long)(r * frames.size() + c);
            if (fg.sender) {
                if (!fg.send(i, make)) return fg.group.finishSending();
                continue;
            }
            RgbImage panel;
            if (const int failed = fg.picture(i, settings.width, settings.height, (long long)settings.height * side, &progress, &panel, make))
                return failed;
            placePanel(&sheet, layout, int(r), int(c), panel);
        }
    }
    if (fg.sender) return fg.group.finishSending();
    progress.finish();
    const std::filesystem::path parent = std::filesystem::path(settings.out_path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (ec || !writePng(settings.out_path, sheet, &error))
        return fg.fail(kExitOutputError, ec ? settings.out_path + ": cannot create folder: " + ec.message() : error);
    if (fg.receiver) fg.group.endFrames(0);
    if (!settings.quiet) {
        log << settings.out_path << ": " << sheet.width << "x" << sheet.height << ", rows";
        for (Model m : rows) log << " " << modelName(m);
        log << "; frames";
        const TimePrefix prefix = cameraTimePrefix(scene);
        for (long long k : frames)
            log << " " << k << " (t = " << frameTime(scene.frames, k) / prefix.seconds << " " << prefix.name << ")";
        if (side > 1) log << "; " << side * side << " samples a pixel";
        if (settings.frame_objects) {
            const Vec3 at = scene.camera.look_at * unitsPerLightSecond(scene.units);  // in the scene's units
            log << "; framed: camera.look_at [" << at.x << ", " << at.y << ", " << at.z << "], camera.fov_deg "
                << scene.camera.fov_deg;
        }
        if (fg.receiver) log << "; " << fg.group.size() << " processes shared the frames";
        log << "\n";
    }
    return kExitOk;
}

}  // namespace apparent
