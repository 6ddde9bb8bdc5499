#include "tessellate.h"

#include <cmath>

namespace mesh4d {

uint32_t boundaryIndex(const uint32_t n[3], int c, uint32_t k) {
    uint32_t start = 0;
    for (int e = 0; e < c; ++e) start += n[e];
    const uint32_t total = n[0] + n[1] + n[2];
    return (start + k) % total;  // corner 3 is corner 0
}

DomainTriangulation triangulateDomain(const uint32_t n[3], uint32_t level) {
    DomainTriangulation d;
    const double corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    // Step: boundary points, edge by edge.
    for (int c = 0; c < 3; ++c) {
        const double* a = corner[c];
        const double* b = corner[(c + 1) % 3];
        for (uint32_t k = 0; k < n[c]; ++k) {
            const double s = double(k) / n[c];
            d.points.push_back({a[0] + (b[0] - a[0]) * s, a[1] + (b[1] - a[1]) * s});
        }
    }
    d.boundary_count = d.points.size();

    // Step: the inner lattice (i, j >= 1, i + j <= N - 1), indexed by (i, j).
    const uint32_t N = level;
    std::vector<uint32_t> lattice(size_t(N + 1) * (N + 1), UINT32_MAX);
    auto at = [&](uint32_t i, uint32_t j) -> uint32_t& { return lattice[size_t(i) * (N + 1) + j]; };
    for (uint32_t i = 1; i + 1 < N; ++i)
        for (uint32_t j = 1; i + j + 1 <= N; ++j) {
            at(i, j) = uint32_t(d.points.size());
            d.points.push_back({double(i) / N, double(j) / N});
        }

    // Step: regular triangles of the inner lattice.
    for (uint32_t i = 1; i + 1 < N; ++i)
        for (uint32_t j = 1; i + j + 2 <= N; ++j) {
            d.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
            if (i + j + 3 <= N) d.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
        }

    // Step: the ring, one zipper per side. t is the position along the side, in [0, 1].
    for (int c = 0; c < 3; ++c) {
        std::vector<uint32_t> inner;
        std::vector<double> inner_t;
        for (uint32_t k = 1; k + 1 < N; ++k) {
            // Inner chain of side c, from its inner corner c towards inner corner c + 1.
            uint32_t i, j;
            double t;
            if (c == 0) { i = k; j = 1; t = double(i) / N; }               // row v = 1/N, t = u
            else if (c == 1) { i = N - 1 - k; j = k; t = double(j) / N; }  // row u + v = (N-1)/N, t = v
            else { i = 1; j = N - 1 - k; t = 1.0 - double(j) / N; }        // row u = 1/N, t = 1 - v
            inner.push_back(at(i, j));
            inner_t.push_back(t);
        }
        size_t a = 0, b = 0;  // next outer point index (0..n[c]) and inner index
        while (a < n[c] || b + 1 < inner.size()) {
            const bool can_outer = a < n[c], can_inner = b + 1 < inner.size();
            const double outer_next = can_outer ? double(a + 1) / n[c] : 2.0;
            const double inner_next = can_inner ? inner_t[b + 1] : 2.0;
            if (can_outer && (!can_inner || outer_next <= inner_next)) {
                d.triangles.push_back({boundaryIndex(n, c, uint32_t(a)), boundaryIndex(n, c, uint32_t(a + 1)), inner[b]});
                ++a;
            } else {
                d.triangles.push_back({boundaryIndex(n, c, uint32_t(a)), inner[b + 1], inner[b]});
                ++b;
            }
        }
    }
    return d;
}

}  // namespace mesh4d
