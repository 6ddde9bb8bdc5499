#include "slice.h"

#include <cmath>

#include "robust.h"

namespace mesh4d {

namespace {

// Where a vertex's worldline crossing falls relative to the extruded span.
enum class Side : uint8_t { NotYet, Inside, Gone };

constexpr uint32_t kUnset = 0xffffffffu;

struct FrameBuilder {
    const World4D& world;
    const ViewSurface& view;
    ApparentMesh out;
    std::vector<Side> side;
    std::vector<uint32_t> vertex_out;     // rest vertex -> output vertex
    std::vector<uint32_t> crossing_out;   // 2 * edge + cap -> output vertex

    FrameBuilder(const World4D& w, const ViewSurface& v) : world(w), view(v) {}

    uint32_t emit(const Event& e) {
        out.positions.push_back(e.x);
        out.emission_times.push_back(e.t);
        return uint32_t(out.positions.size() - 1);
    }

    // Step: classify every vertex against the real caps, and cut the worldlines of the rest.
    void classifyVertices() {
        const size_t nv = world.mesh.positions.size();
        side.assign(nv, Side::Inside);
        vertex_out.assign(nv, kUnset);
        for (size_t i = 0; i < nv; ++i) {
            if (world.cap_a_real && viewSide(view, world.events[2 * i]) < 0) side[i] = Side::NotYet;
            else if (world.cap_b_real && viewSide(view, world.events[2 * i + 1]) > 0) side[i] = Side::Gone;
        }
        // Visible vertices first, in input order: when nothing is clipped, output vertex i is the
        // image of input vertex i (unreferenced input vertices aside).
        for (size_t i = 0; i < nv; ++i)
            if (side[i] == Side::Inside && world.vertex_used[i]) vertexPoint(uint32_t(i));
    }

    uint32_t vertexPoint(uint32_t i) {
        if (vertex_out[i] == kUnset) {
            const Motion& m = world.motion;
            const double one_minus_b2 = oneMinusSquare(m.beta);
            // Anchor the worldline at the cap event nearer in time to the frame: the shorter the
            // extrapolation v (t_c - t_anchor), the smaller its absolute rounding.
            const Event& ea = world.events[2 * i];
            const Event& eb = world.events[2 * i + 1];
            const Event& anchor = std::fabs(view.t_c - ea.t) <= std::fabs(view.t_c - eb.t) ? ea : eb;
            vertex_out[i] = emit(cutWorldline(view, anchor, m.velocity, one_minus_b2).event);
        }
        return vertex_out[i];
    }

    // The crossing of edge `edge` at cap `cap` (0 = a, 1 = b), always parametrised from the
    // lower vertex id so both triangles of the edge compute the same point.
    uint32_t crossingPoint(uint32_t edge, int cap) {
        uint32_t& slot = crossing_out[2 * edge + cap];
        if (slot == kUnset) {
            const Edge& e = world.edges[edge];
            const Event& p0 = world.events[2 * e.lo + cap];
            const Event& p1 = world.events[2 * e.hi + cap];
            slot = emit(lerp(p0, p1, cutSegment(view, p0, p1)));
        }
        return slot;
    }

    // Step: one triangle, clipped to the span where needed (Sutherland-Hodgman over the two caps).
    void addTriangle(size_t f) {
        const auto& tri = world.mesh.triangles[f];
        const Side s0 = side[tri[0]], s1 = side[tri[1]], s2 = side[tri[2]];
        if (s0 == Side::Inside && s1 == Side::Inside && s2 == Side::Inside) {
            out.triangles.push_back({vertexPoint(tri[0]), vertexPoint(tri[1]), vertexPoint(tri[2])});
            return;
        }
        if (s0 == s1 && s1 == s2) return;  // wholly before or after existence
        ++out.clipped_triangles;
        uint32_t polygon[6];  // a triangle clipped by a slab has at most 5 corners
        int n = 0;
        for (int c = 0; c < 3; ++c) {
            const uint32_t vi = tri[c], vj = tri[(c + 1) % 3];
            const Side si = side[vi], sj = side[vj];
            const uint32_t edge = world.triangle_edges[f][c];
            if (si == Side::Inside) polygon[n++] = vertexPoint(vi);
            if (si == sj) continue;
            // Caps crossed going from vi to vj, in order along the edge.
            const bool cross_a = si == Side::NotYet || sj == Side::NotYet;
            const bool cross_b = si == Side::Gone || sj == Side::Gone;
            const bool a_first = si == Side::NotYet || sj == Side::Gone;
            if (cross_a && cross_b) {
                polygon[n++] = crossingPoint(edge, a_first ? 0 : 1);
                polygon[n++] = crossingPoint(edge, a_first ? 1 : 0);
            } else {
                polygon[n++] = crossingPoint(edge, cross_a ? 0 : 1);
            }
        }
        // Fan over the clipped polygon, convex in the triangle's parameter domain.
        for (int k = 1; k + 1 < n; ++k) out.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
    }
};

}  // namespace

ApparentMesh sliceWorld(const World4D& world, const ViewSurface& view) {
    FrameBuilder b(world, view);
    if (world.empty()) return std::move(b.out);
    b.classifyVertices();
    b.crossing_out.assign(2 * world.edges.size(), kUnset);
    for (size_t f = 0; f < world.mesh.triangles.size(); ++f) b.addTriangle(f);
    return std::move(b.out);
}

}  // namespace mesh4d
