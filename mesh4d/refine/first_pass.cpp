// refineFrame: the first pass over the mesh, the drain, the batch cut and the leaves' assembly.
#include "mesh4d/refine/bisect.h"
#include "mesh4d/refine/templates.h"

namespace mesh4d {
namespace slicing {

uint32_t FrameBuilder::outId(uint32_t id) {
    if (vertex_out[id] == kUnset) vertex_out[id] = emit(eventOfId(id), restOfId(id));
    return vertex_out[id];
}

uint32_t FrameBuilder::leafCrossing(uint32_t a, uint32_t b, int cap) {
    const uint32_t lo = std::min(a, b), hi = std::max(a, b);
    auto [it, inserted] = r_crossings[cap].try_emplace((uint64_t(lo) << 32) | hi, kUnset);
    if (!inserted) return it->second;
    const double s = cutSegment(view, capOfId(lo, cap), capOfId(hi, cap));
    const uint32_t id = crossingAt(
        s, side[lo], side[hi], [&](int end) { return outId(end == 0 ? lo : hi); },
        [&] { return restOfId(lo) * (1 - s) + restOfId(hi) * s; });
    return it->second = id;
}

void FrameBuilder::emitLeaf(uint32_t src, const uint32_t v[3]) {
    const Side s[3] = {side[v[0]], side[v[1]], side[v[2]]};
    if (s[0] == Side::Inside && s[1] == Side::Inside && s[2] == Side::Inside) {
        addOutput(src, {outId(v[0]), outId(v[1]), outId(v[2])});
        return;
    }
    uint32_t polygon[6];
    const int n = clipToSpan(3, s, [&](int i) { return outId(v[i]); },
                             [&](int i, int j, int cap) { return leafCrossing(v[i], v[j], cap); }, polygon);
    for (int k = 1; k + 1 < n; ++k) addOutput(src, {polygon[0], polygon[k], polygon[k + 1]});
}

void FrameBuilder::refineFrame(const std::vector<uint8_t>* live) {
    rt = r_tri.get();
    r_nv = uint32_t(world.mesh.positions.size());
    r_nt = uint32_t(world.mesh.triangles.size());
    const size_t ne = world.edges.size();
    r_ne = uint32_t(ne);
    int levels = 1;
    while (levels < 30 && (int64_t(1) << levels) < int64_t(std::max(settings.max_segments, 2))) ++levels;
    r_max_depth = uint32_t(2 * levels);  // about max_segments pieces along each direction of a triangle
    auto isLive = [&](size_t f) { return !live || (*live)[f / kChunkTriangles]; };

    // Step: images of every vertex.
    r_pos.resize(r_nv);
    r_time.resize(r_nv);
    cutRestLocalBatch(anchor, world.motion, world.mesh.positions.data(), r_nv, r_pos.data(), r_time.data());
    const bool caps = world.cap_a_real || world.cap_b_real;
    r_caps = caps;
    r_templates = !caps;
    scratch.forms.clear();
    scratch.form_aniso.clear();
    scratch.form_of.clear();
    scratch.coarse.clear();
    if (caps) classifyVertices(live);  // else every side is Inside (classified below, if anything is refined)

    // Step: the corners' bound (chordErrorFromCorners) passes most triangles that need no refinement.
    std::vector<uint32_t>& candidates = scratch.candidates;
    std::vector<uint32_t>& failing = scratch.failing;
    candidates.clear();
    failing.clear();
    double expected_pieces = 0;
    r_now = nowBase(view, world.motion);
    r_terms.resize(r_nv);  // the bound's terms, once per vertex
    for (size_t i = 0; i < r_nv; ++i) {
        const Event e{r_time[i], r_pos[i]};
        r_terms[i].s = shapeOfEvent(world.motion, e);
        r_terms[i].xm = normMOfEvent(anchor, world.motion, e);
    }
    // (The corners' bounds have the factor |u|: a displaced bound takes the full one.)
    const bool displaced = view.sheared() || settings.displacement >= 0;
    // Faces containing v are judged on their rim (slide_bound.h), unless their parametric error is bounded too.
    r_slide = !caps && !displaced && world.motion.beta > 0 && settings.attribute_tolerance > settings.tolerance;
    // The corners' spread (chord_error.h cornerSpread).
    std::vector<double>& spread = scratch.spread;
    const bool edge_spread = !displaced && !live;
    // Every triangle passes when the whole mesh does.
    bool whole_passes = false;
    if (edge_spread) {
        // The least |x|_M of all vertices, and their sum.
        double xm_least = INFINITY, xm_sum = 0;
        for (size_t i = 0; i < r_nv; ++i) {
            const double xm = r_terms[i].xm;
            xm_least = std::min(xm_least, xm);
            xm_sum += xm;
        }
        spread.resize(ne);
        const Vec3 v = world.motion.velocity;
        const double k = world.motion.one_minus_beta2;
        double d2_most = 0;
        for (size_t e = 0; e < ne; ++e) {
            const Vec3 u = r_terms[world.edges[e].hi].s - r_terms[world.edges[e].lo].s;
            const double uv = dot(u, v);
            const double d2 = uv * uv + k * norm2(u);
            spread[e] = d2;
            d2_most = std::max(d2_most, d2);
        }
        const double xm_all[3] = {xm_least, xm_least, xm_least};
        whole_passes = !caps && xm_sum == xm_sum && passesFromSpread(d2_most, xm_all, world.motion, settings.tolerance);
    }
    // (The arrays and the tolerance read through locals).
    const std::array<uint32_t, 3>* const tris = world.mesh.triangles.data();
    const std::array<uint32_t, 3>* const tri_edges = world.triangle_edges.data();
    const VTerms* const corner_terms = r_terms.data();
    const double* const spreads = spread.data();
    const double tolerance = settings.tolerance;
    for (size_t f = whole_passes ? r_nt : 0; f < r_nt; ++f) {
        if (!isLive(f)) continue;
        const auto& t = tris[f];
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) continue;  // no area: dropped at output, never split
        if (caps) {
            const Side s0 = side[t[0]];
            if (s0 != Side::Inside && side[t[1]] == s0 && side[t[2]] == s0) continue;  // wholly before or after
            if (s0 != Side::Inside || side[t[1]] != Side::Inside || side[t[2]] != Side::Inside) ++out.clipped_triangles;
        }
        // The terms are the corners' own (shapeOfEvent, normMOfEvent).
        if (!displaced) {
            const double xc[3] = {corner_terms[t[0]].xm, corner_terms[t[1]].xm, corner_terms[t[2]].xm};
            double d2;
            if (edge_spread) {
                const auto& te = tri_edges[f];
                d2 = std::max(std::max(std::max(0.0, spreads[te[0]]), spreads[te[1]]), spreads[te[2]]);
            } else {
                const Vec3 sc[3] = {r_terms[t[0]].s, r_terms[t[1]].s, r_terms[t[2]].s};
                d2 = cornerSpread(sc, world.motion);
            }
            if (passesFromSpread(d2, xc, world.motion, tolerance)) continue;
            if (!(chordErrorFromSpread(d2, xc, world.motion) > tolerance)) continue;
        }
        candidates.push_back(uint32_t(f));
    }
    // Each mesh edge's bound made once and kept for the splits (edgeOf makes the same bits).
    const bool keep_edges = !candidates.empty() && 4 * candidates.size() >= ne;
    if (keep_edges) r_edges.assign(ne, REdge{kUnset, kUnset, NAN, NAN, NAN});
    REdge* const kept = keep_edges ? r_edges.data() : nullptr;
    const VTerms* const terms = r_terms.data();
    for (uint32_t f : candidates) {
        const auto& te = world.triangle_edges[f];
        double c[3], len[3], xm_mid[3];
        for (int k = 0; k < 3; ++k) {
            const uint32_t e = te[k];
            if (kept) {
                REdge& re = kept[e];
                if (re.len != re.len) {
                    const Edge& ed = world.edges[e];
                    storeEdge(re, edgeBubble(world.motion, r_now, terms[ed.lo], terms[ed.hi]));
                }
                c[k] = re.c;
                len[k] = re.len;
                xm_mid[k] = re.xm_mid;
            } else {
                const Edge& ed = world.edges[e];
                const EdgeBubble eb = edgeBubble(world.motion, r_now, terms[ed.lo], terms[ed.hi]);
                c[k] = eb.c;
                len[k] = eb.length;
                xm_mid[k] = eb.xm_mid;
            }
        }
        // The corners' terms in place (the drain's pointsBound on the same record).
        const auto& t = world.mesh.triangles[f];
        const VTerms &k0 = terms[t[0]], &k1 = terms[t[1]], &k2 = terms[t[2]];
        ChordError ce;
        if (edge_spread) {
            auto sides = [&](double side2[3]) {
                for (int k = 0; k < 3; ++k) side2[k] = spreads[te[k]];
                return std::min(std::min(k0.xm, k1.xm), k2.xm);
            };
            ce = chordErrorOfSides(world.motion, bound_speed, c, sides, settings.tolerance);
        } else {
            ce = pointsBound(c, k0, k1, k2);
        }
        const double bound = ce.bound;
        if (bound > settings.tolerance && !(r_slide && bound <= settings.attribute_tolerance && slides(f) && rimPasses(f, t.data(), te.data(), c, len, xm_mid)) &&
            !(ce.quadratic <= settings.tolerance && passesByForm(k0.s, k1.s, k2.s))) {
            // (Room for every mesh triangle's, made when the first one fails: set for the failing only.)
            if (failing.empty() && scratch.quadratic.size() < r_nt) scratch.quadratic.resize(r_nt);
            failing.push_back(f);
            scratch.quadratic[f] = ce.quadratic;
            // About bound / T pieces once halved down to T (the error falls about as the area).
            expected_pieces += std::min(bound / settings.tolerance, 1e6);
        }
    }
    // Nothing to refine on a simple mesh that exists throughout: vertex mode's output.
    if (failing.empty() && !caps && world.simple) {
        out.positions = std::move(r_pos);
        out.emission_times = std::move(r_time);
        out.rest_points = world.mesh.positions;
        out.triangles = world.mesh.triangles;
        out.source_triangles.resize(r_nt);
        for (size_t f = 0; f < r_nt; ++f) out.source_triangles[f] = uint32_t(f);
        return;
    }
    // Room for the pieces and points the refinement is expected to make (growth would copy them).
    size_t expect = size_t(std::min(2 * expected_pieces, 1e6));
    if (settings.max_triangles > 0) expect = std::min(expect, settings.max_triangles);

