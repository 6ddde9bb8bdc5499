#include "mesh4d/slice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>

#include "mesh4d/cut/frame_builder.h"

namespace mesh4d {
namespace slicing {

void FrameBuilder::classifyVertices(const std::vector<uint8_t>* live) {
    const size_t nv = world.mesh.positions.size();
    side.assign(nv, Side::Inside);
    // No real cap, nothing culled, every vertex used, the refinement's batch cut made.
    if (!world.cap_a_real && !world.cap_b_real && !live && world.simple && r_pos.size() == nv && out.positions.empty()) {
        out.positions.assign(r_pos.begin(), r_pos.end());
        out.emission_times.assign(r_time.begin(), r_time.end());
        out.rest_points = world.mesh.positions;
        vertex_out.resize(nv);
        for (size_t i = 0; i < nv; ++i) vertex_out[i] = uint32_t(i);
        return;
    }
    vertex_out.assign(nv, kUnset);
    std::vector<uint8_t> needed;
    if (live) {
        needed.assign(nv, 0);
        for (size_t c = 0; c < world.chunks.size(); ++c)
            if ((*live)[c])
                for (uint32_t f = world.chunks[c].first; f < world.chunks[c].last; ++f)
                    for (uint32_t v : world.mesh.triangles[f]) needed[v] = 1;
    }
    for (size_t i = 0; i < nv; ++i) {
        if (live && !needed[i]) side[i] = Side::NotYet;  // only culled triangles use it
        else if (world.cap_a_real && viewSideSign(view, world.events[2 * i]) < 0) side[i] = Side::NotYet;
        else if (world.cap_b_real && viewSideSign(view, world.events[2 * i + 1]) > 0) side[i] = Side::Gone;
    }
    // Visible vertices first, in input order.
    for (size_t i = 0; i < nv; ++i)
        if (side[i] == Side::Inside && world.vertex_used[i]) vertexPoint(uint32_t(i));
}

uint32_t FrameBuilder::crossingPoint(uint32_t edge, int cap) {
    uint32_t& slot = crossing_out[2 * edge + cap];
    if (slot == kUnset) {
        const Edge& e = world.edges[edge];
        const Event& p0 = world.events[2 * e.lo + cap];
        const Event& p1 = world.events[2 * e.hi + cap];
        const double s = cutSegment(view, p0, p1);
        slot = crossingAt(
            s, side[e.lo], side[e.hi], [&](int end) { return vertexPoint(end == 0 ? e.lo : e.hi); },
            [&] { return world.mesh.positions[e.lo] * (1 - s) + world.mesh.positions[e.hi] * s; });
    }
    return slot;
}

double FrameBuilder::hiddenCrossingRatio(const Event* e, const double* h, int n, double limit) const {
    double hmax = -INFINITY, L = 0, dmin = INFINITY, tmax = -INFINITY;
    for (int i = 0; i < n; ++i) {
        if (!(h[i] < 0)) return 0;  // a corner on the inside: no hidden crossing to fear
        hmax = std::max(hmax, h[i]);
        tmax = std::max(tmax, view.t_c - e[i].t);
        dmin = std::min(dmin, norm(e[i].x - view.apex));
        for (int j = i + 1; j < n; ++j) L = std::max(L, norm(e[i].x - e[j].x));
    }
    if (view.kind != ViewKind::PastCone) return 0;  // h is affine on a hyperplane
    const double d = dmin - L;
    if (!(d > 0)) {
        // The camera among the events.
        return tmax <= limit ? 0 : INFINITY;
    }
    const double excess = L * L / ((n == 2 ? 8.0 : 6.0) * d);
    const double narrow = limit * limit / (2 * dmin);
    if (hmax + excess <= narrow) return 0;
    // Twice the ratio that would just pass, so a refined piece clears the bound with margin.
    return 2 * excess / std::max(-hmax, narrow);
}

double FrameBuilder::clipRatio(const uint32_t v[3], const double* la, const double* lb, const double* lc, double limit) const {
    if (view.kind != ViewKind::PastCone) return 0;  // hyperplane: straight clip lines, exact crossings
    const double* l[3] = {la, lb, lc};
    double ratio = 0;
    for (int cap = 0; cap < 2; ++cap) {
        if (!capReal(cap)) continue;
        Event e[3];
        double h[3];
        for (int i = 0; i < 3; ++i) {
            e[i] = capAt(v, l[i], cap);
            h[i] = viewSide(view, e[i]);
        }
        ratio = std::max(ratio, hiddenCrossingRatio(e, h, 3, limit));
        // The curve's crossings of the sides; a side with both ends outside may hide two.
        double cross[2][3];
        int found = 0;
        for (int i = 0; i < 3; ++i) {
            const int j = (i + 1) % 3;
            if ((h[i] < 0) == (h[j] < 0)) {
                const Event se[2] = {e[i], e[j]};
                const double sh[2] = {h[i], h[j]};
                ratio = std::max(ratio, hiddenCrossingRatio(se, sh, 2, limit));
                continue;
            }
            if (found == 2) continue;
            const double t = cutSegment(view, e[i], e[j]);
            for (int k = 0; k < 3; ++k) cross[found][k] = l[i][k] * (1 - t) + l[j][k] * t;
            ++found;
        }
        if (found != 2) continue;
        if (cross[0][1] == cross[1][1] && cross[0][2] == cross[1][2]) continue;  // through a corner: no chord
        double mid[3], across[3];
        for (int k = 0; k < 3; ++k) mid[k] = 0.5 * (cross[0][k] + cross[1][k]);
        // Across the chord in the (u, v) = (l1, l2) parameter plane, as long as the chord.
        const double du = cross[1][1] - cross[0][1], dv = cross[1][2] - cross[0][2];
        across[1] = -dv;
        across[2] = du;
        across[0] = -(across[1] + across[2]);
        double p0[3], p1[3];
        for (int k = 0; k < 3; ++k) {
            p0[k] = mid[k] - across[k];
            p1[k] = mid[k] + across[k];
        }
        const Event q0 = capAt(v, p0, cap), q1 = capAt(v, p1, cap);
        if ((viewSide(view, q0) < 0) == (viewSide(view, q1) < 0)) {
            ratio = std::max(ratio, 4.0);  // the curve bends away by more than the chord: halve it
            continue;
        }
        const double t = cutSegment(view, q0, q1);
        double on[3];
        for (int k = 0; k < 3; ++k) on[k] = p0[k] * (1 - t) + p1[k] * t;
        const Vec3 chord_mid = (surfaceAt(v, cross[0]).x + surfaceAt(v, cross[1]).x) * 0.5;
        const double dev = norm(surfaceAt(v, on).x - chord_mid);
        if (!(dev == dev)) return INFINITY;
        ratio = std::max(ratio, dev / limit);
    }
    return ratio;
}

void FrameBuilder::clipWhole(size_t f) {
    const auto& tri = world.mesh.triangles[f];
    const Side s[3] = {side[tri[0]], side[tri[1]], side[tri[2]]};
    uint32_t polygon[6];
    const int n = clipToSpan(3, s, [&](int i) { return vertexPoint(tri[size_t(i)]); },
                             [&](int i, int, int cap) { return crossingPoint(world.triangle_edges[f][size_t(i)], cap); },
                             polygon);
    // Fan over the clipped polygon, convex in the triangle's parameter domain.
    for (int k = 1; k + 1 < n; ++k) addOutput(f, {polygon[0], polygon[k], polygon[k + 1]});
}

void FrameBuilder::addTriangle(size_t f) {
    const auto& tri = world.mesh.triangles[f];
    const Side s0 = side[tri[0]], s1 = side[tri[1]], s2 = side[tri[2]];
    if (rest_clip) {
        restPlan(f);
        return;
    }
    const bool inside = s0 == Side::Inside && s1 == Side::Inside && s2 == Side::Inside;
    if (!inside && s0 == s1 && s1 == s2) return;  // wholly before or after existence
    if (!inside) ++out.clipped_triangles;
    if (inside) addOutput(f, {vertexPoint(tri[0]), vertexPoint(tri[1]), vertexPoint(tri[2])});
    else clipWhole(f);
}

}  // namespace slicing

namespace {

using namespace slicing;

// The 4D-box cull of one run of triangles (SliceSettings::cull).
bool chunkMayShow(const World4D& world, const ViewSurface& view, const TriangleChunk& c) {
    const bool cone = view.kind == ViewKind::PastCone;
    auto distances = [&](const EventBox& b, double* nearest, double* farthest) {
        double in[3], out[3];
        for (int k = 0; k < 3; ++k) {
            const double p = view.apex[k], lo = b.lo[k], hi = b.hi[k];
            in[k] = p < lo ? lo - p : (p > hi ? p - hi : 0.0);
            out[k] = std::max(std::fabs(p - lo), std::fabs(p - hi));
        }
        *nearest = norm(Vec3{in[0], in[1], in[2]});
        *farthest = norm(Vec3{out[0], out[1], out[2]});
    };
    auto margin = [&](const EventBox& b) {
        const double scale = std::fabs(view.t_c) + std::max(std::fabs(b.t_lo), std::fabs(b.t_hi)) + norm(view.apex) +
                             std::max(norm(b.lo), norm(b.hi));
        return 1e-12 * scale;
    };
    // On a tilted hyperplane the least and greatest (x - C).k over the box take the distances' place.
    auto along = [&](const EventBox& b, double* nearest, double* farthest) {
        double lo = 0, hi = 0;
        for (int k = 0; k < 3; ++k) {
            const double a0 = (b.lo[k] - view.apex[k]) * view.tilt[k], a1 = (b.hi[k] - view.apex[k]) * view.tilt[k];
            lo += std::min(a0, a1);
            hi += std::max(a0, a1);
        }
        *nearest = lo;
        *farthest = hi;
    };
    const bool tilted = view.kind == ViewKind::Hyperplane && view.tilted();
    if (world.cap_a_real) {
        const EventBox& a = c.cap[0];
        double nearest = 0, farthest = 0;
        if (cone) distances(a, &nearest, &farthest);
        if (tilted) along(a, &nearest, &farthest);
        if ((view.t_c - a.t_lo) - nearest < -margin(a)) return false;  // none has begun existing
    }
    if (world.cap_b_real) {
        const EventBox& b = c.cap[1];
        double nearest = 0, farthest = 0;
        if (cone) distances(b, &nearest, &farthest);
        if (tilted) along(b, &nearest, &farthest);
        if ((view.t_c - b.t_hi) - farthest > margin(b)) return false;  // all have ended existing
    }
    return true;
}

}  // namespace

namespace {

// The cut in the view's own frame (sliceWorld before the shear).
ApparentMesh sliceUnsheared(const World4D& world, const ViewSurface& view, const SliceSettings& requested) {
    // Model only what the cut requires.
    SliceSettings settings = requested;
    const bool at_rest = world.motion.beta == 0 && !view.sheared() && !(settings.displacement > 0);
    // At rest on the past cone with a real cap, the caps' clip curves are circles.
    const bool uniform = isUniform(world.motion);
    // A motion that is not uniform, with a tolerance.
    if (!uniform && settings.tolerance > 0 && !world.cap_a_real && !world.cap_b_real && !(settings.displacement >= 0) &&
        !world.empty())
        return refineWorldlines(world, view, settings);
    const bool rest_clip = uniform && view.kind == ViewKind::PastCone && at_rest && settings.tolerance > 0 &&
                           (world.cap_a_real || world.cap_b_real);
    if (view.kind == ViewKind::Hyperplane || at_rest || !uniform) settings.tolerance = 0;
    FrameBuilder b(world, view, settings);
    b.rest_clip = rest_clip;
    b.rest_tolerance = requested.tolerance;
    if (world.empty()) return std::move(b.out);
    // Step: the fast path of vertex mode when nothing is clipped.
    if (settings.tolerance == 0 && !world.cap_a_real && !world.cap_b_real && world.simple) {
        const size_t nv = world.mesh.positions.size(), nt = world.mesh.triangles.size();
        ApparentMesh& out = b.out;
        out.positions.resize(nv);
        out.emission_times.resize(nv);
        cutRestLocalBatch(b.anchor, world.motion, world.mesh.positions.data(), nv, out.positions.data(),
                          out.emission_times.data());
        out.rest_points = world.mesh.positions;
        out.triangles = world.mesh.triangles;
        out.source_triangles.resize(nt);
        for (size_t f = 0; f < nt; ++f) out.source_triangles[f] = uint32_t(f);
        return std::move(b.out);
    }
    // Step: the cull. Only real caps hide anything; without them every worldline meets the view.
    std::vector<uint8_t> live;
    const bool culling = settings.cull && (world.cap_a_real || world.cap_b_real) && !world.chunks.empty();
    if (culling) {
        live.resize(world.chunks.size());
        bool any = false;
        for (size_t c = 0; c < world.chunks.size(); ++c) {
            live[c] = chunkMayShow(world, view, world.chunks[c]);
            any |= live[c] != 0;
            if (!live[c]) b.out.culled_triangles += world.chunks[c].last - world.chunks[c].first;
        }
        if (!any) return std::move(b.out);
    }
    if (settings.tolerance > 0) {  // moving, on the past cone
        b.refineFrame(culling ? &live : nullptr);
        return std::move(b.out);
    }
    b.out.positions.reserve(world.mesh.positions.size());
    b.out.emission_times.reserve(world.mesh.positions.size());
    b.out.rest_points.reserve(world.mesh.positions.size());
    b.out.triangles.reserve(world.mesh.triangles.size());
    b.out.source_triangles.reserve(world.mesh.triangles.size());
    b.classifyVertices(culling ? &live : nullptr);
    b.crossing_out.assign(2 * world.edges.size(), kUnset);
    if (culling) {
        for (size_t c = 0; c < world.chunks.size(); ++c)
            if (live[c])
                for (uint32_t f = world.chunks[c].first; f < world.chunks[c].last; ++f) b.addTriangle(f);
    } else {
        for (size_t f = 0; f < world.mesh.triangles.size(); ++f) b.addTriangle(f);
    }
    for (const auto& plan : b.rest_plans) b.restEmit(plan);
    return std::move(b.out);
}

// The output origin under the view's shear: (t, x) -> (t, x - shear t) at the anchor's origin.
Vec3 shearedOrigin(const ViewSurface& view, const ViewAnchor& anchor) {
    return anchor.origin - view.shear * anchor.time_origin;
}

}  // namespace

ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view, const SliceSettings& given) {
    // Step: an attribute tolerance below the distance's bounds the parametric error everywhere.
    SliceSettings settings = given;
    if (settings.tolerance > 0 && settings.attribute_tolerance < settings.tolerance)
        settings.tolerance = settings.attribute_tolerance;
    ApparentMesh out = sliceUnsheared(world, view, settings);
    if (!view.sheared()) return out;
    // Step: the Galilean map into the output frame, origin and local parts apart.
    out.origin = out.origin - view.shear * out.time_origin;
    for (size_t i = 0; i < out.positions.size(); ++i) out.positions[i] -= view.shear * out.emission_times[i];
    return out;
}

