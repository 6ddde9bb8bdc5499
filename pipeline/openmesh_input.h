// What the OBJ and PLY readers share once OpenMesh has read a file that our own scan checked first:
// the double-precision OpenMesh mesh type, and turning its result into a RestMesh with what
// OpenMesh changed counted as warnings (or refused, when it dropped faces).
#pragma once

#include <array>
#include <cmath>
#include <streambuf>
#include <string>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "pipeline/mesh_check.h"
#include "pipeline/mesh_input.h"

namespace apparent {

// An istream over bytes in memory, without copying them: OpenMesh reads the bytes our scan
// checked, never the path a second time.
// Seekable: OpenMesh's OBJ reader reads the text twice (vertices, then faces).
struct MemoryBuffer : std::streambuf {
    explicit MemoryBuffer(std::string& text) { setg(&text[0], &text[0], &text[0] + text.size()); }

protected:
    pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
        const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? gptr() - eback() : egptr() - eback();
        const off_type to = base + off;
        if (to < 0 || to > egptr() - eback()) return pos_type(off_type(-1));
        setg(eback(), eback() + to, egptr());
        return pos_type(to);
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode mode) override {
        return seekoff(off_type(pos), std::ios_base::beg, mode);
    }
};

struct OpenMeshDoubleTraits : OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<OpenMeshDoubleTraits> InputTriMesh;

// What the scan of the file counted before OpenMesh read it.
struct ScannedCounts {
    size_t vertices = 0;        // vertices the file declares
    size_t triangles = 0;       // triangles its faces give after fan triangulation
    size_t polygons = 0;        // faces with more than 3 vertices
    size_t repeated_index = 0;  // faces dropped for a repeated index
};

// Copies `om` into `mesh`. OpenMesh gives a face that would make an edge non-manifold copies of its
// vertices (so the vertex count grows: counted), and drops faces it cannot add at all (refused).
// Then zero-area triangles are dropped with CGAL's exact predicate and counted.
inline Status takeOpenMeshResult(const InputTriMesh& om, const ScannedCounts& scan, const std::string& path,
                                 mesh4d::RestMesh* mesh, MeshWarnings* warnings) {
    mesh->positions.clear();
    mesh->triangles.clear();
    mesh->positions.reserve(om.n_vertices());
    for (auto v : om.vertices()) {
        const auto& p = om.point(v);
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            return Status::failure(path + ": vertex[" + std::to_string(v.idx()) + "]: not finite after reading");
        mesh->positions.push_back({p[0], p[1], p[2]});
    }
    for (auto f : om.faces()) {
        std::array<uint32_t, 3> tri{};
        int c = 0;
        for (auto v : om.fv_range(f))
            if (c < 3) tri[c++] = uint32_t(v.idx());
        mesh->triangles.push_back(tri);
    }
    warnings->polygons_triangulated += scan.polygons;
    warnings->degenerate_dropped += scan.repeated_index;
    for (const auto& tri : mesh->triangles)
        if (tri[0] >= scan.vertices || tri[1] >= scan.vertices || tri[2] >= scan.vertices) ++warnings->nonmanifold_split;
    if (mesh->triangles.size() < scan.triangles)
        return Status::failure(path + ": OpenMesh dropped " + std::to_string(scan.triangles - mesh->triangles.size()) +
                               " of " + std::to_string(scan.triangles) + " triangles (malformed faces)");
    warnings->degenerate_dropped += dropDegenerateTriangles(mesh);
    if (mesh->triangles.empty()) return Status::failure(path + ": every triangle is degenerate (zero area)");
    return Status::success();
}

}  // namespace apparent
