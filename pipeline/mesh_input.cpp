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
    // A node name follows the last '#' (names of object nodes cannot contain one; folders may).
    const auto hash = path.rfind('#');
    const std::string file = path.substr(0, hash);
    std::string ext = file.substr(file.find_last_of('.') == std::string::npos ? file.size() : file.find_last_of('.'));
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".gltf" || ext == ".glb") return readGltf(path, limits, out, warnings);
    if (hash != std::string::npos) {
        // No glTF before the '#': the '#' is part of an OBJ's own path.
        std::string whole = path.substr(path.find_last_of('.') == std::string::npos ? path.size() : path.find_last_of('.'));
        for (char& c : whole) c = char(std::tolower((unsigned char)c));
        if (whole == ".obj") return readObj(path, limits, &out->mesh, warnings);
        return Status::failure(path + ": '#NodeName' selects a node of a glTF file only");
    }
    if (ext == ".obj") return readObj(path, limits, &out->mesh, warnings);
    return Status::failure(path + ": unknown mesh format '" + ext + "' (use .obj, .gltf or .glb)");
}

}  // namespace apparent
