// A scene object ready for the 4D stage: its mesh read once, rotation, scale and the node's
// linear map applied (pipeline/stage/stage.h loads them; pipeline/stage/worlds.h extrudes them).
#pragma once

#include <array>
#include <iosfwd>
#include <vector>

#include "mesh4d/extrude.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/scene.h"

namespace apparent {

struct PreparedObject {
    ObjectSpec spec;
    mesh4d::RestMesh rest;             // rest-frame mesh with rotation, scale and `linear` applied
    bool has_color = false;            // the mesh file gave a base colour
    std::array<double, 4> color{1, 1, 1, 1};
    std::shared_ptr<const SurfaceLook> look;  // the mesh file's look (mesh_input.h LoadedMesh::look)
    double radius = 0;  // the largest |q| of `rest` (kept when the worlds take the mesh: worlds.h takeWorlds)
};

// The base colour object i is drawn with (linear RGBA): its mesh file's, else a palette colour.
std::array<double, 4> objectBaseColor(const std::vector<PreparedObject>& objects, size_t i);

// Loads every object's mesh (each file once; its path confined as docs/HOSTILE_INPUT.md says
// unless limits.allow_outside) and applies scale, then rotation (X, Y, Z about fixed axes), then
// the spec's linear map; a map with negative determinant flips the triangles back. Counted
// warnings go to `log` as "warning: FILE: ..." unless `quiet`. On failure the message names the
// file and the field.
Status prepareObjects(const Scene& scene, const MeshLimits& limits, std::vector<PreparedObject>* objects,
                      std::ostream& log, bool quiet);

}  // namespace apparent
