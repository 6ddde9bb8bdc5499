// Conversion of an exported frame to an OpenMesh triangle mesh, shared by the PLY and OBJ writers.
#pragma once

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "exporters/frame_mesh.h"

namespace apparent {

struct FrameTraits : OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<FrameTraits> FrameTriMesh;

// Fills `om` with the frame's vertices and triangles; a triangle OpenMesh cannot add to a
// manifold structure (a non-manifold input edge) gets its own copies of its vertices, so no face
// is lost. Returns the handle of the per-vertex emission-time property, named "quality".
OpenMesh::VPropHandleT<double> toOpenMesh(const ExportFrame& frame, FrameTriMesh* om);

}  // namespace apparent