Event exactApparentPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    const ViewAnchor anchor = viewAnchor(view, world.motion);
    const Event local = cutRestLocal(anchor, world.motion, q);
    return {anchor.time_origin + local.t, shearedOrigin(view, anchor) + (local.x - view.shear * local.t)};
}

BoundingSphere apparentBound(const World4D& world, const ViewSurface& view) {
    const ViewAnchor anchor = viewAnchor(view, world.motion);
    if (!isUniform(world.motion)) return {anchor.origin, INFINITY};  // no bound derived: never culled
    const double b = world.motion.beta;
    double stretch = view.kind == ViewKind::PastCone ? (1 + b) / world.motion.one_minus_beta2 : 1.0;
    // A tilted hyperplane: local points s - v delta with |delta| = |s.k| / (1 + v.k) <= R / (1 - b).
    if (view.kind == ViewKind::Hyperplane && view.tilted()) stretch = 1 / (1 - b);
    // Sheared, local points are s - w delta, w = u - shear, with |s| <= R and |delta| <= R / (1 - b).
    if (view.sheared() && view.kind == ViewKind::PastCone)
        stretch = 1 + norm(world.motion.velocity - view.shear) * (1 + b) / world.motion.one_minus_beta2;
    // A relative 1e-9 more for the rounding of the points themselves.
    return {shearedOrigin(view, anchor), world.shape_radius * stretch * (1 + 1e-9)};
}

Event exactLocalPoint(const World4D& world, const ViewSurface& view, const Vec3& q) {
    const Event local = cutRestLocal(viewAnchor(view, world.motion), world.motion, q);
    return {local.t, local.x - view.shear * local.t};
}

}  // namespace mesh4d
