// Stanford PLY meshes (ascii, binary little- and big-endian), read by our own single-pass scan
// into double positions and made into a mesh as OpenMesh's importer would
// (pipeline/input/polygon_input.h).
//
// A lenient reader trusts the header (sizing its arrays from the element counts) and drops faces
// with bad indices with a log line only. Our scan checks everything as it reads: the
// header (the `ply` magic, one `format` line, known property types, `element vertex` with scalar
// x, y and z, `element face` with a `vertex_indices` or `vertex_index` list), the element counts
// against the limits and against the file size (each row needs a minimum number of bytes, so a
// 200-byte file cannot ask for a billion vertices), then every row of the body (finite
// coordinates, face indices in range, faces of at least 3 vertices, no missing or trailing
// bytes in binary files). Errors are one line, "mesh.ply: field: problem", for example
// "mesh.ply: face[3].vertex_indices[2]: index 9 is out of range (8 vertices)". Faces with a
// repeated index are dropped and counted as degenerate, polygons triangulated (a fan) and counted.
//
// The look (issue 35; exporters/surface_look.h), when asked for:
// - Vertex colours: `red green blue` (or `diffuse_red diffuse_green diffuse_blue`), and `alpha` when
//   given (else 1), scalar properties of any type. An integer type is normalised by its type's
//   largest value (uchar / 255, ushort / 65535, char / 127, ...), a float type taken as it is; the
//   value must lie in [0, 1] (a negative integer, a float outside [0, 1] or not finite: an error
//   naming the row and property, "mesh.ply: vertex[3].red: 1.5 is not a colour value in [0, 1]").
//   PLY colours are display values (sRGB-encoded, as MeshLab shows them) and glTF's COLOR_0 is
//   linear, so R, G and B are decoded with the sRGB transfer function (IEC 61966-2-1:1999, the
//   inverse of its encoding), s the normalised value:
//     linear = s / 12.92                      for s <= 0.04045
//     linear = ((s + 0.055) / 1.055)^2.4      above
//   (0 -> 0, 0.04045 -> 0.0031308, 0.5 -> 0.21404, 1 -> 1); alpha stays as it is (linear).
// - Texture coordinates: `texture_u texture_v`, `s t` or `u v` (the first pair the vertex has;
//   finite, within float range). MeshLab's reader (vcglib, wrap/io_trimesh/import_ply.h) stores
//   texture_u/texture_v and s/t unchanged as a vertex's (u, v), as its OBJ reader
//   (wrap/io_trimesh/import_obj.h) stores `vt`: a PLY's v points up as OBJ's does, and glTF's down,
//   so TEXCOORD_0 = (u, 1 - v) as for OBJ (obj_reader.h).
// - Per-corner texture coordinates: MeshLab's face list `texcoord` (vcglib's "wedge" coordinates:
//   u0 v0 u1 v1 ... in the order of vertex_indices; any integer count type, float or double values;
//   2 per face vertex, finite, within float range, else an error naming the face row, which may
//   list them before or after its indices). Taken as an OBJ's `vt` per corner: a vertex with
//   different coordinates on different faces is split (polygon_input.h, splitAtTextureSeams), a
//   polygon's fan triangles keep their corners' coordinates, TEXCOORD_0 = (u, 1 - v), and the
//   vertex colours follow the copies. With per-vertex coordinates too, the per-corner ones win
//   (one warning).
// - The image: a header line `comment TextureFile NAME` (MeshLab's convention; NAME the rest of the
//   line, relative to the PLY's folder), read under the rules of pipeline/input/look_files.h (only
//   inside the allowed folders, a regular file within the size limit, PNG or JPEG; otherwise one
//   warning and no texture), when the file has texture coordinates (else one warning). Only the
//   first such line is read (later ones: one warning), unless the faces have `texnumber`.
// The object then has one material (white, metallic 0, roughness 1, double-sided, the image as its
// baseColorTexture when read), on every triangle; vertices OpenMesh copies keep their original's values.
// MeshLab's several textures: with more than one TextureFile line and a face scalar `texnumber`,
// one such material per TextureFile (in line order, each with its own image), each triangle the
// one its face's texnumber names. A texnumber must be an integer naming a TextureFile (0 alone when
// there is at most one line; else an error naming the row): with one texture and texnumber 0
// everywhere, the file reads as without it.
// Every other property of `vertex` and `face` is named in one warning per element ("element vertex:
// properties nx, ny, nz, quality ignored (normals are the apparent surface's own)"), other elements in
// one more; an apparent PLY frame's per-vertex `object` index (exporters/ply.h) has its own
// warning: the frame is read as one object.
#pragma once

#include <memory>
#include <string>

#include "mesh4d/extrude.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/status.h"

namespace apparent {

// Reads a PLY file into a rest-frame triangle mesh (no transform applied), and its look into `look`
// when given (null when it has none; without `look` colours and texture coordinates are named in a
// warning, not kept).
Status readPly(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
               std::shared_ptr<const SurfaceLook>* look = nullptr);

}  // namespace apparent