    // Step: split until every piece passes.
    if (!failing.empty()) {
        if (!keep_edges) r_edges.assign(ne, REdge{kUnset, kUnset, NAN, NAN, NAN});
        reserveTris(r_nt + expect);  // records made on first touch (ensureBase)
        r_tri_size = r_nt;
        r_edges.reserve(ne + 2 * expect);
        for (auto* v : {&r_pos, &r_rest}) v->reserve(v->size() + expect);
        r_terms.reserve(r_terms.size() + expect);
        r_time.reserve(r_time.size() + expect);
        if (caps) {  // the clipped leaves emit their points and triangles one by one (emitLeaf)
            out.positions.reserve(out.positions.size() + expect);
            out.emission_times.reserve(out.emission_times.size() + expect);
            out.rest_points.reserve(out.rest_points.size() + expect);
            out.triangles.reserve(out.triangles.size() + expect);
            out.source_triangles.reserve(out.source_triangles.size() + expect);
        }
        r_init.assign(r_nt, 0);
        r_init_data = r_init.data();
        r_edge_data = r_edges.data();
        r_term_data = r_terms.data();
        r_limited.assign(r_nt, 0);
        r_leaves = r_nt;
        std::vector<uint32_t>& stack = scratch.stack;
        for (uint32_t f : failing) {
            ensureBase(f);
            // Still as the mesh has it (only a split changes a record's corners, and it deepens it).
            if (rt[f].depth == 0 && rt[f].state == kUnknown) rt[f].state = kBoundFailed;
            stack.push_back(f);
            drain(stack);
        }
        // Step: templates only where they make most of the output.
        if (r_templates && !scratch.forms.empty() && !out.over_budget) {
            const uint32_t cap = uint32_t(std::max(settings.max_segments, 2));
            double templated = 0;
            auto share = [&](uint32_t id) {
                if (rt[id].state == kCoarse) templated += fillEstimate(scratch.form_of[id], cap);
            };
            // The records still coarse, in id order (as a pass over all records would meet them).
            std::vector<uint32_t>& coarse = scratch.coarse;
            std::sort(coarse.begin(), coarse.end());
            coarse.erase(std::unique(coarse.begin(), coarse.end()), coarse.end());
            for (uint32_t id : coarse) share(id);
            if (templated < kTemplateShare * double(r_leaves)) {
                r_templates = false;
                for (uint32_t id : coarse) {
                    if (rt[id].state != kCoarse) continue;
                    rt[id].state = kUnknown;
                    stack.push_back(id);
                }
                drain(stack);
                scratch.forms.clear();
                scratch.form_aniso.clear();
            }
        }
    }
    // Step (no real cap): the output's points, once the splits are done.
    const bool filling = r_templates && !failing.empty() && !out.over_budget && !scratch.forms.empty();
    if (!caps) {
        const size_t points = r_nv + (filling ? std::max(r_rest.size(), expect) : r_rest.size());
        out.positions.reserve(points);
        out.emission_times.reserve(points);
        out.rest_points.reserve(points);
        classifyVertices(live);
    }
    // Step (no real cap): the leaves filled by their templates.
    const bool templated = filling && templateLeaves();
    if (!failing.empty()) {
        for (uint8_t l : r_limited) out.limited_triangles += l;
        // Step: the exact images of the new points (splits' and templates'), in one batch.
        const size_t n_new = r_rest.size();
        r_pos.resize(r_nv + n_new);
        r_time.resize(r_nv + n_new);
        cutRestLocalBatch(anchor, world.motion, r_rest.data(), n_new, r_pos.data() + r_nv, r_time.data() + r_nv);
    }

