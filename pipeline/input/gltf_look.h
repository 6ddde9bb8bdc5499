// The look of a glTF object (exporters/surface_look.h) from what the reader gathered: the
// materials its primitives use, in first-use order, with the textures, samplers and images they
// reach renumbered for the output.
//
// Kept: a material's JSON as written (PBR factors and textures, normal, occlusion and emissive
// textures, alpha mode and cutoff, double-sidedness, name), textureInfo's KHR_texture_transform
// and the material extensions three.js and the Khronos validator read (KHR_materials_*); images
// given as PNG or JPEG bytes. Dropped, with one warning each naming what: other extensions, texture
// references to a set other than TEXCOORD_0 and TEXCOORD_1 (or to TEXCOORD_1 where the meshes have
// none), textures whose image is not PNG or JPEG or could not be read. Refused (one line naming the file and the glTF path): references out of range.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "exporters/surface_look.h"
#include "pipeline/input/gltf_document.h"
#include "pipeline/input/mesh_input.h"

namespace apparent {

// What the reader gathers per primitive: TEXCOORD_0 and TEXCOORD_1 (u, v per vertex) and COLOR_0
// (R, G, B, A) for the vertices up to the last primitive that had them, and the glTF material of
// each triangle (-1: none).
struct GltfLookParts {
    std::vector<double> texcoord, texcoord1, color;
    std::vector<int> triangle_material;
};

// The look of a mesh of `vertices` vertices, or null when the file gives no material, texture
// coordinate or colour. Warnings go to `warnings`.
Status buildGltfLook(const std::string& path, const GltfDocument& doc, GltfLookParts parts, size_t vertices,
                     MeshWarnings* warnings, std::shared_ptr<const SurfaceLook>* out);

}  // namespace apparent
