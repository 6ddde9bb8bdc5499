#include "form_bisect.h"

#include <algorithm>
#include <cmath>

#include "chord_error.h"

namespace mesh4d {

namespace {
constexpr double kCorner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
}

int FormBisection::sideSegments(double c, double limit, int cap) {
    cap = std::max(cap, 1);
    if (!(c > 0)) return 1;
    if (!(limit > 0)) return cap;
    const double need = c / (3 * limit);
    if (!(need <= double(cap) * double(cap))) return cap;
    int n = std::max(1, int(std::ceil(std::sqrt(need))));
    while (double(n) * double(n) < need) ++n;
    return std::min(n, cap);
}

inline double FormBisection::edgeC(uint32_t a, uint32_t b) const {
    const double d1 = pts_[b].l1 - pts_[a].l1, d2 = pts_[b].l2 - pts_[a].l2;
    return d1 * d1 * form_.cu + d2 * d2 * form_.cv + 2 * d1 * d2 * form_.cuv;
}

// The index of point p along side k (from P_k), or -1 when p is not on it.
int FormBisection::sideIndex(uint32_t p, int k) const {
    if (p < 3) {
        if (int(p) == k) return 0;
        if (int(p) == (k + 1) % 3) return n_[k];
        return -1;
    }
    return pts_[p].side == k ? pts_[p].index : -1;
}

bool FormBisection::splittable(const Tri& t, int e) const {
    if (t.nb[e] >= 0) return true;
    const int k = -t.nb[e] - 1;
    const int i0 = sideIndex(t.v[e], k), i1 = sideIndex(t.v[(e + 1) % 3], k);
    return std::abs(i1 - i0) > 1;
}

// A triangle's verdict from its edges: the edge to split is the longest splittable one in the
// form's metric, ties to the older ends (lower ids: a point the splits make never wins a tie, so
// Rivara's path cannot follow the new edges of equal length around a corner); it must be split while a side's edge spans more than one
// segment or its bound exceeds the limit.
void FormBisection::judge(Tri& t) const {
    int best = -1;
    double len = 0;
    uint32_t lo = 0, hi = 0;
    bool need = false;
    for (int e = 0; e < 3; ++e) {
        if (!splittable(t, e)) continue;
        if (t.nb[e] < 0) need = true;
        const uint32_t a = t.v[e], b = t.v[(e + 1) % 3];
        const uint32_t l = std::min(a, b), h = std::max(a, b);
        const double c = t.c[e];
        if (best < 0 || c > len || (c == len && (l < lo || (l == lo && h < hi)))) {
            best = e;
            len = c;
            lo = l;
            hi = h;
        }
    }
    t.chosen = int8_t(best);
    t.need = need || !(bubbleMax(t.c[0], t.c[1], t.c[2]) <= form_.limit);
    if (shape(t) < min_shape_) over_ = true;  // a sliver (see fill)
}

// 2 (c0 c1 + c1 c2 + c2 c0) - c0^2 - c1^2 - c2^2 (4 times the squared area in the form's metric)
// over the largest c squared: 3 for an equilateral triangle, 0 for a flat one.
double FormBisection::shape(const Tri& t) {
    const double a = t.c[0], b = t.c[1], c = t.c[2];
    const double m = std::max(a, std::max(b, c));
    return m > 0 ? (2 * (a * b + b * c + c * a) - a * a - b * b - c * c) / (m * m) : 0;
}

uint32_t FormBisection::sidePoint(int k, int i) const {
    if (i == 0) return uint32_t(k);
    if (i == n_[k]) return uint32_t((k + 1) % 3);
    return side_first_[k] + uint32_t(i - 1);
}

// Splits triangle t: Rivara's path from t (the neighbour across t's chosen edge first, when that
// edge is not the neighbour's own chosen one), then t's chosen edge in both its triangles.
void FormBisection::split(uint32_t t) {
    // Halves triangle id across edge e at point m: id keeps (a, m, o), the new one is (m, b, o).
    // c_am, c_mb: the form on the halves (a quarter of c(a, b) at the middle); c_mo computed once.
    auto halve = [&](uint32_t id, int e, uint32_t m, double c_am, double c_mb) {
        const Tri T = tris_[id];
        const int e1 = (e + 1) % 3, e2 = (e + 2) % 3;
        const uint32_t a = T.v[e], b = T.v[e1], o = T.v[e2];
        const int32_t nab = T.nb[e], nbo = T.nb[e1], noa = T.nb[e2];
        const uint32_t id1 = uint32_t(tris_.size());
        const double c_mo = edgeC(std::min(m, o), std::max(m, o));
        tris_[id] = Tri{{a, m, o}, {nab, int32_t(id1), noa}, {c_am, c_mo, T.c[e2]}, -1, false};
        tris_.push_back(Tri{{m, b, o}, {nab, nbo, int32_t(id)}, {c_mb, T.c[e1], c_mo}, -1, false});
        if (nbo >= 0)
            for (int32_t& x : tris_[size_t(nbo)].nb)
                if (x == int32_t(id)) x = int32_t(id1);
        stack_.push_back(id);
        stack_.push_back(id1);
        return id1;
    };
    for (;;) {
        if (tris_.size() >= max_triangles_) {
            over_ = true;
            return;
        }
        const Tri T = tris_[t];
        const int e = T.chosen;
        const uint32_t a = T.v[e], b = T.v[(e + 1) % 3];
        if (T.nb[e] < 0) {  // a side's edge: cut at the side's middle point of its span
            const int k = -T.nb[e] - 1;
            const int i0 = sideIndex(a, k), i1 = sideIndex(b, k);
            const uint32_t m = sidePoint(k, (std::min(i0, i1) + std::max(i0, i1)) / 2);
            halve(t, e, m, edgeC(std::min(a, m), std::max(a, m)), edgeC(std::min(m, b), std::max(m, b)));
            judge(tris_[t]);
            judge(tris_.back());
            return;
        }
        const uint32_t n = uint32_t(T.nb[e]);
        const int en = tris_[n].chosen;
        if (tris_[n].nb[en] != int32_t(t)) {
            split(n);  // the neighbour's longer edge first; t's neighbour across e is now one of its halves
            if (over_) return;
            continue;
        }
        const uint32_t m = uint32_t(pts_.size());
        pts_.push_back(Point{0.5 * (pts_[a].l1 + pts_[b].l1), 0.5 * (pts_[a].l2 + pts_[b].l2), -1, -1});
        inner_.push_back({pts_.back().l1, pts_.back().l2});
        const double quarter = 0.25 * T.c[e];
        const uint32_t t1 = halve(t, e, m, quarter, quarter);
        const uint32_t n1 = halve(n, en, m, quarter, quarter);
        tris_[t].nb[0] = int32_t(n1);
        tris_[n1].nb[0] = int32_t(t);
        tris_[n].nb[0] = int32_t(t1);
        tris_[t1].nb[0] = int32_t(n);
        for (uint32_t id : {t, t1, n, n1}) judge(tris_[id]);
        return;
    }
}

bool FormBisection::fill(const TessForm& form, const int n[3], size_t max_triangles,
                         std::vector<std::array<uint32_t, 3>>& out) {
    form_ = form;
    max_triangles_ = max_triangles;
    over_ = false;
    pts_.clear();
    inner_.clear();
    tris_.clear();
    stack_.clear();
    out.clear();
    for (int k = 0; k < 3; ++k) {
        n_[k] = std::max(1, n[k]);
        pts_.push_back(Point{kCorner[k][0], kCorner[k][1], -1, -1});
    }
    for (int k = 0; k < 3; ++k) {
        side_first_[k] = uint32_t(pts_.size());
        const double* p = kCorner[k];
        const double* q = kCorner[(k + 1) % 3];
        for (int i = 1; i < n_[k]; ++i) {
            const double t = double(i) / double(n_[k]);
            pts_.push_back(Point{p[0] + (q[0] - p[0]) * t, p[1] + (q[1] - p[1]) * t, k, i});
        }
    }
    inner_first_ = uint32_t(pts_.size());
    tris_.push_back(Tri{{0, 1, 2}, {-1, -2, -3}, {edgeC(0, 1), edgeC(1, 2), edgeC(0, 2)}, -1, false});
    min_shape_ = shape(tris_[0]) * kShapeLoss;
    judge(tris_[0]);
    stack_.push_back(0);
    while (!stack_.empty()) {
        if (over_) return false;
        const uint32_t t = stack_.back();
        stack_.pop_back();
        if (!tris_[t].need) continue;
        if (tris_[t].chosen < 0 || tris_.size() >= max_triangles) return false;
        split(t);
        if (over_) return false;
    }
    out.reserve(tris_.size());
    for (const Tri& t : tris_) out.push_back({t.v[0], t.v[1], t.v[2]});
    return true;
}

}  // namespace mesh4d
