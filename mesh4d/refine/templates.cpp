// The templates: pieces the bisection leaves, each filled at once by a grid or a form bisection.
#include "mesh4d/refine/bisect.h"
#include "mesh4d/refine/templates.h"

namespace mesh4d {
namespace slicing {

bool FrameBuilder::passesByForm(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const Vec3 s[3] = {a, b, c};
#if defined(APPARENT_NO_LANES)
    return pieceFormWithin(world.motion, r_now, s, bound_speed, settings.tolerance);
#else
    return pieceFormWithinLanes(world.motion, r_now, s, bound_speed, settings.tolerance);
#endif
}

bool FrameBuilder::forcedTemplatePays(uint32_t id) {
    const uint32_t* v = rt[id].v;
    const double c[3] = {edgeOf(id, 0).c, edgeOf(id, 1).c, edgeOf(id, 2).c};
    const ChordError ce = pointsBound(c, r_term_data[v[0]], r_term_data[v[1]], r_term_data[v[2]]);
    const double expected = std::max(1.0, ce.quadratic / settings.tolerance);
    return fillEstimate(scratch.form_of[id], kNoCap) <= kForceRatio * expected;
}

bool FrameBuilder::coarseForm(uint32_t id, const Vec3 s[3], bool force) {
    std::vector<uint32_t>& form_of = scratch.form_of;
    if (form_of.size() <= id) form_of.resize(std::max<size_t>(r_tri_size, size_t(id) + 1), kUnset);
    form_of[id] = kUnset;
#if defined(APPARENT_NO_LANES)
    const PieceForm pf = pieceForm(world.motion, r_now, s);
#else
    const PieceForm pf = pieceFormLanes(world.motion, r_now, s);
#endif
    if (!pf.finite) return false;
    const double whole = bubbleMax(pf.c[0], pf.c[1], pf.c[2]);
    const double need = bound_speed * whole / settings.tolerance;
    // Its shape in the form's metric.
    const double cuv = 0.5 * (pf.c[0] + pf.c[2] - pf.c[1]);
    const double area = std::sqrt(std::max(0.0, pf.c[0] * pf.c[2] - cuv * cuv));
    const bool shaped = area >= kShapeShare * kEquilateral * whole;
    // Step: a stretched piece of need at most kAnisoMaxNeed: the form bisection (form_bisect.h).
    const double xa = std::ceil(std::sqrt(need));
    const bool aniso = !shaped && need <= kAnisoMaxNeed;
    if (!force) {
        const double centre = bubbleMax(pf.centre[0], pf.centre[1], pf.centre[2]);
        {  // the fill's triangles against the halves' (above)
            const double xc2 = bound_speed * centre / settings.tolerance;
            const double infl = whole / centre;
            const double cost_t = aniso ? kAnisoCost * need : xa * xa;
            double cost_b;
            if (infl <= kNearlyUniform && rt[id].depth == 0) {
                cost_b = halvesEstimate(pf, bound_speed / settings.tolerance, infl);
            } else {
                cost_b = 2 * halfCost(0.5 * xc2 * halfGrowth(infl));
            }
            if (!(cost_t <= cost_b) && !(whole <= kCoarseSlack * centre)) return false;
        }
        if (!aniso && !shaped) return false;
        if (!(need >= kMinLevel * kMinLevel)) return false;
    }
    form_of[id] = uint32_t(scratch.forms.size());
    scratch.forms.push_back(pf);
    scratch.form_aniso.push_back(aniso ? 1 : 0);
    return true;
}

double FrameBuilder::halvesEstimate(const PieceForm& pf, double per, double infl) {
    const double* q = pf.centre;
    int k = 0;  // the longest side (k -> k + 1)
    if (q[1] > q[k]) k = 1;
    if (q[2] > q[k]) k = 2;
    const double qc = q[k], qa = q[kSucc[k]], qb = q[kSucc[kSucc[k]]];  // sides k + 1, k + 2
    const double med = std::max(0.0, 0.25 * (2 * qa + 2 * qb - qc));
    const double grow = halfGrowth(infl);
    double cost = 0;
    for (const double other : {qb, qa}) cost += halfCost(per * bubbleMax(0.25 * qc, med, other) * grow);
    return cost;
}

double FrameBuilder::halfCost(double child) {
    return std::max(1.0, (std::sqrt(child) + kRounding) * (std::sqrt(child) + kRounding));
}

double FrameBuilder::fillEstimate(uint32_t f, uint32_t cap) const {
    const PieceForm& pf = scratch.forms[f];
    if (scratch.form_aniso[f]) return std::max(1.0, kAnisoCost * bound_speed * bubbleMax(pf.c[0], pf.c[1], pf.c[2]) / settings.tolerance);
    const double n = formLevel(pf, cap);
    return n * n;
}

uint32_t FrameBuilder::formLevel(const PieceForm& pf, uint32_t cap) const {
    const double need = bound_speed * bubbleMax(pf.c[0], pf.c[1], pf.c[2]) / settings.tolerance;
    if (!(need <= double(cap) * double(cap))) return r_level_scale < 1 ? std::max(1u, uint32_t(cap * r_level_scale)) : cap;
    uint32_t n = std::max(1u, uint32_t(std::ceil(std::sqrt(need))));
    while (double(n) * double(n) < need) ++n;
    if (r_level_scale < 1) n = std::max(1u, uint32_t(double(n) * r_level_scale));
    return std::min(n, cap);
}

uint32_t FrameBuilder::edgePoints(uint32_t e, uint32_t a, uint32_t b, uint32_t count) {
    uint32_t& first = scratch.edge_first[e];
    if (first != kUnset) return first;
    first = uint32_t(r_nv + r_rest.size());
    const Vec3 lo = restOfId(std::min(a, b)), hi = restOfId(std::max(a, b));
    for (uint32_t i = 1; i < count; ++i) {
        const double t = double(i) / double(count);
        r_rest.push_back(lo * (1 - t) + hi * t);
    }
    return first;
}

void FrameBuilder::fillLeaf(uint32_t src, const uint32_t v[3], const uint32_t e[3], uint32_t N, const PieceForm* form,
              bool unsplit, size_t base, uint32_t cap, bool aniso) {
    auto outOf = [&](uint32_t g) { return g < r_nv ? vertex_out[g] : uint32_t(base + (g - r_nv)); };
    const uint32_t* count = scratch.edge_count.data();  // segments - 1
    const int n[3] = {int(count[e[0]]) + 1, int(count[e[1]]) + 1, int(count[e[2]]) + 1};
    if (N == 1 && n[0] == 1 && n[1] == 1 && n[2] == 1) {
        addOutput(src, {outOf(v[0]), outOf(v[1]), outOf(v[2])});
        return;
    }
    TessForm tf;
    if (form) {
        tf.cu = form->c[0];
        tf.cv = form->c[2];
        tf.cuv = 0.5 * (form->c[0] + form->c[2] - form->c[1]);
        tf.limit = settings.tolerance / bound_speed;
    }
    std::vector<std::array<uint32_t, 3>>& local = scratch.local;
    // A fill's local points 0..2 are the corners, then each side's n[k] - 1 shared points.
    auto mapCornersAndSides = [&](std::vector<uint32_t>& map, auto side_first) {
        for (int k = 0; k < 3; ++k) map[size_t(k)] = v[k];
        for (int k = 0; k < 3; ++k) {
            if (n[k] == 1) continue;
            const uint32_t a = v[k], b = v[kSucc[k]];
            const uint32_t first = edgePoints(e[k], a, b, uint32_t(n[k]));
            for (int i = 1; i < n[k]; ++i)
                map[side_first(k) + uint32_t(i - 1)] = first + uint32_t(a < b ? i - 1 : n[k] - i - 1);
        }
    };
    // A piece stretched in its form's metric.
    if (aniso && form) {
        FormBisection& fb = scratch.bisection;
        if (fb.fill(tf, n, size_t(cap) * size_t(cap), local)) {
            std::vector<uint32_t>& map = scratch.local_map;
            map.resize(fb.innerFirst() + fb.params().size());
            mapCornersAndSides(map, [&](int k) { return fb.sideFirst(k); });
            const Vec3 p0 = restOfId(v[0]), p1 = restOfId(v[1]), p2 = restOfId(v[2]);
            uint32_t id = uint32_t(r_nv + r_rest.size());
            for (size_t j = 0; j < fb.params().size(); ++j) {
                const double l1 = fb.params()[j][0], l2 = fb.params()[j][1];
                r_rest.push_back(p0 * (1 - l1 - l2) + p1 * l1 + p2 * l2);
                map[fb.innerFirst() + j] = id++;
            }
            for (uint32_t& g : map) g = outOf(g);  // each point's output id once, not once per triangle on it
            for (const auto& t : local) addOutput(src, {map[t[0]], map[t[1]], map[t[2]]});
            if (unsplit && local.size() > 1) ++out.refined_triangles;
            return;
        }
    }
    int level = int(N);
    for (;;) {
        const TessLayout probe(level, n);
        const bool checked = form && probe.level() > 1;
        if (probe.tessellate(checked ? &tf : nullptr, local)) break;
        if (probe.level() >= int(cap)) {  // the ring cannot be made to pass: limited
            r_limited[src] = 1;
            probe.tessellate(nullptr, local);
            break;
        }
        level = probe.level() + 1;
    }
    const TessLayout lay(level, n);
    // Step: the leaf's points: corners, its sides' shared points, its own inner points.
    std::vector<uint32_t>& map = scratch.local_map;
    map.resize(lay.count());
    mapCornersAndSides(map, [&](int k) { return lay.sideFirst(k); });
    if (lay.innerCount() > 0) {
        const Vec3 p0 = restOfId(v[0]), p1 = restOfId(v[1]), p2 = restOfId(v[2]);
        uint32_t id = uint32_t(r_nv + r_rest.size());
        const int L = lay.level();
        auto add = [&](double l1, double l2) { r_rest.push_back(p0 * (1 - l1 - l2) + p1 * l1 + p2 * l2); };
        if (L == 1) {
            add(1.0 / 3, 1.0 / 3);
        } else {
            for (int j = 1; j + 2 <= L; ++j)
                for (int i = 1; i + j + 1 <= L; ++i) add(double(i) / L, double(j) / L);
        }
        for (uint32_t p = lay.innerFirst(); p < lay.count(); ++p) map[p] = id++;
    }
    for (uint32_t& g : map) g = outOf(g);  // each point's output id once, not once per triangle on it
    for (const auto& t : local) addOutput(src, {map[t[0]], map[t[1]], map[t[2]]});
    if (unsplit && local.size() > 1) ++out.refined_triangles;
}

bool FrameBuilder::templateLeaves() {
    const uint32_t cap = uint32_t(std::max(settings.max_segments, 2));
    std::vector<uint32_t>& count = scratch.edge_count;  // per edge record: its segments - 1
    auto clear = [](std::vector<uint32_t>& v, size_t n, int byte) {
        v.resize(n);
        std::memset(v.data(), byte, n * sizeof(uint32_t));
    };
    std::vector<uint32_t>& form_of = scratch.form_of;
    if (form_of.size() < r_tri_size) form_of.resize(r_tri_size, kUnset);
    // Step: each record's level, and each edge's count (the largest level around it).
    double estimate = 0;
    r_level_scale = 1;
    auto levelPass = [&](uint32_t id) {
        RTri& t = rt[id];
        if (t.state == kFailed) {  // the depth limit stopped it: its template is what it gets
            if (r_slide && slides(t.src)) return;  // a face containing v: no form (slide_bound.h)
            const Vec3 s[3] = {r_terms[t.v[0]].s, r_terms[t.v[1]].s, r_terms[t.v[2]].s};
            coarseForm(id, s, true);
        } else if (t.state != kCoarse) {
            return;
        }
        if (form_of[id] == kUnset) return;
        const PieceForm& pf = scratch.forms[form_of[id]];
        const uint32_t n = formLevel(pf, cap);
        // A form asking for more than max_segments segments gets that many.
        if (n == cap && formLevel(pf, kNoCap) > cap) r_limited[t.src] = 1;
        if (scratch.form_aniso[form_of[id]] && !out.over_budget) {
            // The bisection's sides: each cut so that its segments pass alone (form_bisect.h).
            estimate += fillEstimate(form_of[id], cap);
            const double limit = settings.tolerance / bound_speed;
            for (int c = 0; c < 3; ++c) {
                const uint32_t k = uint32_t(FormBisection::sideSegments(pf.c[c], limit, int(cap))) - 1;
                count[t.edge[c]] = std::max(count[t.edge[c]], k);
            }
            return;
        }
        estimate += double(n) * double(n);
        for (int c = 0; c < 3; ++c) count[t.edge[c]] = std::max(count[t.edge[c]], n - 1);
    };
    auto levels = [&] {
        estimate = 3.0 * double(r_nt) + 3.0 * double(r_tri_size - r_nt);
        clear(count, r_edges.size(), 0);
        for (uint32_t f = 0; f < r_nt; ++f)
            if (r_init[f]) levelPass(f);
        for (uint32_t id = r_nt; id < r_tri_size; ++id) levelPass(id);
        for (uint32_t c : count) estimate += 2.0 * double(c);
    };
    levels();
    for (int round = 0; settings.max_triangles > 0 && estimate > double(settings.max_triangles); ++round) {
        out.over_budget = true;
        const double leaves = 3.0 * double(r_tri_size);
        if (round == 8 || double(settings.max_triangles) <= leaves) return false;
        r_level_scale *= 0.95 * std::sqrt((double(settings.max_triangles) - leaves) / (estimate - leaves));
        levels();
    }
    // Step: the templates, in record order.
    clear(scratch.edge_first, r_edges.size(), 0xff);  // kUnset
    // (The estimate counts 3 per leaf: about 1 is made.)
    const size_t expect = size_t(std::min(std::max(0.0, estimate - 2.0 * double(r_tri_size)), 1e8));
    out.triangles.reserve(out.triangles.size() + expect);
    out.source_triangles.reserve(out.source_triangles.size() + expect);
    r_rest.reserve(r_rest.size() + expect / 2 + 16);
    const size_t base = out.positions.size();
    auto fillRecord = [&](uint32_t id) {
        const RTri& t = rt[id];
        const bool formed = (t.state == kCoarse || t.state == kFailed) && form_of[id] != kUnset;
        const PieceForm* pf = formed ? &scratch.forms[form_of[id]] : nullptr;
        const uint32_t v[3] = {t.v[0], t.v[1], t.v[2]}, e[3] = {t.edge[0], t.edge[1], t.edge[2]};
        const bool aniso = pf && scratch.form_aniso[form_of[id]] && !out.over_budget;
        fillLeaf(t.src, v, e, pf ? formLevel(*pf, cap) : 1, out.over_budget ? nullptr : pf, t.depth == 0, base, cap, aniso);
    };
    for (uint32_t f = 0; f < r_nt; ++f) {
        if (r_init[f]) {
            fillRecord(f);
            continue;
        }
        const auto& tri = world.mesh.triangles[f];
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;  // no area: dropped
        const auto& te = world.triangle_edges[f];
        if ((count[te[0]] | count[te[1]] | count[te[2]]) == 0) {  // untouched, no finer neighbour
            out.triangles.push_back({vertex_out[tri[0]], vertex_out[tri[1]], vertex_out[tri[2]]});
            out.source_triangles.push_back(f);
            continue;
        }
        const uint32_t v[3] = {tri[0], tri[1], tri[2]};
        const uint32_t e[3] = {te[0], te[1], te[2]};
        fillLeaf(f, v, e, 1, nullptr, true, base, cap);
    }
    for (uint32_t id = r_nt; id < r_tri_size; ++id) fillRecord(id);
    return true;
}

}  // namespace slicing
}  // namespace mesh4d
