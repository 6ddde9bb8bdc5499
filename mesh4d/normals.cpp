#include "normals.h"

namespace mesh4d {

std::vector<Vec3> vertexNormals(const ApparentMesh& mesh) {
    std::vector<Vec3> n(mesh.positions.size(), Vec3{0, 0, 0});
    for (const auto& t : mesh.triangles) {
        const Vec3& a = mesh.positions[t[0]];
        const Vec3 area2 = cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a);
        for (uint32_t v : t) n[v] += area2;
    }
    for (Vec3& v : n) {
        const double len = norm(v);
        v = len > 0 ? v / len : Vec3{0, 0, 1};
    }
    return n;
}

}  // namespace mesh4d
