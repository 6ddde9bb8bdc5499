#include "subdivide.h"

#include <algorithm>
#include <unordered_map>

namespace mesh4d {

RestMesh subdivideUniform(const RestMesh& mesh, int levels) {
    RestMesh cur = mesh;
    for (int level = 0; level < levels; ++level) {
        RestMesh next;
        next.positions = cur.positions;
        next.triangles.reserve(4 * cur.triangles.size());
        std::unordered_map<uint64_t, uint32_t> mids;
        mids.reserve(2 * cur.triangles.size());
        auto mid = [&](uint32_t a, uint32_t b) {
            const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            auto [it, inserted] = mids.try_emplace(key, uint32_t(next.positions.size()));
            if (inserted) next.positions.push_back((cur.positions[a] + cur.positions[b]) * 0.5);
            return it->second;
        };
        for (const auto& t : cur.triangles) {
            const uint32_t m01 = mid(t[0], t[1]), m12 = mid(t[1], t[2]), m20 = mid(t[2], t[0]);
            next.triangles.push_back({t[0], m01, m20});
            next.triangles.push_back({m01, t[1], m12});
            next.triangles.push_back({m20, m12, t[2]});
            next.triangles.push_back({m01, m12, m20});
        }
        cur = std::move(next);
    }
    return cur;
}

}  // namespace mesh4d
