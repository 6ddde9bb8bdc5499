#include "pipeline/input/polygon_input.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>

#include <OpenMesh/Core/IO/importer/ImporterT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "pipeline/input/mesh_check.h"

namespace apparent {

namespace {

struct DoubleTraits : OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<DoubleTraits> ImportMesh;

// One corner's view of its triangle: the edge opposite the corner, in the triangle's orientation.
struct LinkEdge {
    uint32_t from, to;
};

// The link edges around one vertex form a single path or a single cycle, every `from` and every
// `to` distinct (each directed mesh edge at the vertex used once). Sorts `link` by `from`.
bool singleFan(LinkEdge* link, size_t n, std::vector<uint32_t>* tos) {
    if (n <= 1) return true;
    std::sort(link, link + n, [](const LinkEdge& a, const LinkEdge& b) { return a.from < b.from; });
    tos->resize(n);
    for (size_t i = 0; i < n; ++i) (*tos)[i] = link[i].to;
    std::sort(tos->begin(), tos->end());
    for (size_t i = 1; i < n; ++i)
        if (link[i].from == link[i - 1].from || (*tos)[i] == (*tos)[i - 1]) return false;
    // A path starts at a `from` that is no edge's `to`; with distinct ends there is at most one
    // such start in a single fan, none in a closed one.
    size_t start = n;
    for (size_t i = 0; i < n; ++i)
        if (!std::binary_search(tos->begin(), tos->end(), link[i].from)) {
            if (start != n) return false;
            start = i;
        }
    if (start == n) start = 0;
    // Walk from the start; the fan is single when the walk covers every edge.
    size_t steps = 0, at = start;
    for (;;) {
        ++steps;
        const uint32_t next = link[at].to;
        const LinkEdge* it = std::lower_bound(link, link + n, next, [](const LinkEdge& e, uint32_t v) { return e.from < v; });
        if (it == link + n || it->from != next || size_t(it - link) == start) break;
        at = size_t(it - link);
        if (steps > n) return false;
    }
    return steps == n;
}

// The scanned faces through OpenMesh's importer, as its OBJ and PLY readers add them; `from` gets
// the scanned triangle each triangle of `out` is. OpenMesh triangulates a polygon as a fan and, when
// the last fan triangle cannot be added, adds the whole polygon again on copies of its corners,
// keeping the triangles it did add: a polygon may give more triangles than its fan. Each triangle
// is therefore matched to its polygon's fan triangle of the same corners (copies read as the
// corners they copy, in one of the three rotations).
void importWithOpenMesh(const ScannedMesh& scan, mesh4d::RestMesh* out, std::vector<uint32_t>* from) {
    omerr().disable();
    omlog().disable();
    ImportMesh om;
    OpenMesh::IO::ImporterT<ImportMesh> importer(om);
    const auto& positions = scan.mesh.positions;
    const auto& triangles = scan.mesh.triangles;
    om.reserve(positions.size(), 3 * triangles.size(), triangles.size());
    for (const auto& p : positions) importer.add_vertex(OpenMesh::Vec3d(p.x, p.y, p.z));
    std::vector<OpenMesh::VertexHandle> face;
    std::vector<uint32_t> copy_of;  // per vertex OpenMesh appends: the file vertex it copies
    auto fileVertex = [&](int v) { return size_t(v) < positions.size() ? uint32_t(v) : copy_of[size_t(v) - positions.size()]; };
    from->clear();
    size_t next_polygon = 0;
    for (size_t f = 0; f < triangles.size();) {
        face.clear();
        size_t corners = 3;
        if (next_polygon < scan.polygons.size() && scan.polygons[next_polygon].first == f)
            corners = scan.polygons[next_polygon++].second;
        // A fan (v0, v[k], v[k+1]) gives back the polygon's corners in order.
        face.emplace_back(int(triangles[f][0]));
        face.emplace_back(int(triangles[f][1]));
        for (size_t k = 0; k + 2 < corners; ++k) face.emplace_back(int(triangles[f + k][2]));
        const size_t vertices_before = om.n_vertices(), faces_before = om.n_faces();
        importer.add_face(face);
        // Step: the copies it made (of the face's corners, in order), then each new triangle's fan triangle.
        for (size_t v = vertices_before; v < om.n_vertices(); ++v)
            copy_of.push_back(uint32_t(face[std::min(v - vertices_before, face.size() - 1)].idx()));
        for (size_t k = faces_before; k < om.n_faces(); ++k) {
            std::array<uint32_t, 3> corner{};
            int c = 0;
            for (auto v : om.fv_range(OpenMesh::FaceHandle(int(k))))
                if (c < 3) corner[size_t(c++)] = fileVertex(v.idx());
            uint32_t match = uint32_t(f);
            for (size_t t = f; t < f + corners - 2 && match == uint32_t(f); ++t)
                for (int r = 0; r < 3; ++r)
                    if (corner[0] == triangles[t][size_t(r)] && corner[1] == triangles[t][size_t((r + 1) % 3)] &&
                        corner[2] == triangles[t][size_t((r + 2) % 3)]) {
                        match = uint32_t(t);
                        break;
                    }
            from->push_back(match);
        }
        f += corners - 2;
    }
    out->positions.clear();
    out->triangles.clear();
    out->positions.reserve(om.n_vertices());
    for (auto v : om.vertices()) {
        const auto& p = om.point(v);
        out->positions.push_back({p[0], p[1], p[2]});
    }
    out->triangles.reserve(om.n_faces());
    for (auto f : om.faces()) {
        std::array<uint32_t, 3> tri{};
        int c = 0;
        for (auto v : om.fv_range(f))
            if (c < 3) tri[c++] = uint32_t(v.idx());
        out->triangles.push_back(tri);
    }
}

}  // namespace

bool addsAsGiven(const mesh4d::RestMesh& mesh) {
    const size_t nv = mesh.positions.size();
    // Step: the link edges of every vertex, grouped by vertex (counting sort).
    std::vector<uint32_t> offset(nv + 1, 0);
    for (const auto& t : mesh.triangles)
        for (uint32_t v : t) ++offset[v + 1];
    for (size_t v = 0; v < nv; ++v) offset[v + 1] += offset[v];
    std::vector<LinkEdge> link(offset[nv]);
    {
        std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
        for (const auto& t : mesh.triangles)
            for (int c = 0; c < 3; ++c) link[fill[t[c]]++] = {t[(c + 1) % 3], t[(c + 2) % 3]};
    }
    // Step: one fan per vertex.
    std::vector<uint32_t> tos;
    for (size_t v = 0; v < nv; ++v)
        if (!singleFan(link.data() + offset[v], offset[v + 1] - offset[v], &tos)) return false;
    return true;
}

Status finishScannedMesh(ScannedMesh&& scan, const std::string& path, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
                         std::vector<int>* per_triangle) {
    const size_t file_vertices = scan.mesh.positions.size();
    const size_t scanned_triangles = scan.mesh.triangles.size();
    warnings->polygons_triangulated += scan.polygons.size();
    warnings->degenerate_dropped += scan.repeated_index;
    warnings->other.insert(warnings->other.end(), scan.warnings.begin(), scan.warnings.end());
    if (addsAsGiven(scan.mesh)) {
        *mesh = std::move(scan.mesh);
    } else {
        std::vector<uint32_t> from;
        importWithOpenMesh(scan, mesh, &from);
        if (per_triangle) {
            std::vector<int> kept(from.size());
            for (size_t t = 0; t < from.size(); ++t) kept[t] = (*per_triangle)[from[t]];
            *per_triangle = std::move(kept);
        }
        for (const auto& tri : mesh->triangles)
            if (tri[0] >= file_vertices || tri[1] >= file_vertices || tri[2] >= file_vertices) ++warnings->nonmanifold_split;
        if (mesh->triangles.size() < scanned_triangles)
            return Status::failure(path + ": OpenMesh dropped " + std::to_string(scanned_triangles - mesh->triangles.size()) +
                                   " of " + std::to_string(scanned_triangles) + " triangles (malformed faces)");
    }
    warnings->degenerate_dropped += dropDegenerateTriangles(mesh, per_triangle);
    if (mesh->triangles.empty()) return Status::failure(path + ": every triangle is degenerate (zero area)");
    return Status::success();
}

std::vector<uint32_t> scannedVertexOf(const mesh4d::RestMesh& mesh, const std::vector<std::array<uint32_t, 3>>& triangles,
                                      size_t scanned_vertices, const std::vector<int>& per_triangle) {
    std::vector<uint32_t> origin(mesh.positions.size(), kNoOrigin);
    std::iota(origin.begin(), origin.begin() + std::ptrdiff_t(std::min(scanned_vertices, origin.size())), 0u);
    if (mesh.positions.size() > scanned_vertices)
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            const auto& out = mesh.triangles[t];
            const auto& in = triangles[size_t(per_triangle[t])];
            for (int r = 0; r < 3; ++r) {
                bool same = true;
                for (int c = 0; c < 3 && same; ++c) {
                    const mesh4d::Vec3& a = mesh.positions[out[size_t(c)]];
                    const mesh4d::Vec3& b = mesh.positions[in[size_t((c + r) % 3)]];
                    same = a.x == b.x && a.y == b.y && a.z == b.z;
                }
                if (!same) continue;
                for (int c = 0; c < 3; ++c)
                    if (out[size_t(c)] >= scanned_vertices) origin[out[size_t(c)]] = in[size_t((c + r) % 3)];
                break;
            }
        }
    return origin;
}

