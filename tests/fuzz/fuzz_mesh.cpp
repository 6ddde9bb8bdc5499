// libFuzzer harness for one mesh reader, chosen at compile time by APPARENT_FUZZ_EXT (".obj",
// ".ply", ".gltf" or ".glb"): the input bytes become a mesh file read through readMesh, the
// dispatch the command uses, with small limits so that a valid header cannot ask for gigabytes.
// A reader must return ok with finite positions and in-range triangles, or an error of one line
// that starts with the path. For .gltf and .glb the same bytes are also read as a scene; for .obj
// also as a .mtl material library (pipeline/mtl_reader.h); for .ply the look must be well formed.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "pipeline/input/mesh_input.h"
#include "pipeline/input/mtl_reader.h"
#include "pipeline/input/scene.h"
#include "tests/fuzz/fuzz_input.h"

#ifndef APPARENT_FUZZ_EXT
#error "define APPARENT_FUZZ_EXT"
#endif

namespace {

void check(bool condition) {
    if (!condition) std::abort();  // libFuzzer reports the input as a crash
}

void checkStatus(const apparent::Status& st, const std::string& path) {
    if (!st.ok) check(st.message.rfind(path, 0) == 0 && st.message.find('\n') == std::string::npos);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    apparent_fuzz::removeInputFolderAtExit();
    const std::string path = apparent_fuzz::writeInput(data, size, APPARENT_FUZZ_EXT);
    apparent::MeshLimits limits;
    limits.max_vertices = 1'000'000;
    limits.max_faces = 1'000'000;
    limits.max_file_bytes = 16u << 20;
    apparent::LoadedMesh mesh;
    apparent::MeshWarnings warnings;
    const apparent::Status st = apparent::readMesh(path, limits, &mesh, &warnings);
    checkStatus(st, path);
    if (st.ok) {
        check(!mesh.mesh.triangles.empty());
        for (const auto& p : mesh.mesh.positions) check(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        for (const auto& t : mesh.mesh.triangles)
            for (uint32_t i : t) check(i < mesh.mesh.positions.size());
    }
    if (st.ok && mesh.look && std::string(APPARENT_FUZZ_EXT) == ".ply") {
        // A PLY's look (pipeline/input/ply_reader.h): parallel to the mesh, one material (one per
        // TextureFile with texnumber) that each triangle names, colours in [0, 1], texture coordinates finite.
        const apparent::SurfaceLook& look = *mesh.look;
        const size_t n = mesh.mesh.positions.size();
        check(look.color.empty() || look.color.size() == 4 * n);
        check(look.texcoord.empty() || look.texcoord.size() == 2 * n);
        check(look.hasAttributes() && !look.materials.empty());
        check(look.triangle_material.size() == mesh.mesh.triangles.size());
        for (uint32_t m : look.triangle_material) check(m < look.materials.size());
        for (double c : look.color) check(c >= 0 && c <= 1);
        for (double t : look.texcoord) check(std::isfinite(t));
    }
    if (std::string(APPARENT_FUZZ_EXT) == ".obj") {
        // The same bytes as an OBJ's material library: parsed, or one line naming it; every
        // material's glTF JSON formed (names made UTF-8).
        std::vector<apparent::MtlMaterial> materials;
        std::vector<std::string> mtl_warnings, extensions;
        const std::string text(reinterpret_cast<const char*>(data), size);
        const apparent::Status mtl = apparent::parseMtl("input.mtl", text, &materials, &mtl_warnings);
        checkStatus(mtl, "input.mtl");
        if (mtl.ok)
            for (const apparent::MtlMaterial& m : materials) check(!apparent::mtlMaterialJson(m, 0, &extensions).empty());
    }
    if (apparent::isGltfPath(path)) {
        apparent::Scene scene;
        checkStatus(apparent::loadScene(path, &scene), path);
    }
    return 0;
}
