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
// Texture coordinates: sets TEXCOORD_0 and TEXCOORD_1, the two every glTF client is to support
// (glTF 2.0, 3.7.2.1 "Meshes: Overview"; occlusion and light maps use the second); further
// sets are dropped on reading with a warning.
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
    std::vector<double> texcoord;   // TEXCOORD_0: u, v per vertex
    std::vector<double> texcoord1;  // TEXCOORD_1: u, v per vertex
    std::vector<double> color;      // COLOR_0: linear R, G, B, A per vertex
    // Whether the vertex arrays hold TEXCOORD_1: what a process without them (a shard's merge)
    // needs to lay out meshopt's vertex record. Readers set it with texcoord1.
    bool has_texcoord1 = false;
    // Per rest triangle: its material, an index into `materials`.
    std::vector<uint32_t> triangle_material;
    // glTF objects as JSON text (nlohmann's dump() form), their references renumbered for these
    // lists: a material's textureInfo "index" into `textures`, a texture's "source" into `images`
    // and "sampler" into `samplers`.
    std::vector<std::string> materials, textures, samplers;
    std::vector<LookImage> images;
    std::vector<std::string> extensions;  // extensionsUsed by the materials (KHR_texture_transform, ...)

    bool hasAttributes() const { return !texcoord.empty() || !texcoord1.empty() || !color.empty(); }
};

// A look's attributes per apparent vertex: 2 texture coordinates per set and 4 colour components
// per vertex (each empty where the look has none).
struct VertexLook {
    std::vector<double> texcoord, texcoord1, color;
};

// An output mesh's attributes per apparent vertex (ApparentMesh::positions), interpolated on the rest
// triangles of `rest` (the mesh the cut's rest points and source triangles refer to: the prepared
// object's, after scale, rotation and node transforms) as above. A vertex no triangle uses gets zeros.
void interpolateLook(const SurfaceLook& look, const mesh4d::RestMesh& rest, const mesh4d::ApparentMesh& mesh,
                     VertexLook* out);

// The barycentric coordinates (1 - l1 - l2, l1, l2) of `q` on triangle (a, b, c), as above.
std::array<double, 3> restBarycentric(const mesh4d::Vec3& a, const mesh4d::Vec3& b, const mesh4d::Vec3& c,
                                      const mesh4d::Vec3& q);

}  // namespace apparent
