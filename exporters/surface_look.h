// What an object's surface looks like, as its input file gives it: texture coordinates and vertex
// colours per rest vertex, a material per rest triangle, and the glTF materials, textures, samplers
// and images they use (issue 35, "Real models look like themselves").
//
// Carried through the cut: every output vertex is the image of a rest point that lies on a known
// rest triangle (ApparentMesh::rest_points and source_triangles), so its attributes are those of the
// rest triangle's corners interpolated at the point's barycentric coordinates there: exactly where
// the texture lies on the moving body. Normals stay the apparent surface's own.
//   rest point q on triangle (a, b, c): with e1 = b - a, e2 = c - a, w = q - a, the coordinates
//   (l1, l2) solve the 2x2 normal equations [e1.e1 e1.e2; e1.e2 e2.e2] (l1, l2) = (w.e1, w.e2)
//   (least squares, so a point a rounding off the plane still gets the nearest coordinates), and
//   attribute(q) = (1 - l1 - l2) A(a) + l1 A(b) + l2 A(c). A point equal to a corner takes that
//   corner's attribute as it is (vertex mode: the input's values vertex for vertex).
// glTF splits a vertex wherever an attribute is discontinuous (texture seams, material borders),
// so each rest vertex has one value of each attribute and the output's vertices inherit that.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mesh4d/slice.h"

namespace apparent {

// An image as the file holds it (PNG or JPEG bytes), copied into the output once.
struct LookImage {
    std::string mime_type;  // image/png or image/jpeg
    std::string name;
    std::vector<unsigned char> bytes;
};

struct SurfaceLook {
    // Per rest vertex; empty when the file has none.
    std::vector<double> texcoord;  // TEXCOORD_0: u, v per vertex
    std::vector<double> color;     // COLOR_0: linear R, G, B, A per vertex
    // Per rest triangle: its material, an index into `materials`.
    std::vector<uint32_t> triangle_material;
    // glTF objects as JSON text (nlohmann's dump() form), their references renumbered for these
    // lists: a material's textureInfo "index" into `textures`, a texture's "source" into `images`
    // and "sampler" into `samplers`.
    std::vector<std::string> materials, textures, samplers;
    std::vector<LookImage> images;
    std::vector<std::string> extensions;  // extensionsUsed by the materials (KHR_texture_transform, ...)

    bool hasAttributes() const { return !texcoord.empty() || !color.empty(); }
};

// An output mesh's attributes per apparent vertex (ApparentMesh::positions), interpolated on the rest
// triangles of `rest` (the mesh the cut's rest points and source triangles refer to: the prepared
// object's, after scale, rotation and node transforms) as above: 2 texture coordinates and 4
// colour components per vertex (empty where the look has none). A vertex no triangle uses gets zeros.
void interpolateLook(const SurfaceLook& look, const mesh4d::RestMesh& rest, const mesh4d::ApparentMesh& mesh,
                     std::vector<double>* texcoord, std::vector<double>* color);

// The barycentric coordinates (1 - l1 - l2, l1, l2) of `q` on triangle (a, b, c), as above.
std::array<double, 3> restBarycentric(const mesh4d::Vec3& a, const mesh4d::Vec3& b, const mesh4d::Vec3& c,
                                      const mesh4d::Vec3& q);

}  // namespace apparent
