#include "exporters/openmesh_frame.h"

namespace apparent {

OpenMesh::VPropHandleT<double> toOpenMesh(const ExportFrame& frame, FrameTriMesh* om) {
    const auto& m = frame.mesh;
    OpenMesh::VPropHandleT<double> quality;
    om->add_property(quality, "quality");
    om->property(quality).set_persistent(true);
    std::vector<FrameTriMesh::VertexHandle> vh(m.positions.size());
    auto addVertex = [&](size_t i) {
        const auto& p = m.positions[i];
        auto v = om->add_vertex(FrameTriMesh::Point(p.x, p.y, p.z));
        om->property(quality, v) = m.emission_times[i];
        return v;
    };
    for (size_t i = 0; i < m.positions.size(); ++i) vh[i] = addVertex(i);
    for (const auto& t : m.triangles) {
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;  // zero area by construction
        if (om->add_face(vh[t[0]], vh[t[1]], vh[t[2]]).is_valid()) continue;
        om->add_face(addVertex(t[0]), addVertex(t[1]), addVertex(t[2]));
    }
    return quality;
}

}  // namespace apparent
