#include "ray4d.h"

#include <algorithm>
#include <cmath>

#include "motion/worldline.h"

namespace mesh4d {

namespace {

using Vec4 = std::array<double, 4>;  // (t, x, y, z)

Vec4 toVec4(const Event& e) { return {e.t, e.x.x, e.x.y, e.x.z}; }
Vec4 minus(const Event& a, const Event& b) { return {a.t - b.t, a.x.x - b.x.x, a.x.y - b.x.y, a.x.z - b.x.z}; }
double dot4(const Vec4& a, const Vec4& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

// 4D direction of the ray: dR/ds.
Vec4 rayDirection(const Ray4D& ray) {
    return {ray.along_cone ? -1.0 : 0.0, ray.direction.x, ray.direction.y, ray.direction.z};
}

double det3(double a0, double a1, double a2, double b0, double b1, double b2, double c0, double c1, double c2) {
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
}

}  // namespace

std::array<double, 4> flatNormal(const std::array<Event, 4>& v) {
    const Vec4 a = minus(v[1], v[0]), b = minus(v[2], v[0]), c = minus(v[3], v[0]);
    // Expansion of the formal determinant det[e; a; b; c] along its first row: N . a = det[a; a; b; c] = 0.
    return {det3(a[1], a[2], a[3], b[1], b[2], b[3], c[1], c[2], c[3]),
            -det3(a[0], a[2], a[3], b[0], b[2], b[3], c[0], c[2], c[3]),
            det3(a[0], a[1], a[3], b[0], b[1], b[3], c[0], c[1], c[3]),
            -det3(a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2])};
}

std::optional<TetHit> intersectTet(const Ray4D& ray, const std::array<Event, 4>& v, double s_max) {
    // Step: the system [E1 E2 E3 -D] (l1, l2, l3, s)^T = R(0) - V0, rows t, x, y, z.
    const Vec4 e1 = minus(v[1], v[0]), e2 = minus(v[2], v[0]), e3 = minus(v[3], v[0]);
    const Vec4 d = rayDirection(ray);
    const Vec4 rhs = minus(ray.origin, v[0]);
    double m[4][5];
    double scale = 0;
    for (int r = 0; r < 4; ++r) {
        m[r][0] = e1[size_t(r)];
        m[r][1] = e2[size_t(r)];
        m[r][2] = e3[size_t(r)];
        m[r][3] = -d[size_t(r)];
        m[r][4] = rhs[size_t(r)];
        for (int c = 0; c < 3; ++c) scale = std::max(scale, std::fabs(m[r][c]));
    }
    // Step: eliminate with partial pivoting. A pivot below 1e-13 of the largest edge component
    // (columns 0-2; column 3 is a unit vector) means the ray runs parallel to the tetrahedron's
    // 3-flat or the tetrahedron is flat: no single hit point, reported as a miss.
    for (int col = 0; col < 4; ++col) {
        int piv = col;
        for (int r = col + 1; r < 4; ++r)
            if (std::fabs(m[r][col]) > std::fabs(m[piv][col])) piv = r;
        const double col_scale = col < 3 ? scale : 1.0;
        if (!(std::fabs(m[piv][col]) > 1e-13 * col_scale)) return std::nullopt;
        if (piv != col)
            for (int c = 0; c < 5; ++c) std::swap(m[piv][c], m[col][c]);
        for (int r = col + 1; r < 4; ++r) {
            const double f = m[r][col] / m[col][col];
            for (int c = col; c < 5; ++c) m[r][c] -= f * m[col][c];
        }
    }
    double x[4];
    for (int r = 3; r >= 0; --r) {
        double acc = m[r][4];
        for (int c = r + 1; c < 4; ++c) acc -= m[r][c] * x[c];
        x[r] = acc / m[r][r];
    }
    // Step: accept inside the tetrahedron (with kBaryEps of slack) and ahead of the origin.
    const double l0 = 1 - x[0] - x[1] - x[2];
    if (!(x[0] >= -kBaryEps && x[1] >= -kBaryEps && x[2] >= -kBaryEps && l0 >= -kBaryEps)) return std::nullopt;
    if (!(x[3] > 0 && x[3] < s_max)) return std::nullopt;
    TetHit hit;
    hit.s = x[3];
    hit.bary = {l0, x[0], x[1], x[2]};
    return hit;
}

namespace {

// The co-moving position y = x - v t of event e.
Vec3 comoving(const Event& e, const Vec3& v) { return e.x - e.t * v; }

// Builds the node for order[begin, end) at nodes[index] and, recursively, its children.
void buildNode(TraceWorld* trace, const std::vector<EventBox>& boxes, uint32_t index, uint32_t begin, uint32_t end) {
    EventBox box, centres;
    for (uint32_t i = begin; i < end; ++i) {
        const EventBox& b = boxes[trace->order[i]];
        box.add({b.t_lo, b.lo});
        box.add({b.t_hi, b.hi});
        centres.add({0.5 * (b.t_lo + b.t_hi), b.center()});
    }
    trace->nodes[index].box = box;
    trace->nodes[index].begin = begin;
    trace->nodes[index].end = end;
    if (end - begin <= kLeafPrisms) return;
    // Step: split at the median centre along the widest axis of the centres.
    // Time slabs traced as one (split_time): time is a fourth axis, in seconds = light-seconds.
    const Vec3 ext = centres.hi - centres.lo;
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    if (trace->split_time && centres.t_hi - centres.t_lo > std::max(ext.x, std::max(ext.y, ext.z))) axis = 3;
    auto key = [&](uint32_t p) {
        const Vec3 c = boxes[p].center();
        return axis == 3 ? 0.5 * (boxes[p].t_lo + boxes[p].t_hi) : (axis == 0 ? c.x : (axis == 1 ? c.y : c.z));
    };
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(trace->order.begin() + begin, trace->order.begin() + mid, trace->order.begin() + end,
                     [&](uint32_t a, uint32_t b) { return key(a) < key(b) || (key(a) == key(b) && a < b); });
    const uint32_t left = uint32_t(trace->nodes.size());
    trace->nodes[index].left = left;
    trace->nodes.resize(trace->nodes.size() + 2);
    buildNode(trace, boxes, left, begin, mid);
    buildNode(trace, boxes, left + 1, mid, end);
}

// The ray parameters [*s_lo, *s_hi] inside `box` widened by `slack`, clipped to the input range;
// false when empty. Origin o and direction D are in the box's coordinates (t, y). Inlined by
// demand: it is the traversal's inner test, and with two instances of the traversal (one world,
// slabs) GCC stopped inlining it by itself (raytrace_bench).
[[gnu::always_inline]] inline bool slab(const EventBox& box, double slack, const Vec4& o, const Vec4& D, double* s_lo, double* s_hi) {
    const double lo[4] = {box.t_lo - slack, box.lo.x - slack, box.lo.y - slack, box.lo.z - slack};
    const double hi[4] = {box.t_hi + slack, box.hi.x + slack, box.hi.y + slack, box.hi.z + slack};
    for (size_t i = 0; i < 4; ++i) {
        if (D[i] == 0) {
            if (o[i] < lo[i] || o[i] > hi[i]) return false;
            continue;
        }
        const double inv = 1 / D[i];
        double a = (lo[i] - o[i]) * inv, b = (hi[i] - o[i]) * inv;
        if (a > b) std::swap(a, b);
        *s_lo = std::max(*s_lo, a);
        *s_hi = std::min(*s_hi, b);
        if (*s_lo > *s_hi) return false;
    }
    return true;
}

}  // namespace

namespace {

// The prisms of `world` appended to trace->prisms, and their co-moving boxes to *boxes.
void addPrisms(TraceWorld* trace, const World4D& world, std::vector<EventBox>* boxes) {
    for (size_t f = 0; f < world.mesh.triangles.size(); ++f) {
        TraceWorld::Prism p;
        // Step: the 3-flat, from the first tetrahedron of the prism (all three share it: the prism
        // is the affine image of triangle x interval).
        const auto t = world.tet(3 * f);
        const std::array<Event, 4> v{world.events[t[0]], world.events[t[1]], world.events[t[2]], world.events[t[3]]};
        p.normal = flatNormal(v);
        p.offset = dot4(p.normal, toVec4(v[0]));
        // Step: bounds of the prism's six events, in the lab and co-moving, and across the 3-flat.
        EventBox co;
        double across_lo = p.offset, across_hi = p.offset, reach = 0;
        for (uint32_t vi : world.mesh.triangles[f])
            for (uint32_t cap = 0; cap < 2; ++cap) {
                const Event& e = world.events[2 * vi + cap];
                p.box.add(e);
                co.add({e.t, comoving(e, trace->velocity)});
                const double across = dot4(p.normal, toVec4(e));
                across_lo = std::min(across_lo, across);
                across_hi = std::max(across_hi, across);
                reach = std::max(reach, std::fabs(e.t) + norm(e.x));
            }
        // Step: widen the thick flat by far more than the rounding of normal . V and the hits'
        // barycentric slack (kBaryEps of an edge), far less than any pixel.
        const double widen = 1e-8 * (std::fabs(p.normal[0]) + std::fabs(p.normal[1]) + std::fabs(p.normal[2]) +
                                     std::fabs(p.normal[3])) *
                             (p.box.diagonal() + (p.box.t_hi - p.box.t_lo) + reach + 1);
        p.below = float(across_lo - widen - p.offset);
        if (double(p.below) > across_lo - widen - p.offset) p.below = std::nextafter(p.below, -INFINITY);
        p.above = float(across_hi + widen - p.offset);
        if (double(p.above) < across_hi + widen - p.offset) p.above = std::nextafter(p.above, INFINITY);
        trace->prisms.push_back(p);
        if (boxes) boxes->push_back(co);
    }
}

// The hierarchy over trace->prisms from their co-moving boxes.
void buildHierarchy(TraceWorld* trace, const std::vector<EventBox>& boxes) {
    trace->order.resize(trace->prisms.size());
    for (uint32_t f = 0; f < trace->order.size(); ++f) trace->order[f] = f;
    trace->nodes.reserve(2 * trace->prisms.size() / kLeafPrisms + 2);
    trace->nodes.resize(1);
    buildNode(trace, boxes, 0, 0, uint32_t(trace->order.size()));
}

}  // namespace

TraceWorld prepareTrace(const World4D& world, bool hierarchy) {
    TraceWorld trace;
    trace.world = &world;
    trace.flat_prisms = isUniform(world.motion);
    if (world.empty()) return trace;
    trace.prisms.reserve(world.mesh.triangles.size());
    trace.velocity = hierarchy ? world.motion.velocity : Vec3{0, 0, 0};
    std::vector<EventBox> boxes;
    addPrisms(&trace, world, hierarchy ? &boxes : nullptr);
    if (!hierarchy) return trace;
    buildHierarchy(&trace, boxes);
    return trace;
}

TraceWorld prepareSlabsTrace(const std::vector<const World4D*>& slabs) {
    TraceWorld trace;
    if (slabs.empty()) return trace;
    trace.world = slabs.front();
    trace.velocity = slabs.front()->motion.velocity;
    trace.split_time = true;
    trace.flat_prisms = isUniform(slabs.front()->motion);
    size_t prisms = 0;
    for (const World4D* w : slabs) prisms += w->empty() ? 0 : w->mesh.triangles.size();
    trace.prisms.reserve(prisms);
    std::vector<EventBox> boxes;
    boxes.reserve(prisms);
    for (const World4D* w : slabs) {
        if (w->empty()) continue;
        trace.slabs.push_back(w);
        trace.slab_first.push_back(uint32_t(trace.prisms.size()));
        addPrisms(&trace, *w, &boxes);
    }
    if (trace.prisms.empty()) return trace;
    buildHierarchy(&trace, boxes);
    return trace;
}

namespace {

// The nearest hit of a search so far, as plain numbers (one object: the search's lambda holds one
// reference to it); its WorldHit is made once, at the end (makeHit). A WorldHit held in the search
// was zeroed on every call (rep stos) and copied per hit, and a dozen separate captures were
// stored per call: together about 5 % of a frame (raytrace_bench BM_TraceFrame/1/0).
struct NearestSoFar {
    double s = 0;
    bool found = false;
    size_t prism = 0;
    uint32_t slab = 0, triangle = 0;
    const World4D* world = nullptr;
    std::array<uint32_t, 4> tet{};
    std::array<double, 4> bary{};
};

// The WorldHit of `best` (found) for `ray` (4D direction d) in `trace`.
WorldHit makeHit(const TraceWorld& trace, const Ray4D& ray, const Vec4& d, const NearestSoFar& best) {
    const TraceWorld::Prism& p = trace.prisms[best.prism];
    WorldHit w;
    w.s = best.s;
    w.event = ray.at(best.s);
    w.triangle = best.triangle;
    w.slab = best.slab;
    // The side the ray arrives from is a 4D question: it meets the 3-flat coming from where
    // N . (R(s) - V) has the sign of -N . D. The spatial test n . d alone flips the normal across
    // a moving face wherever aberration makes d graze it (issue 20).
    const Vec3 n{p.normal[1], p.normal[2], p.normal[3]};
    const double len = norm(n);
    const double facing = dot4(p.normal, d) > 0 ? -1.0 : 1.0;
    w.lab_normal = len > 0 ? (facing / len) * n : Vec3{0, 0, 0};
    // Event index 2 i + cap: rest vertex i at tau_a (cap 0) or tau_b (cap 1).
    for (size_t c = 0; c < 4; ++c) {
        w.rest_point = w.rest_point + best.bary[c] * best.world->mesh.positions[best.tet[c] / 2];
        w.own_time += best.bary[c] * (best.tet[c] % 2 ? best.world->tau_b : best.world->tau_a);
    }
    return w;
}

// intersectWorld for one world (kSlabs false) or for the slabs of a history (true).
template <bool kSlabs>
std::optional<WorldHit> intersectTrace(const TraceWorld& trace, const Ray4D& ray, double s_max) {
    const Vec4 d = rayDirection(ray);
    const Vec4 o = toVec4(ray.origin);
    const double o_abs = std::fabs(o[0]) + std::fabs(o[1]) + std::fabs(o[2]) + std::fabs(o[3]) + 1;
    NearestSoFar best;
    best.s = s_max;
    auto finish = [&]() -> std::optional<WorldHit> {
        if (!best.found) return std::nullopt;
        return makeHit(trace, ray, d, best);
    };
    auto testPrism = [&](size_t f) {
        const TraceWorld::Prism& p = trace.prisms[f];
        if (trace.flat_prisms) {
            // Step: cheap rejection: where the ray meets the prism's 3-flat must be ahead, nearer
            // than the best hit so far and inside the prism's bounds (slack of 1e-9 of the box and
            // the position, far above the rounding of s, far below any pixel).
            const double nd = dot4(p.normal, d);
            if (nd == 0) return;
            const double s_flat = (p.offset - dot4(p.normal, o)) / nd;
            const double slack_s = 1e-9 * (std::fabs(s_flat) + 1);
            if (!(s_flat > -slack_s && s_flat < best.s + slack_s)) return;
            const Event at = ray.at(s_flat);
            const double slack = 1e-9 * (p.box.diagonal() + norm(at.x) + (p.box.t_hi - p.box.t_lo) + std::fabs(at.t));
            if (!p.box.contains(at, slack)) return;
        } else {
            // Step: a twisted prism (flat_prisms false): the ray must pass through its thick flat
            // and its box at once, ahead of the origin and nearer than the best hit so far (slack as
            // above; across the flat, 1e-9 of |normal|_1 |o|_1 more for the rounding of normal . o).
            const double slack =
                1e-9 * (p.box.diagonal() + (p.box.t_hi - p.box.t_lo) + norm(ray.origin.x) + std::fabs(ray.origin.t) + 1);
            double s_lo = -slack, s_hi = best.s + slack * (1 + std::fabs(best.s));
            const double nd = dot4(p.normal, d), no = dot4(p.normal, o);
            const double across = 1e-9 * o_abs *
                                  (std::fabs(p.normal[0]) + std::fabs(p.normal[1]) + std::fabs(p.normal[2]) + std::fabs(p.normal[3]));
            const double lo = (p.offset - no) + (double(p.below) - across), hi = (p.offset - no) + (double(p.above) + across);
            if (nd == 0) {
                if (lo > 0 || hi < 0) return;
            } else {
                const double a = lo / nd, b = hi / nd;
                s_lo = std::max(s_lo, std::min(a, b));
                s_hi = std::min(s_hi, std::max(a, b));
                if (s_lo > s_hi) return;
            }
            if (!slab(p.box, slack, o, d, &s_lo, &s_hi)) return;
        }
        // Step: the prism's world (its slab) and triangle there.
        uint32_t slab = 0, triangle = uint32_t(f);
        if constexpr (kSlabs) {
            slab = uint32_t(std::upper_bound(trace.slab_first.begin(), trace.slab_first.end(), uint32_t(f)) -
                            trace.slab_first.begin()) - 1;
            triangle = uint32_t(f) - trace.slab_first[slab];
        }
        const World4D& world = kSlabs ? *trace.slabs[slab] : *trace.world;
        // Step: the prism's three tetrahedra by the 4D barycentric method; the nearest hit wins.
        for (size_t j = 0; j < 3; ++j) {
            const auto t = world.tet(3 * size_t(triangle) + j);
            const std::array<Event, 4> v{world.events[t[0]], world.events[t[1]], world.events[t[2]], world.events[t[3]]};
            const std::optional<TetHit> hit = intersectTet(ray, v, best.s);
            if (!hit) continue;
            best.s = hit->s;
            best.found = true;
            best.prism = f;
            best.slab = slab;
            best.triangle = triangle;
            best.world = &world;
            best.tet = t;
            best.bary = hit->bary;
        }
    };
    if (trace.nodes.empty()) {
        for (size_t f = 0; f < trace.prisms.size(); ++f) testPrism(f);
        return finish();
    }
    // Step: walk the hierarchy in co-moving coordinates, skipping nodes the ray meets only beyond
    // the best hit so far (slack as for the prism boxes: 1e-9 of the sizes involved).
    const Vec3& v = trace.velocity;
    const Vec3 y0 = ray.origin.x - ray.origin.t * v;
    const Vec3 dy = ray.along_cone ? ray.direction + v : ray.direction;
    const Vec4 oy{ray.origin.t, y0.x, y0.y, y0.z}, Dy{d[0], dy.x, dy.y, dy.z};
    const EventBox& root = trace.nodes[0].box;
    const double slack = 1e-9 * (root.diagonal() + norm(y0) + (root.t_hi - root.t_lo) + std::fabs(ray.origin.t) + 1);
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const TraceWorld::Node& node = trace.nodes[stack[--top]];
        double s_lo = -slack, s_hi = best.s + slack * (1 + std::fabs(best.s));
        if (!slab(node.box, slack, oy, Dy, &s_lo, &s_hi)) continue;
        if (node.left == 0) {
            for (uint32_t i = node.begin; i < node.end; ++i) testPrism(trace.order[i]);
        } else if (top + 2 <= 128) {
            stack[top++] = node.left + 1;
            stack[top++] = node.left;
        } else {
            for (uint32_t i = node.begin; i < node.end; ++i) testPrism(trace.order[i]);
        }
    }
    return finish();
}

}  // namespace

std::optional<WorldHit> intersectWorld(const TraceWorld& trace, const Ray4D& ray, double s_max) {
    if (!trace.world || trace.prisms.empty()) return std::nullopt;
    return trace.slabs.empty() ? intersectTrace<false>(trace, ray, s_max) : intersectTrace<true>(trace, ray, s_max);
}

}  // namespace mesh4d
