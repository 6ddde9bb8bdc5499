// Wavefront OBJ meshes, read by our own single-pass scanner (std::from_chars, no iostreams) into
// double positions, made into a mesh as OpenMesh's importer would (pipeline/input/polygon_input.h).
//
// Everything a lenient reader would drop unannounced becomes either a one-line error naming the
// line (bad numbers, indices out of range, faces of fewer than 3 vertices) or a counted warning
// (degenerate faces with a repeated index). Polygons are triangulated as a fan about their first
// corner, counted as a warning. Read: `v` (the first three numbers), `f` (each corner's position
// index and texture coordinate index: "i", "i/t", "i//n", "i/t/n", negatives counting back), and
// for the look `vt` (u and v), `usemtl` (the rest of the line) and `mtllib` (blank-separated file
// names); other keywords skipped. Coordinates must lie within float range (|x| <= 3e38), since
// every export is float32.
//
// The look (issue 35; exporters/surface_look.h), when asked for: the libraries named by `mtllib`
// (relative to the OBJ's folder) are read (pipeline/mtl_reader.h), and so are the images their
// `map_Kd` name (relative to the library's folder, PNG or JPEG: others dropped with a warning),
// when the resolved path (".." and symlinks followed) lies inside the folders a mesh path may use
// (the scene's folder, MeshLimits::scene_path, or the working folder) or the OBJ's own folder, or
// anywhere with MeshLimits::allow_outside. A path outside, or a missing file: one
// warning, not opened; a file that is not regular or is larger than max_file_bytes: refused (an
// error), as for the mesh itself. Errors start with the OBJ's path, then the library's or image's
// own message ("m.obj: m.mtl:2: Kd: ..."). Each triangle gets the material its face's `usemtl` names, the
// materials numbered in first-use order; a face without one, or whose name no library defines
// (one warning naming them), gets a material without fields or name (white, metallic 0, rough 1). When no face's
// name is defined the object has no look (one warning) and keeps one colour, as before. `vt` are
// kept when a material is: TEXCOORD_0 = (u, 1 - v) (OBJ's v axis points up, glTF's down); a
// position used with two different `vt` becomes one vertex per `vt` (copies of the position,
// exactly; counted as a warning), as a glTF file splits its vertices at seams. A `vt` index out of
// range is then an error naming the line (without a look it is not read).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mesh4d/extrude.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/status.h"

namespace apparent {

// Reads an OBJ file into a rest-frame triangle mesh (no transform applied), and its look into
// `look` when given (null when it has none; without `look` the file's materials and texture
// coordinates are counted in a warning, not read).
Status readObj(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
               std::shared_ptr<const SurfaceLook>* look = nullptr);

}  // namespace apparent
