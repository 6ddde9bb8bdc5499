// What reading a mesh file yields, whatever its format, and the limits on what a file may ask for.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "exporters/surface_look.h"
#include "mesh4d/extrude.h"
#include "pipeline/input/status.h"

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
    size_t max_vertices = 10'000'000;
    size_t max_faces = 10'000'000;
    size_t max_file_bytes = size_t(2) << 30;  // any one file a mesh reads (glTF buffers included)
    // Scene mesh paths must resolve (".." and symlinks followed) inside the scene file's folder or
    // the current working folder, unless this is set (--allow-outside). glTF buffer URIs stay
    // confined to the glTF file's folder either way.
    bool allow_outside = false;
    // The scene file naming the mesh: an OBJ's material libraries and textures may also lie in its
    // folder (empty: only the OBJ's folder and the working folder; pipeline/obj_reader.h).
    std::string scene_path;
};

struct LoadedMesh {
    mesh4d::RestMesh mesh;
    bool has_color = false;               // the file gave a base colour (glTF material)
    std::array<double, 4> color{1, 1, 1, 1};
    // Texture coordinates, vertex colours and materials (glTF, OBJ and PLY inputs; null: none), parallel to
    // `mesh`'s vertices and triangles.
    std::shared_ptr<const SurfaceLook> look;
};

// Reads an OBJ (.obj), PLY (.ply), glTF (.gltf) or binary glTF (.glb) file; a glTF path may end in
// "#NodeName" to read only that node's subtree. Dispatches on the extension.
Status readMesh(const std::string& path, const MeshLimits& limits, LoadedMesh* out, MeshWarnings* warnings);

// Succeeds when `mesh_path` (resolved, optionally "file.glb#Node") lies inside the folder of
// `scene_path` or inside the current working folder, after resolving ".." and symlinks
// (std::filesystem::weakly_canonical). Otherwise fails with
// "scene.json: objects[2].mesh: "../x.obj" is outside the scene's folder and the working folder (allow with --allow-outside)",
// quoting `mesh_text` (the field as written) at `field` (such as "objects[2].mesh").
Status checkMeshInside(const std::string& scene_path, const std::string& field, const std::string& mesh_text,
                       const std::string& mesh_path);

}  // namespace apparent
