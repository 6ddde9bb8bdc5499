#include "pipeline/input/mesh_input.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "pipeline/input/gltf_reader.h"
#if !defined(APPARENT_NO_OPENMESH)
#include "pipeline/input/obj_reader.h"
#include "pipeline/input/ply_reader.h"
#endif

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
#if defined(APPARENT_NO_OPENMESH)
    // A build without OpenMesh (the WebAssembly module) reads glTF meshes only.
    return Status::failure(path + ": only glTF meshes (.gltf, .glb) are read by this build (the WebAssembly module); "
                                  "write the scene's web file with 'apparent render SCENE --format web'");
#else
    if (hash != std::string::npos) {
        // No glTF before the '#': the '#' is part of an OBJ's own path.
        std::string whole = path.substr(path.find_last_of('.') == std::string::npos ? path.size() : path.find_last_of('.'));
        for (char& c : whole) c = char(std::tolower((unsigned char)c));
        if (whole == ".obj") return readObj(path, limits, &out->mesh, warnings, &out->look);
        return Status::failure(path + ": '#NodeName' selects a node of a glTF file only");
    }
    if (ext == ".obj") return readObj(path, limits, &out->mesh, warnings, &out->look);
    if (ext == ".ply") return readPly(path, limits, &out->mesh, warnings, &out->look);
    return Status::failure(path + ": unknown mesh format '" + ext + "' (use .obj, .ply, .gltf or .glb)");
#endif
}

namespace {

// True when `p` is `root` or below it, both already canonical (compared component by component).
bool isWithin(const std::filesystem::path& p, const std::filesystem::path& root) {
    auto pi = p.begin();
    for (auto ri = root.begin(); ri != root.end(); ++ri, ++pi) {
        if (ri->empty()) continue;  // a trailing separator
        if (pi == p.end() || *pi != *ri) return false;
    }
    return true;
}

}  // namespace

Status checkMeshInside(const std::string& scene_path, const std::string& field, const std::string& mesh_text,
                       const std::string& mesh_path) {
    namespace fs = std::filesystem;
    // A glTF node selector "file.glb#Node" names the file before the '#'.
    std::string file = mesh_path;
    if (const auto hash = mesh_path.rfind('#'); hash != std::string::npos) {
        std::string ext = mesh_path.substr(0, hash);
        ext = ext.substr(std::min(ext.size(), ext.find_last_of('.') == std::string::npos ? ext.size() : ext.find_last_of('.')));
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (ext == ".gltf" || ext == ".glb") file = mesh_path.substr(0, hash);
    }
    std::error_code ec;
    const fs::path scene_folder = fs::path(scene_path).parent_path();
    const fs::path mesh = fs::weakly_canonical(fs::absolute(file, ec), ec);
    const fs::path folder = fs::weakly_canonical(fs::absolute(scene_folder.empty() ? fs::path(".") : scene_folder, ec), ec);
    const fs::path cwd = fs::weakly_canonical(fs::current_path(ec), ec);
    if (!ec && (isWithin(mesh, folder) || isWithin(mesh, cwd))) return Status::success();
    return Status::failure(scene_path + ": " + field + ": \"" + mesh_text +
                           "\" is outside the scene's folder and the working folder (allow with --allow-outside)");
}

}  // namespace apparent
