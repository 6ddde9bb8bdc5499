#include "tessellate.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

namespace mesh4d {

namespace {
typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Triangulation_vertex_base_with_info_2<uint32_t, K> Vb;
typedef CGAL::Constrained_triangulation_face_base_2<K> Fb;
typedef CGAL::Triangulation_data_structure_2<Vb, Fb> Tds;
typedef CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag> CDT;
}  // namespace

std::vector<std::array<uint32_t, 3>> triangulateDomain(const std::vector<std::array<double, 2>>& boundary,
                                                       const std::vector<std::array<double, 2>>& interior) {
    CDT cdt;
    std::vector<CDT::Vertex_handle> bh(boundary.size());
    // Step: the boundary chain, constrained segment by segment.
    for (size_t i = 0; i < boundary.size(); ++i) {
        bh[i] = cdt.insert(K::Point_2(boundary[i][0], boundary[i][1]));
        bh[i]->info() = uint32_t(i);
    }
    for (size_t i = 0; i < boundary.size(); ++i) cdt.insert_constraint(bh[i], bh[(i + 1) % boundary.size()]);
    // Step: the interior grid.
    for (size_t i = 0; i < interior.size(); ++i) {
        auto v = cdt.insert(K::Point_2(interior[i][0], interior[i][1]));
        v->info() = uint32_t(boundary.size() + i);
    }
    // Step: every finite face lies inside the domain, which is its own convex hull.
    std::vector<std::array<uint32_t, 3>> out;
    out.reserve(size_t(cdt.number_of_faces()));
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
        out.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
    return out;
}

}  // namespace mesh4d
