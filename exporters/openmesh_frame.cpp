#include "exporters/openmesh_frame.h"

namespace apparent {

mesh4d::ApparentMesh mergeObjects(const ExportFrame& frame) {
    mesh4d::ApparentMesh all;  // absolute lab positions and times (origin 0)
    for (const auto& part : frame.objects) {
        const uint32_t base = uint32_t(all.positions.size());
        for (size_t i = 0; i < part.positions.size(); ++i) {
            all.positions.push_back(part.absolutePosition(i));
            all.emission_times.push_back(part.absoluteTime(i));
        }
        for (const auto& t : part.triangles) all.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
        all.rest_points.insert(all.rest_points.end(), part.rest_points.begin(), part.rest_points.end());
        all.clipped_triangles += part.clipped_triangles;
    }
    return all;
}

OpenMesh::VPropHandleT<double> toOpenMesh(const ExportFrame& frame, FrameTriMesh* om) {
    const mesh4d::ApparentMesh m = mergeObjects(frame);
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