    // Step: the leaves in record order.
    if (!caps) {
        // Nothing clipped: every point a split made is a corner of some leaf.
        const size_t base = out.positions.size(), n_new = r_rest.size();
        out.positions.insert(out.positions.end(), r_pos.begin() + r_nv, r_pos.begin() + r_nv + n_new);
        out.emission_times.insert(out.emission_times.end(), r_time.begin() + r_nv, r_time.begin() + r_nv + n_new);
        out.rest_points.insert(out.rest_points.end(), r_rest.begin(), r_rest.begin() + n_new);
        if (templated) return;  // the triangles are made
        vertex_out.resize(r_nv + n_new);
        for (size_t k = 0; k < n_new; ++k) vertex_out[r_nv + k] = uint32_t(base + k);
        const size_t n_out = r_nt + (r_tri_size > r_nt ? r_tri_size - r_nt : 0);
        out.triangles.reserve(out.triangles.size() + n_out);
        out.source_triangles.reserve(out.source_triangles.size() + n_out);
        auto leaf = [&](uint32_t src, const uint32_t* v) {
            addOutput(src, {vertex_out[v[0]], vertex_out[v[1]], vertex_out[v[2]]});
        };
        for (size_t f = 0; f < r_nt; ++f) {
            const uint32_t* v = (r_init.empty() || !r_init[f]) ? world.mesh.triangles[f].data() : rt[f].v;
            leaf(uint32_t(f), v);
        }
        for (size_t id = r_nt; id < r_tri_size; ++id) leaf(rt[id].src, rt[id].v);
        return;
    }
    for (size_t f = 0; f < r_nt; ++f) {
        if (!isLive(f)) continue;
        if (r_init.empty() || !r_init[f]) {
            const auto& t = world.mesh.triangles[f];
            const uint32_t v[3] = {t[0], t[1], t[2]};
            emitLeaf(uint32_t(f), v);
        } else {
            emitLeaf(uint32_t(f), rt[f].v);
        }
    }
    for (size_t id = r_nt; id < r_tri_size; ++id)
        if (isLive(rt[id].src)) emitLeaf(rt[id].src, rt[id].v);
}

}  // namespace slicing
}  // namespace mesh4d
