// What the OBJ and PLY readers share: the vertices and faces their own single-pass scanners read
// and checked, turned into a RestMesh exactly as OpenMesh's importer would build it, without
// paying for OpenMesh's half-edge construction when it would change nothing.
//
// OpenMesh (OpenMesh::IO::ImporterT) adds faces one by one; a face that would make an edge or a
// vertex non-manifold gets copies of its vertices (appended after the file's vertices). When the
// triangles already form an oriented manifold (every directed edge used once, the triangles
// around each vertex one fan), OpenMesh adds every face as given, so the scanned mesh is kept
// as is. Otherwise the scanned vertices and faces are replayed through OpenMesh's importer and
// its result taken, with the vertices it had to copy counted as a warning. Either way
// positions stay double, as the scanners parsed them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "mesh4d/extrude.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/status.h"

namespace apparent {

// What a scanner read, in file order.
struct ScannedMesh {
    // Positions as parsed; faces fan-triangulated about their first corner, (v0, v[k], v[k+1]),
    // as OpenMesh's triangle mesh does; faces with a repeated index already left out.
    mesh4d::RestMesh mesh;
    // Faces with more than 3 corners: (first triangle, corner count), in order.
    std::vector<std::pair<uint32_t, uint32_t>> polygons;
    size_t repeated_index = 0;  // faces left out for a repeated index (OpenMesh drops them too)
    std::vector<std::string> warnings;  // the scanner's own, for MeshWarnings::other
};

// True when OpenMesh's importer would add every triangle of `mesh` as it is: each directed edge
// occurs at most once and the triangles around each vertex form a single fan (open or closed).
// Linear in the number of triangles (a few small sorts per vertex).
bool addsAsGiven(const mesh4d::RestMesh& mesh);

// The RestMesh of a scanned file: `scan` as is when addsAsGiven, else OpenMesh's importer's result
// (non-manifold faces given their own vertices: counted; faces it could not add at all: refused,
// "mesh.obj: OpenMesh dropped 2 of 10 triangles (malformed faces)"). Then zero-area triangles are
// dropped with CGAL's exact predicate and counted; none left is an error. `per_triangle` (one value
// per scanned triangle), when given, follows the triangles kept: each triangle OpenMesh made gets
// the value of the scanned triangle it is (a polygon OpenMesh adds twice, partly and then on copies,
// gives two triangles the same value).
Status finishScannedMesh(ScannedMesh&& scan, const std::string& path, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
                         std::vector<int>* per_triangle = nullptr);

// A vertex of finishScannedMesh's result that no scanned vertex gives (scannedVertexOf).
constexpr uint32_t kNoOrigin = UINT32_MAX;

// The scanned vertex each vertex of `mesh` is or copies, so that per-vertex attributes follow the
// vertices OpenMesh copies. `mesh` is finishScannedMesh's result for the scanned `triangles` of
// `scanned_vertices` vertices, `per_triangle` (as finishScannedMesh left it) the scanned triangle
// each of its triangles came from. The file's vertices are themselves; a copy is found by its
// triangle's corners (the scanned triangle's corners at equal positions, in one of its three
// rotations). A copy no triangle uses (OpenMesh copies the corners of a face it cannot add, and that
// face may then be dropped) is kNoOrigin: its attributes are never read.
std::vector<uint32_t> scannedVertexOf(const mesh4d::RestMesh& mesh, const std::vector<std::array<uint32_t, 3>>& triangles,
                                      size_t scanned_vertices, const std::vector<int>& per_triangle);

// finishScannedMesh for a reader whose look follows the mesh OpenMesh makes: also where each
// resulting triangle came from (`triangle_origin`, the scanned triangle) and each vertex
// (`vertex_origin`, scannedVertexOf).
Status finishScannedMeshTraced(ScannedMesh&& scan, const std::string& path, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
                               std::vector<int>* triangle_origin, std::vector<uint32_t>* vertex_origin);

// A texture coordinate index no corner has (splitAtTextureSeams).
constexpr uint32_t kNoTexcoord = UINT32_MAX;

// Texture coordinates given per face corner (an OBJ's `vt` indices, a PLY's `texcoord` lists) made
// per vertex, as a glTF file gives them. `uv` holds the file's (u, v) pairs, `corner_uv` each of
// scan's triangles' three indices into them (kNoTexcoord: none, written as (0, 0)); indices of
// equal pairs are first made one. A vertex whose corners carry different coordinates keeps the
// first one met (triangles in order, corners in order) and gets one copy of its position (exactly,
// appended after the vertices) for each other coordinate, those corners renumbered to it, as a
// glTF file splits its vertices at seams. Fills `texcoord` per vertex with glTF's (u, 1 - v) (the
// files' v axis points up, glTF's down) and `copied_from` with the vertex each copy copies (in the
// order appended). Refused, "mesh.obj: more than N vertices once split at texture seams", when the
// copies pass limits.max_vertices. `corner_uv` is rewritten.
Status splitAtTextureSeams(const std::string& path, const MeshLimits& limits, const std::vector<double>& uv,
                           std::vector<std::array<uint32_t, 3>>* corner_uv, ScannedMesh* scan, std::vector<double>* texcoord,
                           std::vector<uint32_t>* copied_from);

}  // namespace apparent
