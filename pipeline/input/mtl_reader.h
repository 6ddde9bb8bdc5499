// Wavefront .mtl material libraries (an OBJ's `mtllib`), read as glTF materials (issue 35).
//
// Read: `newmtl NAME` (the rest of the line; may be empty, as Blender writes it; bytes that are not
// UTF-8 read as U+FFFD, with a warning), `Kd r [g b]` (baseColorFactor rgb; one number is grey),
// `d a` or `Tr t` (alpha a = d, or 1 - t; alphaMode BLEND when < 1), `Ke r [g b]` (emissiveFactor;
// components above 1 are divided by the largest, which becomes KHR_materials_emissive_strength),
// `Pr` and `Pm` (roughnessFactor, metallicFactor: the PBR extension of the format) and `map_Kd`
// (baseColorTexture; its options are ignored with a warning, the last token is the file).
// Without `Pr`, roughness comes from the specular exponent `Ns` as Blender writes it
// (Ns = (30 (1 - roughness))^2, so roughness = 1 - sqrt(min(Ns, 900)) / 30), or is 1 without Ns;
// without `Pm`, metallic is 0. Without `Kd`, the base colour is white (glTF's default).
// Every other keyword is named in one warning. Numbers must be finite and in range (Kd, d, Tr, Pr,
// Pm in [0, 1]; Ke, Ns >= 0), else one error naming the file, the line and the keyword.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "pipeline/input/status.h"

namespace apparent {

struct MtlMaterial {
    std::string name;
    size_t line = 0;                           // where `newmtl` names it
    std::array<double, 3> diffuse{1, 1, 1};    // Kd
    double alpha = 1;                          // d, or 1 - Tr
    std::array<double, 3> emissive{0, 0, 0};   // Ke
    double roughness = 1, metallic = 0;        // Pr (or from Ns), Pm
    bool roughness_given = false;              // Pr read (a later Ns does not change it)
    std::string diffuse_map;                   // map_Kd's file as written ('\' read as '/'); empty: none
};

// Parses the text of library `path` into `materials` (file order); warnings (unknown keywords,
// map options, a name defined twice: the first kept) go to `warnings`, each starting with `path`.
Status parseMtl(const std::string& path, const std::string& text, std::vector<MtlMaterial>* materials,
                std::vector<std::string>* warnings);

// `text` with every byte that is not part of valid UTF-8 replaced by U+FFFD (glTF text is UTF-8).
std::string utf8Replaced(const std::string& text);

// The glTF material JSON (dump() form) of `m`: name (none when empty), doubleSided true, pbrMetallicRoughness
// (baseColorFactor [Kd, alpha], metallicFactor, roughnessFactor, baseColorTexture {"index":
// `texture`} when `texture` >= 0), emissiveFactor when non-zero, alphaMode BLEND when alpha < 1.
// Adds the extensions it uses to `extensions` (once each).
std::string mtlMaterialJson(const MtlMaterial& m, int texture, std::vector<std::string>* extensions);

}  // namespace apparent
