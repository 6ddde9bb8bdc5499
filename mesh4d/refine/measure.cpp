#include "measure.h"

#include <numeric>

namespace mesh4d::measure {

namespace {

double boxDistance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
    auto gap = [](double x, double a, double b) { return x < a ? a - x : (x > b ? x - b : 0.0); };
    const double dx = gap(p.x, lo.x, hi.x), dy = gap(p.y, lo.y, hi.y), dz = gap(p.z, lo.z, hi.z);
    return dx * dx + dy * dy + dz * dz;
}

Vec3 minV(const Vec3& a, const Vec3& b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
Vec3 maxV(const Vec3& a, const Vec3& b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
double axis(const Vec3& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

}  // namespace

// ---- The box tree ----

void BoxTree::build(std::vector<Vec3> lo, std::vector<Vec3> hi) {
    nodes_.clear();
    order_.resize(lo.size());
    std::iota(order_.begin(), order_.end(), 0u);
    if (lo.empty()) return;
    // Step: split the longest side of the centres' box at the median, down to 4 boxes a leaf.
    struct Pending {
        uint32_t node, first, count;
    };
    std::vector<Pending> pending{{0, 0, uint32_t(lo.size())}};
    nodes_.push_back({});
    while (!pending.empty()) {
        const Pending t = pending.back();
        pending.pop_back();
        Node n;
        n.lo = lo[order_[t.first]];
        n.hi = hi[order_[t.first]];
        Vec3 clo = (lo[order_[t.first]] + hi[order_[t.first]]) * 0.5, chi = clo;
        for (uint32_t i = t.first; i < t.first + t.count; ++i) {
            n.lo = minV(n.lo, lo[order_[i]]);
            n.hi = maxV(n.hi, hi[order_[i]]);
            const Vec3 c = (lo[order_[i]] + hi[order_[i]]) * 0.5;
            clo = minV(clo, c);
            chi = maxV(chi, c);
        }
        if (t.count <= 4) {
            n.first = t.first;
            n.count = t.count;
            nodes_[t.node] = n;
            continue;
        }
        const Vec3 ext = chi - clo;
        const int k = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
        const uint32_t half = t.count / 2;
        std::nth_element(order_.begin() + t.first, order_.begin() + t.first + half, order_.begin() + t.first + t.count,
                         [&](uint32_t a, uint32_t b) { return axis(lo[a] + hi[a], k) < axis(lo[b] + hi[b], k); });
        n.first = uint32_t(nodes_.size());
        n.count = 0;
        nodes_[t.node] = n;
        nodes_.push_back({});
        nodes_.push_back({});
        pending.push_back({n.first, t.first, half});
        pending.push_back({n.first + 1, t.first + half, t.count - half});
    }
    // The leaves keep the boxes themselves for the final test.
    leaf_lo_ = std::move(lo);
    leaf_hi_ = std::move(hi);
}

void BoxTree::within(const Vec3& p, double radius, std::vector<std::pair<double, uint32_t>>* out) const {
    out->clear();
    if (nodes_.empty()) return;
    const double r2 = radius * radius;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        if (boxDistance2(p, n.lo, n.hi) > r2) continue;
        if (n.count == 0) {
            stack[top++] = n.first;
            stack[top++] = n.first + 1;
            continue;
        }
        for (uint32_t i = n.first; i < n.first + n.count; ++i) {
            const uint32_t j = order_[i];
            const double d2 = boxDistance2(p, leaf_lo_[j], leaf_hi_[j]);
            if (d2 <= r2) out->push_back({std::sqrt(d2), j});
        }
    }
    std::sort(out->begin(), out->end());
}

// ---- Point to triangle ----

double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    // Step: the closest point by the region of p (vertex, edge or face), from the barycentric signs.
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return norm(p - a);
    const Vec3 bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return norm(p - b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(p - (a + ab * (d1 / (d1 - d3))));
    const Vec3 cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return norm(p - c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return norm(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const double den = va + vb + vc;
    if (!(den > 0)) {  // degenerate: the nearest of its three sides
        auto seg = [&](const Vec3& s, const Vec3& e) {
            const Vec3 d = e - s;
            const double l2 = norm2(d);
            const double t = l2 > 0 ? std::clamp(dot(p - s, d) / l2, 0.0, 1.0) : 0.0;
            return norm(p - (s + d * t));
        };
        return std::min({seg(a, b), seg(b, c), seg(c, a)});
    }
    return norm(p - (a + ab * (vb / den) + ac * (vc / den)));
}

// ---- The exact surface ----

ExactSurface::ExactSurface(const World4D& w, const ViewSurface& view, const Vec3& origin)
    : w_(w), view_(view), origin_(origin), uniform_(isUniform(w.motion)) {
    if (uniform_) now_base_ = nowBase(view, w.motion);
    // Step: each input triangle's lattice of exact points, and its box widened by their chord error.
    const int n = kLattice, per = (n + 1) * (n + 2) / 2;
    const size_t nt = w.mesh.triangles.size();
    lattice_.resize(nt * per);
    std::vector<Vec3> lo(nt), hi(nt);
    for (size_t f = 0; f < nt; ++f) {
        const auto& t = w.mesh.triangles[f];
        const Vec3 q0 = w.mesh.positions[t[0]], e1 = w.mesh.positions[t[1]] - q0, e2 = w.mesh.positions[t[2]] - q0;
        Vec3* L = &lattice_[f * per];
        int k = 0;
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) L[k++] = exact(q0 + e1 * (double(i) / n) + e2 * (double(j) / n));
        // The patch lies within the lattice's flat sub-triangles widened by their chord error: measured at
        // each sub-triangle's centroid, times 4 (a quadratic's largest error over a triangle is at most
        // 9/4 of its centroid's).
        Vec3 a = L[0], b = L[0];
        for (int k2 = 0; k2 < per; ++k2) {
            a = minV(a, L[k2]);
            b = maxV(b, L[k2]);
        }
        double dev = 0;
        auto at = [&](int i, int j) { return i * (n + 1) - i * (i - 1) / 2 + j; };  // index of lattice point (i, j)
        for (int i = 0; i < n; ++i)
            for (int j = 0; i + j < n; ++j) {
                const int c0 = at(i, j), c1 = at(i + 1, j), c2 = at(i, j + 1);
                const Vec3 centre = q0 + e1 * ((3 * i + 1) / (3.0 * n)) + e2 * ((3 * j + 1) / (3.0 * n));
                dev = std::max(dev, norm(exact(centre) - (L[c0] + L[c1] + L[c2]) / 3.0));
                if (i + j + 1 < n) {  // the upside-down sub-triangle (i + 1, j), (i, j + 1), (i + 1, j + 1)
                    const int c3 = at(i + 1, j + 1);
                    const Vec3 centre2 = q0 + e1 * ((3 * i + 2) / (3.0 * n)) + e2 * ((3 * j + 2) / (3.0 * n));
                    dev = std::max(dev, norm(exact(centre2) - (L[c1] + L[c2] + L[c3]) / 3.0));
                }
            }
        const double widen = 4 * dev + 1e-12 * (norm(a) + norm(b));
        const Vec3 pad{widen, widen, widen};
        lo[f] = a - pad;
        hi[f] = b + pad;
    }
    tree_.build(std::move(lo), std::move(hi));
}

double ExactSurface::onEdge(const Vec3& q0, const Vec3& q1, const Vec3& p) const {
    // Step: the best of 5 points along the edge, then Newton in the edge's parameter, clamped to it.
    const Vec3 e = q1 - q0;
    double t = 0, best = INFINITY;
    for (int i = 0; i <= 4; ++i) {
        const double d = norm(exact(q0 + e * (i / 4.0)) - p);
        if (d < best) {
            best = d;
            t = i / 4.0;
        }
    }
    const double h = 1e-6;
    for (int it = 0; it < 30; ++it) {
        const Vec3 r = exact(q0 + e * t) - p;
        const double tt = t + h <= 1 ? h : -h;
        const Vec3 J = (exact(q0 + e * (t + tt)) - p - r) * (1 / tt);
        const double jj = dot(J, J);
        if (!(jj > 0)) break;
        const double next = std::clamp(t - dot(J, r) / jj, 0.0, 1.0);
        const double step = std::fabs(next - t);
        t = next;
        if (step < 1e-8) break;  // the rounding of the exact points
    }
    return std::min(best, norm(exact(q0 + e * t) - p));
}

double ExactSurface::onTriangle(uint32_t f, const Vec3& p, double a, double b) const {
    const auto& t = w_.mesh.triangles[f];
    const Vec3 q0 = w_.mesh.positions[t[0]], q1 = w_.mesh.positions[t[1]], q2 = w_.mesh.positions[t[2]];
    const Vec3 e1 = q1 - q0, e2 = q2 - q0;
    auto F = [&](double x, double y) { return exact(q0 + e1 * x + e2 * y) - p; };
    // Step: Gauss-Newton in (a, b) over the plane of the rest triangle; every iterate inside the
    // triangle is a point of the surface, the nearest of them kept.
    const double h = 1e-6, slack = 1e-12;
    auto inside = [&](double x, double y) { return x >= -slack && y >= -slack && x + y <= 1 + slack; };
    double best = INFINITY;
    bool left = false;  // the minimiser lies outside the triangle (or the search failed)
    for (int it = 0; it < 30; ++it) {
        const Vec3 r = F(a, b);
        if (inside(a, b)) best = std::min(best, norm(r));
        const Vec3 Ja = (F(a + h, b) - r) * (1 / h), Jb = (F(a, b + h) - r) * (1 / h);
        const double A = dot(Ja, Ja), B = dot(Ja, Jb), C = dot(Jb, Jb);
        const double ga = dot(Ja, r), gb = dot(Jb, r);
        const double det = A * C - B * B;
        if (!(det > 0)) {
            left = true;
            break;
        }
        const double da = -(C * ga - B * gb) / det, db = -(A * gb - B * ga) / det;
        a += da;
        b += db;
        if (!(std::fabs(a) < 4 && std::fabs(b) < 4)) {  // far outside: the edges decide
            left = true;
            break;
        }
        // Converged to the rounding of the exact points (steps of 1e-9 of the triangle are noise).
        if (std::fabs(da) + std::fabs(db) < 1e-8) break;
    }
    if (!left && inside(a, b)) {
        const double x = std::clamp(a, 0.0, 1.0), y = std::clamp(b, 0.0, 1.0 - x);
        return std::min(best, norm(F(x, y)));
    }
    // Step: the minimiser outside the triangle: the least over the edges whose side it lies beyond
    // (a convex function's least over the triangle is on one of them), all three if the search failed.
    if (left || b < 0) best = std::min(best, onEdge(q0, q1, p));
    if (left || a + b > 1) best = std::min(best, onEdge(q1, q2, p));
    if (left || a < 0) best = std::min(best, onEdge(q2, q0, p));
    return best;
}

double ExactSurface::distance(const Vec3& p, double radius, uint32_t hint_triangle, const Vec3* hint_rest) const {
    double best = radius;
    // Step: the sample's own triangle first, from its own rest point.
    if (hint_triangle < w_.mesh.triangles.size() && hint_rest) {
        const auto& t = w_.mesh.triangles[hint_triangle];
        const Vec3 q0 = w_.mesh.positions[t[0]], e1 = w_.mesh.positions[t[1]] - q0, e2 = w_.mesh.positions[t[2]] - q0;
        // (a, b) of the rest point: least squares in the triangle's plane.
        const Vec3 d = *hint_rest - q0;
        const double A = dot(e1, e1), B = dot(e1, e2), C = dot(e2, e2), det = A * C - B * B;
        if (det > 0) {
            const double g1 = dot(e1, d), g2 = dot(e2, d);
            best = std::min(best, onTriangle(hint_triangle, p, (C * g1 - B * g2) / det, (A * g2 - B * g1) / det));
        }
    }
    if (best == 0) return 0;
    // Step: every other triangle whose widened box comes within the best distance, nearest box first.
    thread_local std::vector<std::pair<double, uint32_t>> near;
    tree_.within(p, best, &near);
    const int n = kLattice;
    const size_t per = size_t(n + 1) * size_t(n + 2) / 2;
    for (const auto& [box, f] : near) {
        if (box > best) break;
        if (f == hint_triangle && hint_rest) continue;
        // Start from the nearest lattice point.
        const Vec3* L = &lattice_[size_t(f) * per];
        double a = 0, b = 0, dl = INFINITY;
        int k = 0;
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j, ++k)
                if (const double d = norm2(L[k] - p); d < dl) {
                    dl = d;
                    a = double(i) / n;
                    b = double(j) / n;
                }
        best = std::min(best, onTriangle(f, p, a, b));
    }
    return best;
}

// ---- Both directions ----

GeometricError geometricError(const World4D& w, const ViewSurface& view, const ApparentMesh& m, int grid) {
    GeometricError r;
    if (m.triangles.empty()) return r;
    const ExactSurface exact(w, view, m.origin);
    // Step: a tree of the output triangles' boxes.
    std::vector<Vec3> lo(m.triangles.size()), hi(m.triangles.size());
    for (size_t t = 0; t < m.triangles.size(); ++t) {
        const auto& ot = m.triangles[t];
        lo[t] = minV(minV(m.positions[ot[0]], m.positions[ot[1]]), m.positions[ot[2]]);
        hi[t] = maxV(maxV(m.positions[ot[0]], m.positions[ot[1]]), m.positions[ot[2]]);
    }
    BoxTree output;
    output.build(std::move(lo), std::move(hi));
    std::vector<std::pair<double, uint32_t>> near;
    // The distance from an exact point to the output mesh, searched within `radius`.
    auto toOutput = [&](const Vec3& x, double radius) {
        double best = radius;
        output.within(x, radius, &near);
        for (const auto& [box, t] : near) {
            if (box > best) break;
            const auto& ot = m.triangles[t];
            best = std::min(best, pointTriangleDistance(x, m.positions[ot[0]], m.positions[ot[1]], m.positions[ot[2]]));
        }
        return best;
    };
    // Step: each output triangle's largest parametric distance over its samples, the largest first.
    auto sample = [&](size_t t, int s, Vec3* rest, Vec3* out) {
        const auto& ot = m.triangles[t];
        *rest = m.rest_points[ot[0]] * kSamples[s][0] + m.rest_points[ot[1]] * kSamples[s][1] +
                m.rest_points[ot[2]] * kSamples[s][2];
        *out = m.positions[ot[0]] * kSamples[s][0] + m.positions[ot[1]] * kSamples[s][1] +
               m.positions[ot[2]] * kSamples[s][2];
    };
    std::vector<std::pair<double, uint32_t>> order(m.triangles.size());
    for (size_t t = 0; t < m.triangles.size(); ++t) {
        double largest = 0;
        for (int s = 0; s < 12; ++s) {
            Vec3 rest, out;
            sample(t, s, &rest, &out);
            largest = std::max(largest, norm(exact.exact(rest) - out));
        }
        order[t] = {largest, uint32_t(t)};
    }
    std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    // Step: both directions at the samples, each searched within its parametric distance, until no
    // sample left can raise either maximum.
    for (const auto& [largest, t] : order) {
        if (largest <= r.output_to_exact && largest <= r.exact_to_output) break;
        for (int s = 0; s < 12; ++s) {
            Vec3 rest, out;
            sample(t, s, &rest, &out);
            const Vec3 x = exact.exact(rest);
            const double parametric = norm(x - out);
            if (parametric > r.output_to_exact)
                r.output_to_exact = std::max(r.output_to_exact, exact.distance(out, parametric, m.source_triangles[t], &rest));
            if (parametric > r.exact_to_output) r.exact_to_output = std::max(r.exact_to_output, toOutput(x, parametric));
        }
    }
    // Step: the lattice of every input triangle (exactToOutput's points), against the whole output,
    // the largest parametric distance first.
    const std::vector<std::vector<size_t>> by_source = outputBySource(w, m);
    std::vector<std::pair<double, Vec3>> lattice;  // (parametric distance, exact point)
    for (size_t f = 0; f < w.mesh.triangles.size(); ++f) {
        if (by_source[f].empty()) continue;
        Vec3 n;
        forEachLatticePoint(w.mesh, f, grid, &n, [&](const Vec3& q) {
            const Vec3 x = exact.exact(q);
            // The parametric distance (the output point of the same rest point) bounds the search;
            // a point no output triangle covers (radius infinite) is searched over the whole output.
            const double radius = sameRestPoint(m, by_source[f], n, q, x);
            if (radius > r.exact_to_output) lattice.push_back({radius, x});  // others cannot raise it
        });
    }
    std::sort(lattice.begin(), lattice.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    for (const auto& [radius, x] : lattice) {
        if (radius <= r.exact_to_output) break;
        r.exact_to_output = std::max(r.exact_to_output, toOutput(x, radius));
    }
    return r;
}

}  // namespace mesh4d::measure
