#include "pipeline/mesh_input.h"

#include <algorithm>
#include <cctype>

#include "pipeline/gltf_reader.h"
#include "pipeline/obj_reader.h"

namespace apparent {

std::vector<std::string> MeshWarnings::lines() const {
    std::vector<std::string> out;
    if (polygons_triangulated) out.push_back(std::to_string(polygons_triangulated) + " polygons triangulated");
    if (degenerate_dropped) out.push_back(std::to_string(degenerate_dropped) + " degenerate triangles dropped");
    if (nonmanifold_split)
        out.push_back(std::to_string(nonmanifold_split) + " non-manifold faces given their own vertices");
    if (strips_fans_triangulated)
        out.push_back(std::to_string(strips_fans_triangulated) + " triangle strips or fans triangulated");
    if (points_lines_skipped)
        out.push_back(std::to_string(points_lines_skipped) + " point or line primitives skipped (no surface)");
    for (const auto& w : other) out.push_back(w);
    return out;
}

Status readMesh(const std::string& path, const MeshLimits& limits, LoadedMesh* out, MeshWarnings* warnings) {
    const std::string file = path.substr(0, path.find('#'));
    std::string ext = file.substr(file.find_last_of('.') == std::string::npos ? file.size() : file.find_last_of('.'));
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".gltf" || ext == ".glb") return readGltf(path, limits, out, warnings);
    if (path.find('#') != std::string::npos)
        return Status::failure(path + ": '#NodeName' selects a node of a glTF file only");
    if (ext == ".obj") return readObj(path, limits, &out->mesh, warnings);
    return Status::failure(path + ": unknown mesh format '" + ext + "' (use .obj, .gltf or .glb)");
}

}  // namespace apparent
