// The time slabs of the objects whose motion is not uniform, as the 4D raytracer holds them
// (pipeline/trace/raytrace.h SceneTracer: windows of frames): the span of an object's time a window of
// frames sees, its slabs on the motion's grid (mesh4d/extrude.h SlabGrid) and whether a window
// fits the limits (SlabPlanner); the check that every frame alone fits them (checkTracedMotions);
// and the world a uniform motion is traced over (traceWorld).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mesh4d/extrude.h"
#include "mesh4d/motion/seen.h"
#include "mesh4d/motion/worldline.h"
#include "pipeline/stage/mirror.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

// Time slabs for a motion that is not uniform (mesh4d/extrude.h): each vertex's sampled worldline
// within kSlabChordRelative of the object's bounding-box diagonal of its true one in the lab (the
// own-frame chord divided by the boost's or carry's largest stretch, gamma (1 + b)).
constexpr double kSlabChordRelative = 1e-3;

// The slabs' chord in the object's own frame (above) for `mesh` moving with `motion`.
double slabChord(const mesh4d::RestMesh& mesh, const mesh4d::Motion& motion);

// The world of `object` extruded over the union of the spans seen from the camera and from each
// mirror image of the camera, so that reflected rays, which reach further into the past, stay
// inside the history. Existence caps stay real where they clip either span. buildWorld's span,
// padded by the light-crossing time over 1 - b: what a uniform motion is traced over.
mesh4d::World4D traceWorld(const PreparedObject& object, Model model, const Scene& scene,
                           const std::vector<MirrorPlane>& mirrors, long long first, long long last);

// Whether the raytracer traces `motion` in time slabs: every motion that is not uniform.
inline bool isSlabbed(const mesh4d::Motion& motion) { return !mesh4d::isUniform(motion); }

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

// What the raytracer needs of motions beyond uniform (raytrace and figure check it): every frame
// alone within kMaxTraceSlabs of one object and the prisms `slab_memory` holds
// (pipeline/trace/raytrace.h); longer ranges are traced in windows. One line naming the object's
// motion field, the frame and the limit otherwise.
Status checkTracedMotions(const Stage& stage, long long slab_memory);

}  // namespace apparent
