#include "key_split.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "mesh4d/motion/keyed.h"
#include "worldline_bound.h"

namespace mesh4d {

namespace {

// The kink term a triangle may keep (in units of T): the grids' measured test that follows
// divides it by its sub-grid m <= 16 (worldline_refine.h), so 8 T leaves at most T / 2 there.
constexpr double kKinkShare = 8;

uint64_t edgeKey(uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    return uint64_t(a) << 32 | b;
}

struct Splitter {
    const World4D& world;
    const ViewSurface& view;
    const SliceSettings& settings;
    const Motion& m;
    const double shear;
    const double T;
    KeySplit out;
    std::unordered_map<uint64_t, std::vector<uint32_t>> around;  // edge -> the triangles holding it
    std::vector<uint32_t> splits;                                  // per triangle: how often split
    std::vector<CornerCrossing> crossing;                          // per vertex, once computed
    std::vector<uint8_t> crossed;
    double min_edge2 = 0;

    Splitter(const World4D& w, const ViewSurface& v, const SliceSettings& s)
        : world(w), view(v), settings(s), m(w.motion), shear(norm(v.shear)), T(s.tolerance) {}

    std::vector<Vec3>& pos() { return out.mesh.positions; }
    std::vector<std::array<uint32_t, 3>>& tris() { return out.mesh.triangles; }
    static bool degenerate(const std::array<uint32_t, 3>& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; }

    // The edge order of the header: (length^2, lower id, higher id).
    struct Ranked {
        double len2;
        uint64_t key;
        bool operator<(const Ranked& o) const { return len2 < o.len2 || (len2 == o.len2 && key < o.key); }
    };
    Ranked rank(uint32_t a, uint32_t b) { return {norm2(pos()[a] - pos()[b]), edgeKey(a, b)}; }
    Ranked longest(uint32_t t) {
        const auto& v = tris()[t];
        Ranked best = rank(v[0], v[1]);
        for (int c = 1; c < 3; ++c) best = std::max(best, rank(v[c], v[(c + 1) % 3]));
        return best;
    }

    void link(uint32_t t) {
        const auto& v = tris()[t];
        for (int c = 0; c < 3; ++c) around[edgeKey(v[c], v[(c + 1) % 3])].push_back(t);
    }
    void unlink(uint32_t t) {
        const auto& v = tris()[t];
        for (int c = 0; c < 3; ++c) {
            std::vector<uint32_t>& list = around[edgeKey(v[c], v[(c + 1) % 3])];
            list.erase(std::find(list.begin(), list.end(), t));
        }
    }

    // Splits edge `key` at its midpoint in every triangle around it (the header).
    void bisect(uint64_t key) {
        const uint32_t lo = uint32_t(key >> 32), hi = uint32_t(key & 0xffffffffu);
        const uint32_t mid = uint32_t(pos().size());
        pos().push_back(pos()[lo] + (pos()[hi] - pos()[lo]) * 0.5);
        const std::vector<uint32_t> holders = around[key];
        for (uint32_t t : holders) {
            unlink(t);
            const std::array<uint32_t, 3> v = tris()[t];
            int c = 0;  // the side (v[c], v[c + 1]) is the bisected edge
            while (edgeKey(v[c], v[(c + 1) % 3]) != key) ++c;
            const uint32_t p = v[c], q = v[(c + 1) % 3], r = v[(c + 2) % 3];
            tris()[t] = {p, mid, r};
            tris().push_back({mid, q, r});
            out.source.push_back(out.source[t]);
            splits.push_back(0);
            ++splits[t];
            link(t);
            link(uint32_t(tris().size() - 1));
        }
        around.erase(key);
    }

    // Longest-edge bisection until triangle t is split (the header).
    void split(uint32_t t) {
        const uint32_t before = splits[t];
        while (splits[t] == before) {
            uint32_t cur = t;
            for (;;) {
                const Ranked e = longest(cur);
                uint32_t next = cur;
                for (uint32_t nb : around[e.key])
                    if (nb != cur && longest(nb).key != e.key) {
                        next = nb;
                        break;
                    }
                if (next == cur) {
                    bisect(e.key);
                    break;
                }
                cur = next;
            }
        }
    }

    CornerCrossing cut(uint32_t v) {
        if (v >= crossed.size()) crossed.resize(pos().size(), 0), crossing.resize(pos().size());
        if (!crossed[v]) {
            bool ok = true;
            crossing[v] = cornerCrossing(view, m, pos()[v], &ok);
            if (!ok) crossing[v].lambda = -1;  // no bound (NaN or infinite input only)
            crossed[v] = 1;
        }
        return crossing[v];
    }

    // The header's test: the kink term over T / 2, or no bound while the corners straddle a key.
    bool needsSplit(uint32_t t) {
        const auto& v = tris()[t];
        const CornerCrossing c[3] = {cut(v[0]), cut(v[1]), cut(v[2])};
        const PieceBound b = pieceBound(m, view, shear, c);
        double d2 = 0;
        for (int i = 0; i < 3; ++i) d2 = std::max(d2, norm2(c[(i + 1) % 3].q - c[i].q));
        if (b.K < INFINITY) return b.kink > kKinkShare * T;
        const double lo = std::min({c[0].s, c[1].s, c[2].s}), hi = std::max({c[0].s, c[1].s, c[2].s});
        return keyedSegment(*m.keyed, lo) != keyedSegment(*m.keyed, hi);
    }

    KeySplit run() {
        out.mesh = world.mesh;
        const size_t nt = tris().size();
        out.source.resize(nt);
        out.limited.assign(nt, 0);
        splits.assign(nt, 0);
        int levels = 2;
        while (levels < std::max(2, settings.max_segments) && levels < (1 << 20)) levels *= 2;
        double longest2 = 0;
        for (uint32_t t = 0; t < nt; ++t) {
            out.source[t] = t;
            if (degenerate(tris()[t])) continue;
            link(t);
            longest2 = std::max(longest2, longest(t).len2);
        }
        min_edge2 = longest2 / (double(levels) * levels);
        for (uint32_t t = 0; t < tris().size(); ++t) {
            if (degenerate(tris()[t])) continue;
            while (needsSplit(t)) {
                if (!(longest(t).len2 > min_edge2)) {
                    out.limited[out.source[t]] = 1;
                    break;
                }
                if (settings.max_triangles > 0 && tris().size() >= settings.max_triangles) {
                    out.over_budget = true;
                    return std::move(out);
                }
                split(t);
            }
        }
        return std::move(out);
    }
};

}  // namespace

KeySplit splitAlongKeys(const World4D& world, const ViewSurface& view, const SliceSettings& settings) {
    Splitter s(world, view, settings);
    return s.run();
}

}  // namespace mesh4d
