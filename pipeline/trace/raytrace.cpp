#include "pipeline/trace/raytrace.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <ostream>

#include <tbb/parallel_for.h>

#include "mesh4d/angles.h"
#include "mesh4d/doppler_colour.h"
#include "mesh4d/box.h"
#include "mesh4d/light_factors.h"
#include "mesh4d/motion/kinds.h"
#include "mesh4d/motion/seen.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/worlds.h"
#include "pipeline/trace/slab_planner.h"

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

Status checkTracedStage(const Stage& stage, long long slab_memory, double gate, bool quiet, std::ostream& err) {
    if (Status s = checkTracedMotions(stage, slab_memory); !s.ok) return s;
    if (Status g = checkGate(stage, gate); !g.ok) return g;
    if (gate > 0 && !quiet)
        for (Model m : stage.models)
            if (m == Model::Instant || m == Model::Contracted)
                err << "warning: --gate: model " << modelName(m) << " has no light delay to gate; drawn ungated\n";
    return Status::success();
}

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

}  // namespace apparent