Status finishScannedMeshTraced(ScannedMesh&& scan, const std::string& path, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
                               std::vector<int>* triangle_origin, std::vector<uint32_t>* vertex_origin) {
    const std::vector<std::array<uint32_t, 3>> scanned = scan.mesh.triangles;
    const size_t scanned_vertices = scan.mesh.positions.size();
    triangle_origin->resize(scanned.size());
    std::iota(triangle_origin->begin(), triangle_origin->end(), 0);
    if (Status s = finishScannedMesh(std::move(scan), path, mesh, warnings, triangle_origin); !s.ok) return s;
    *vertex_origin = scannedVertexOf(*mesh, scanned, scanned_vertices, *triangle_origin);
    return Status::success();
}

Status splitAtTextureSeams(const std::string& path, const MeshLimits& limits, const std::vector<double>& uv,
                           std::vector<std::array<uint32_t, 3>>* corner_uv, ScannedMesh* scan, std::vector<double>* texcoord,
                           std::vector<uint32_t>* copied_from) {
    // Step: equal (u, v) pairs written twice are one texture coordinate: each index to its first
    // (sorted by value, then index, so each run of equal pairs starts at its first).
    const size_t uv_count = uv.size() / 2;
    std::vector<uint32_t> order(uv_count), same(uv_count);
    std::iota(order.begin(), order.end(), 0u);
    auto less = [&](uint32_t a, uint32_t b) {
        if (uv[2 * a] != uv[2 * b]) return uv[2 * a] < uv[2 * b];
        if (uv[2 * a + 1] != uv[2 * b + 1]) return uv[2 * a + 1] < uv[2 * b + 1];
        return a < b;
    };
    std::sort(order.begin(), order.end(), less);
    for (size_t i = 0; i < uv_count; ++i) {
        const uint32_t k = order[i];
        const bool run_start = i == 0 || uv[2 * k] != uv[2 * order[i - 1]] || uv[2 * k + 1] != uv[2 * order[i - 1] + 1];
        same[k] = run_start ? k : same[order[i - 1]];
    }
    for (auto& corners : *corner_uv)
        for (uint32_t& t : corners)
            if (t != kNoTexcoord) t = same[t];
    // Step: a vertex keeps its first coordinate, a copy for each other one.
    auto& positions = scan->mesh.positions;
    const size_t file_vertices = positions.size();
    std::vector<uint32_t> uv_of(file_vertices, kNoTexcoord);
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> split;
    std::vector<uint32_t> copy_uv;
    copied_from->clear();
    for (size_t t = 0; t < scan->mesh.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c) {
            uint32_t& v = scan->mesh.triangles[t][size_t(c)];
            const uint32_t k = (*corner_uv)[t][size_t(c)];
            if (uv_of[v] == kNoTexcoord) uv_of[v] = k;
            if (uv_of[v] == k) continue;
            auto [it, fresh] = split.try_emplace({v, k}, uint32_t(positions.size()));
            if (fresh) {
                if (positions.size() >= limits.max_vertices)
                    return Status::failure(path + ": more than " + std::to_string(limits.max_vertices) +
                                           " vertices once split at texture seams (raise with --max-vertices)");
                positions.push_back(positions[v]);
                copy_uv.push_back(k);
                copied_from->push_back(v);
            }
            v = it->second;
        }
    // Step: the coordinates per vertex, v flipped for glTF.
    uv_of.insert(uv_of.end(), copy_uv.begin(), copy_uv.end());
    texcoord->assign(2 * positions.size(), 0.0);
    for (size_t v = 0; v < positions.size(); ++v)
        if (uv_of[v] != kNoTexcoord) {
            (*texcoord)[2 * v] = uv[2 * size_t(uv_of[v])];
            (*texcoord)[2 * v + 1] = 1 - uv[2 * size_t(uv_of[v]) + 1];
        }
    return Status::success();
}

}  // namespace apparent
