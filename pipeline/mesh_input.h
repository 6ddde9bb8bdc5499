// What reading a mesh file yields, whatever its format, and the limits on what a file may ask for.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesh4d/extrude.h"
#include "pipeline/status.h"

namespace apparent {

struct MeshWarnings {
    size_t polygons_triangulated = 0;   // OBJ faces with more than 3 vertices
    size_t degenerate_dropped = 0;      // faces with a repeated index or zero area
    size_t nonmanifold_split = 0;       // OBJ faces OpenMesh had to give their own vertices
    size_t strips_fans_triangulated = 0;  // glTF TRIANGLE_STRIP / TRIANGLE_FAN primitives
    size_t points_lines_skipped = 0;    // glTF POINTS / LINES / LINE_LOOP / LINE_STRIP primitives
    std::vector<std::string> other;     // tinygltf's warnings, verbatim
    std::vector<std::string> lines() const;  // human-readable, one per non-zero count
};

struct MeshLimits {
    size_t max_vertices = 50'000'000;
    size_t max_faces = 50'000'000;
    size_t max_file_bytes = size_t(2) << 30;  // any one file a mesh reads (glTF buffers included)
};

struct LoadedMesh {
    mesh4d::RestMesh mesh;
    bool has_color = false;               // the file gave a base colour (glTF material)
    std::array<double, 4> color{1, 1, 1, 1};
};

// Reads an OBJ (.obj), glTF (.gltf) or binary glTF (.glb) file; a glTF path may end in
// "#NodeName" to read only that node's subtree. Dispatches on the extension.
Status readMesh(const std::string& path, const MeshLimits& limits, LoadedMesh* out, MeshWarnings* warnings);

}  // namespace apparent
