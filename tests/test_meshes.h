// Small meshes built in code for the tests: an icosphere, a torus, a cylinder, a thin rod.
#pragma once

#include <cmath>
#include <map>

#include "mesh4d/extrude.h"
#include "mesh4d/slice.h"

namespace testmesh {

using mesh4d::RestMesh;
using mesh4d::Vec3;

// Icosahedron subdivided `levels` times, projected on a sphere of radius r (closed, genus 0).
// The cube of edge 1 centred at the origin, each face two triangles, outward.
inline RestMesh unitBox() {
    RestMesh box;
    for (int i = 0; i < 8; ++i) box.positions.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
    const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        box.triangles.push_back({q[0], q[1], q[2]});
        box.triangles.push_back({q[0], q[2], q[3]});
    }
    return box;
}

inline RestMesh icosphere(int levels, double r) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    RestMesh m;
    m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                   {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            m.positions.push_back((m.positions[a] + m.positions[b]) * 0.5);
            return mid[key] = uint32_t(m.positions.size() - 1);
        };
        std::vector<std::array<uint32_t, 3>> next;
        for (const auto& f : m.triangles) {
            const uint32_t a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
            next.push_back({f[0], a, c});
            next.push_back({f[1], b, a});
            next.push_back({f[2], c, b});
            next.push_back({a, b, c});
        }
        m.triangles = next;
    }
    for (auto& p : m.positions) p = p * (r / mesh4d::norm(p));
    return m;
}

// Torus of major radius R and minor radius r about the y axis (closed, genus 1).
inline RestMesh torus(int nu, int nv, double R, double r) {
    RestMesh m;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double u = 2 * pi * i / nu, v = 2 * pi * j / nv;
            m.positions.push_back({(R + r * std::cos(v)) * std::cos(u), r * std::sin(v), (R + r * std::cos(v)) * std::sin(u)});
        }
    auto id = [&](int i, int j) { return uint32_t(((i + nu) % nu) * nv + (j + nv) % nv); };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            m.triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j)});
            m.triangles.push_back({id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)});
        }
    return m;
}

// A closed cylinder of radius r about z, z in [-h, h], n segments: rings at -h and h, two hub
// vertices. Vertex 0 is at angle 0 on the ring z = -h ... the ring z = h starts at n; the hubs
// are vertices 2n (z = -h) and 2n + 1 (z = h).
inline RestMesh cylinder(double r, double h, int n) {
    const double pi = 3.14159265358979323846;
    RestMesh m;
    for (double z : {-h, h})
        for (int k = 0; k < n; ++k) {
            const double a = 2 * pi * k / n;
            m.positions.push_back({r * std::cos(a), r * std::sin(a), z});
        }
    const uint32_t hub_lo = uint32_t(m.positions.size());
    m.positions.push_back({0, 0, -h});
    m.positions.push_back({0, 0, h});
    for (uint32_t k = 0; k < uint32_t(n); ++k) {
        const uint32_t j = (k + 1) % n;
        m.triangles.push_back({k, j + n, k + n});
        m.triangles.push_back({k, j, j + n});
        m.triangles.push_back({hub_lo, j, k});
        m.triangles.push_back({hub_lo + 1, k + n, j + n});
    }
    return m;
}

// A thin rod along z from z = 0 to z = -L: one sliver triangle whose first two vertices are the
// rod's ends (on the z axis) and whose third sits `width` off the axis at the far end.
inline RestMesh rod(double L, double width) {
    RestMesh m;
    m.positions = {{0, 0, 0}, {0, 0, -L}, {width, 0, -L}};
    m.triangles = {{0, 1, 2}};
    return m;
}

// sliceWorld's output with absolute lab positions and emission times (origin 0), for tests that
// compare with lab-frame closed forms. Fine for scenes near the origin; the stress tests use the
// local coordinates instead.
inline mesh4d::ApparentMesh sliceAbsolute(const mesh4d::World4D& w, const mesh4d::ViewSurface& view,
                                          const mesh4d::SliceSettings& s = {}) {
    mesh4d::ApparentMesh m = mesh4d::sliceWorld(w, view, s);
    for (size_t i = 0; i < m.positions.size(); ++i) {
        m.positions[i] = m.absolutePosition(i);
        m.emission_times[i] = m.absoluteTime(i);
    }
    m.origin = {0, 0, 0};
    m.time_origin = 0;
    return m;
}

}  // namespace testmesh
