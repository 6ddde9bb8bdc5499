#include "pipeline/input/mesh_check.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

namespace apparent {

namespace {
typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef K::Point_3 Point;
typedef CGAL::Surface_mesh<Point> SurfaceMesh;
namespace PMP = CGAL::Polygon_mesh_processing;

Point toPoint(const mesh4d::Vec3& v) { return Point(v.x, v.y, v.z); }
}  // namespace

size_t dropDegenerateTriangles(mesh4d::RestMesh* mesh, std::vector<int>* per_triangle) {
    size_t kept = 0;
    const size_t before = mesh->triangles.size();
    const bool follow = per_triangle && per_triangle->size() == before;
    for (size_t f = 0; f < before; ++f) {
        const auto& t = mesh->triangles[f];
        if (CGAL::collinear(toPoint(mesh->positions[t[0]]), toPoint(mesh->positions[t[1]]),
                            toPoint(mesh->positions[t[2]])))
            continue;
        if (follow) (*per_triangle)[kept] = (*per_triangle)[f];
        mesh->triangles[kept++] = t;
    }
    mesh->triangles.resize(kept);
    if (follow) per_triangle->resize(kept);
    return before - kept;
}

Topology analyzeTopology(const std::vector<mesh4d::Vec3>& positions,
                         const std::vector<std::array<uint32_t, 3>>& triangles) {
    Topology topo;
    topo.faces = triangles.size();
    if (triangles.empty()) return topo;

    // Step: compact to the referenced vertices (the soup functions want every point used).
    std::vector<uint32_t> remap(positions.size(), UINT32_MAX);
    std::vector<Point> points;
    std::vector<std::array<size_t, 3>> polygons;
    polygons.reserve(triangles.size());
    for (const auto& t : triangles) {
        std::array<size_t, 3> p{};
        for (int c = 0; c < 3; ++c) {
            if (remap[t[c]] == UINT32_MAX) {
                remap[t[c]] = uint32_t(points.size());
                points.push_back(toPoint(positions[t[c]]));
            }
            p[c] = remap[t[c]];
        }
        polygons.push_back(p);
    }
    topo.vertices = points.size();

    // Step: edges, counted on the soup so that non-manifold input is measured too.
    std::vector<std::pair<size_t, size_t>> edges;
    edges.reserve(3 * polygons.size());
    for (const auto& p : polygons)
        for (int c = 0; c < 3; ++c) edges.emplace_back(std::min(p[c], p[(c + 1) % 3]), std::max(p[c], p[(c + 1) % 3]));
    std::sort(edges.begin(), edges.end());
    topo.edges = size_t(std::unique(edges.begin(), edges.end()) - edges.begin());
    topo.euler = long(topo.vertices) - long(topo.edges) + long(topo.faces);

    // Step: manifoldness and the rest, on a CGAL surface mesh.
    topo.manifold = PMP::is_polygon_soup_a_polygon_mesh(polygons);
    if (!topo.manifold) return topo;
    SurfaceMesh sm;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
    topo.closed = CGAL::is_closed(sm);
    auto fccmap = sm.add_property_map<SurfaceMesh::Face_index, std::size_t>("f:cc").first;
    topo.components = PMP::connected_components(sm, fccmap);
    std::vector<SurfaceMesh::Halfedge_index> cycles;
    PMP::extract_boundary_cycles(sm, std::back_inserter(cycles));
    topo.boundary_loops = cycles.size();
    if (topo.closed) topo.genus = (2 * long(topo.components) - topo.euler) / 2;
    return topo;
}

}  // namespace apparent
