#include "tessellate.h"

#include <algorithm>
#include <cmath>

#include "chord_error.h"

namespace mesh4d {

namespace {

struct LoopPoint {
    uint32_t id;
    double l1, l2;
    double key;  // side k + place along it (0 .. 1), the zipper's order
};

}  // namespace

TessLayout::TessLayout(int N, const int n[3]) {
    N_ = std::max(N, 1);
    for (int k = 0; k < 3; ++k) n_[k] = std::max(n[k], 1);
    grid_ = n_[0] == N_ && n_[1] == N_ && n_[2] == N_;
    if (!grid_) {
        if (N_ == 1) centroid_ = (n_[0] > 1) + (n_[1] > 1) + (n_[2] > 1) >= 2;
        else if (N_ == 2) N_ = 3;
    }
    uint32_t at = 3;
    for (int k = 0; k < 3; ++k) {
        side_first_[k] = at;
        at += uint32_t(n_[k] - 1);
    }
    inner_first_ = at;
    if (centroid_) at += 1;
    else if (N_ >= 3) at += uint32_t((N_ - 1) * (N_ - 2) / 2);
    count_ = at;
}

// Grid point (i, j), i + j <= N: a corner, a side's point (only when that side has N segments),
// or an inner point (row j = 1 .. N - 2 holds i = 1 .. N - 1 - j).
uint32_t TessLayout::gridPoint(int i, int j) const {
    if (j == 0) return i == 0 ? 0 : (i == N_ ? 1 : side_first_[0] + uint32_t(i - 1));
    if (i + j == N_) return j == N_ ? 2 : side_first_[1] + uint32_t(j - 1);
    if (i == 0) return side_first_[2] + uint32_t(N_ - j - 1);
    const int row_start = (j - 1) * (N_ - 1) - (j - 1) * j / 2;
    return inner_first_ + uint32_t(row_start + i - 1);
}

std::array<double, 2> TessLayout::param(uint32_t p) const {
    static constexpr double kCorner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    if (p < 3) return {kCorner[p][0], kCorner[p][1]};
    if (p < inner_first_) {
        int k = 2;
        while (p < side_first_[k]) --k;
        const double t = double(p - side_first_[k] + 1) / double(n_[k]);
        const int k1 = (k + 1) % 3;
        return {kCorner[k][0] * (1 - t) + kCorner[k1][0] * t, kCorner[k][1] * (1 - t) + kCorner[k1][1] * t};
    }
    if (centroid_) return {1.0 / 3, 1.0 / 3};
    int rest = int(p - inner_first_), j = 1;
    while (rest >= N_ - 1 - j) {
        rest -= N_ - 1 - j;
        ++j;
    }
    return {double(rest + 1) / N_, double(j) / N_};
}

bool TessLayout::tessellate(const TessForm* form, std::vector<std::array<uint32_t, 3>>& out) const {
    out.clear();
    const int N = N_;
    // Step: the grid, or the inner grid (every grid coordinate >= 1) of the stitched pattern.
    if (grid_) {
        // Row by row, the point ids of rows j and j + 1 side by side.
        static thread_local std::vector<uint32_t> rows;
        rows.resize(2 * size_t(N + 1));
        uint32_t* cur = rows.data();
        uint32_t* nxt = cur + N + 1;
        for (int i = 0; i <= N; ++i) cur[i] = gridPoint(i, 0);
        out.resize(size_t(N) * size_t(N));
        std::array<uint32_t, 3>* w = out.data();
        for (int j = 0; j < N; ++j) {
            const int m = N - j;  // points i = 0 .. m on row j
            nxt[0] = gridPoint(0, j + 1);
            if (m - 1 >= 1) {
                nxt[m - 1] = gridPoint(m - 1, j + 1);
                const uint32_t first = m - 1 > 1 ? gridPoint(1, j + 1) : 0;
                for (int i = 1; i < m - 1; ++i) nxt[i] = first + uint32_t(i - 1);
            }
            for (int i = 0; i < m; ++i) {
                *w++ = {cur[i], cur[i + 1], nxt[i]};
                if (i + 1 < m) *w++ = {cur[i + 1], nxt[i + 1], nxt[i]};
            }
            std::swap(cur, nxt);
        }
        return true;
    }
    // The boundary polygon, counter-clockwise: corner k, then side k's points.
    auto sidePoint = [&](int k, int i) -> LoopPoint {  // side k's point i = 0 .. n_k - 1 (0: corner k)
        static constexpr double kCorner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
        const int k1 = (k + 1) % 3;
        const double t = double(i) / double(n_[k]);
        return {i == 0 ? uint32_t(k) : side_first_[k] + uint32_t(i - 1), kCorner[k][0] * (1 - t) + kCorner[k1][0] * t,
                kCorner[k][1] * (1 - t) + kCorner[k1][1] * t, k + t};
    };
    if (N == 1) {
        // Step: the whole piece is within the bound: a fan of its boundary polygon (convexity:
        // every triangle inside it is too), from the centroid or from the corner opposite the
        // one finer side.
        if (centroid_) {
            const uint32_t c = inner_first_;
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < n_[k]; ++i) {
                    const uint32_t a = sidePoint(k, i).id;
                    const uint32_t b = i + 1 < n_[k] ? sidePoint(k, i + 1).id : uint32_t((k + 1) % 3);
                    out.push_back({c, a, b});
                }
            return true;
        }
        int k = 0;
        while (n_[k] == 1) ++k;
        const uint32_t apex = uint32_t((k + 2) % 3);
        for (int i = 0; i < n_[k]; ++i) {
            const uint32_t a = sidePoint(k, i).id;
            const uint32_t b = i + 1 < n_[k] ? sidePoint(k, i + 1).id : uint32_t((k + 1) % 3);
            out.push_back({a, b, apex});
        }
        return true;
    }
    // Step: the stitched ring, every triangle checked against the form.
    // c(d) of the side p -> r in the form's metric (form set), before flooring at 0.
    auto sideValue = [&](const LoopPoint& p, const LoopPoint& r) {
        const double du = r.l1 - p.l1, dv = r.l2 - p.l2;
        return du * du * form->cu + dv * dv * form->cv + 2 * du * dv * form->cuv;
    };
    auto passes = [&](const LoopPoint& a, const LoopPoint& b, const LoopPoint& c) {
        if (!form) return true;
        auto q = [&](const LoopPoint& p, const LoopPoint& r) { return std::max(0.0, sideValue(p, r)); };
        return bubbleMax(q(a, b), q(b, c), q(c, a)) <= form->limit;
    };
    // Ears: at a corner whose two sides have inner points, when the ear's chord (from 1/n[k-1] of
    // the way along one side to 1/n[k] along the other) passes between the corner and the inner
    // grid's corner, at 1/N along both: n[k-1] + n[k] > N.
    bool ear[3];
    for (int k = 0; k < 3; ++k) {
        const int before = n_[(k + 2) % 3];
        ear[k] = before >= 2 && n_[k] >= 2 && before + n_[k] > N;
    }
    static thread_local std::vector<LoopPoint> outer_vec, inner_vec;
    outer_vec.resize(size_t(n_[0] + n_[1] + n_[2]));
    LoopPoint* outer = outer_vec.data();
    size_t no = 0;
    for (int k = 0; k < 3; ++k)
        for (int i = ear[k] ? 1 : 0; i < n_[k]; ++i) outer[no++] = sidePoint(k, i);
    for (int k = 0; k < 3; ++k) {
        if (!ear[k]) continue;
        const int km = (k + 2) % 3;
        const LoopPoint a = sidePoint(km, n_[km] - 1), b = sidePoint(k, 0), c = sidePoint(k, 1);
        if (!passes(a, b, c)) return false;
        out.push_back({a.id, b.id, c.id});
    }
    // The inner loop: the inner grid's boundary, counter-clockwise, each side's points from the
    // second to the corner it ends at (the inner corner near P_k is listed last on side k - 1).
    const size_t n_inner = N == 3 ? 1 : size_t(3 * (N - 3));
    inner_vec.resize(n_inner);
    LoopPoint* inner = inner_vec.data();
    // Inner point i of side k is P_k + (i E_k + D_k) / N, D_k = P_{k+2} - P_k: its place along the
    // side is its projection in the form's metric, i / N + sigma_k / N with
    // sigma_k = B(D_k, E_k) / c(E_k) (B the form's bilinear form; 1/2 without a form), kept within
    // the side: so each stitched triangle joins points that face each other in the metric the
    // bound measures (the grid's own diagonals when every n[k] = N).
    double sigma[3] = {0.5, 0.5, 0.5};
    if (form) {
        auto bil = [&](double a0, double a1, double b0, double b1) {
            return a0 * b0 * form->cu + a1 * b1 * form->cv + (a0 * b1 + a1 * b0) * form->cuv;
        };
        static constexpr double kE[3][2] = {{1, 0}, {-1, 1}, {0, -1}}, kD[3][2] = {{0, 1}, {-1, 0}, {1, -1}};
        for (int k = 0; k < 3; ++k) {
            const double q = bil(kE[k][0], kE[k][1], kE[k][0], kE[k][1]);
            const double b = bil(kD[k][0], kD[k][1], kE[k][0], kE[k][1]);
            if (q > 0 && b == b) sigma[k] = b / q;
        }
    }
    auto place = [&](int k, int i) { return k + std::min(1.0, std::max(0.0, (i + sigma[k]) / N)); };
    if (N == 3) {
        inner[0] = {gridPoint(1, 1), 1.0 / 3, 1.0 / 3, 0};
    } else {
        size_t at = 0;
        for (int i = 2; i <= N - 2; ++i) inner[at++] = {gridPoint(i, 1), double(i) / N, 1.0 / N, place(0, i)};
        for (int i = 2; i <= N - 2; ++i)
            inner[at++] = {gridPoint(N - 1 - i, i), double(N - 1 - i) / N, double(i) / N, place(1, i)};
        for (int i = 2; i <= N - 2; ++i)
            inner[at++] = {gridPoint(1, N - 1 - i), 1.0 / N, double(N - 1 - i) / N, place(2, i)};
    }
    const size_t ni = n_inner;
    // Zip from (first outer point, inner corner near P0), advancing along the loop whose next
    // point comes first (the outer one on a tie) until both are back at the start.
    auto outerKey = [&](size_t a) { return outer[a % no].key + 3.0 * double(a / no); };
    auto innerKey = [&](size_t b) { return b == 0 ? inner[ni - 1].key - 3 : inner[b - 1].key; };  // b - 1: inner index
    size_t a = 0, b = 0;  // b counts inner advances: the current inner point is inner[(b + ni - 1) % ni]
    const size_t inner_steps = ni == 1 ? 0 : ni;
    if (!form) {
        while (a < no || b < inner_steps) {
            const LoopPoint& oa = outer[a % no];
            const LoopPoint& ib = inner[(b + ni - 1) % ni];
            if (b == inner_steps || (a < no && outerKey(a + 1) <= innerKey(b + 1))) {
                out.push_back({oa.id, outer[(a + 1) % no].id, ib.id});
                ++a;
            } else {
                out.push_back({oa.id, inner[b % ni].id, ib.id});
                ++b;
            }
        }
    } else {
        // Each step's triangle (oa, next, ib) is checked on its three sides' values c(d) (as
        // passes, in the same order): the side (ib, oa) is the diagonal the previous step made,
        // and the new diagonal is the one the choice measured, so each value is computed once.
        // (A side's value is the same bits either way round: negating both differences is exact.)
        const auto& q = sideValue;
        auto turns = [&](const LoopPoint& p, const LoopPoint& u, const LoopPoint& r) {
            return (u.l1 - p.l1) * (r.l2 - p.l2) - (u.l2 - p.l2) * (r.l1 - p.l1) > 0;
        };
        double diag = std::max(0.0, q(inner[(ni - 1) % ni], outer[0]));  // c(ib - oa), the current diagonal
        while (a < no || b < inner_steps) {
            const LoopPoint& oa = outer[a % no];
            const LoopPoint& ib = inner[(b + ni - 1) % ni];
            bool take_outer = b == inner_steps || (a < no && outerKey(a + 1) <= innerKey(b + 1));
            double d_outer = NAN, d_inner = NAN;  // c(on - ib) and c(in - oa) when measured
            if (a < no && b < inner_steps) {
                // Both may advance: the shorter diagonal in the form's metric (the smaller triangle),
                // unless that triangle would turn over (a side point beyond the inner side's line).
                const LoopPoint& on = outer[(a + 1) % no];
                const LoopPoint& in = inner[b % ni];
                const bool outer_ok = turns(oa, on, ib), inner_ok = turns(oa, in, ib);
                if (outer_ok && inner_ok) {
                    d_outer = q(on, ib);
                    d_inner = q(oa, in);
                    take_outer = d_outer <= d_inner;
                } else if (outer_ok != inner_ok) {
                    take_outer = outer_ok;
                }
            }
            if (take_outer) {
                const LoopPoint& on = outer[(a + 1) % no];
                const double next = std::max(0.0, d_outer == d_outer ? d_outer : q(on, ib));
                if (!(bubbleMax(std::max(0.0, q(oa, on)), next, diag) <= form->limit)) return false;
                out.push_back({oa.id, on.id, ib.id});
                diag = next;
                ++a;
            } else {
                const LoopPoint& in = inner[b % ni];
                const double next = std::max(0.0, d_inner == d_inner ? d_inner : q(oa, in));
                if (!(bubbleMax(next, std::max(0.0, q(in, ib)), diag) <= form->limit)) return false;
                out.push_back({oa.id, in.id, ib.id});
                diag = next;
                ++b;
            }
        }
    }
    // Step: the inner grid (every grid coordinate >= 1: rows j = 1 .. N - 3 hold its triangles),
    // once the ring passed. Row j's inner points are consecutive from inner_first + rs(j).
    uint32_t rs = inner_first_;
    for (int j = 1; j + 2 < N; ++j) {
        const uint32_t next = rs + uint32_t(N - 1 - j);
        for (int i = 1; i + j + 2 <= N; ++i) {
            const uint32_t p = rs + uint32_t(i - 1), c = next + uint32_t(i - 1);
            out.push_back({p, p + 1, c});
            if (i + j + 3 <= N) out.push_back({p + 1, c + 1, c});
        }
        rs = next;
    }
    return true;
}

}  // namespace mesh4d
