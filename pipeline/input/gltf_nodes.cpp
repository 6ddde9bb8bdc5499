#include "pipeline/input/gltf_nodes.h"

#include <algorithm>
#include <cmath>

namespace apparent {

using mesh4d::Vec3;

Affine Affine::operator*(const Affine& o) const {
    Affine r;
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += m[k * 4 + row] * o.m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

Vec3 Affine::apply(const Vec3& p) const {
    return {m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
            m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]};
}

double Affine::det3() const {
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
}

Affine localTransform(const tinygltf::Node& n) {
    Affine a;
    if (n.matrix.size() == 16) {
        for (int i = 0; i < 16; ++i) a.m[i] = n.matrix[i];
        return a;
    }
    // T * R * S (glTF 2.0 section 5.25).
    double tx = 0, ty = 0, tz = 0, qx = 0, qy = 0, qz = 0, qw = 1, sx = 1, sy = 1, sz = 1;
    if (n.translation.size() == 3) { tx = n.translation[0]; ty = n.translation[1]; tz = n.translation[2]; }
    if (n.rotation.size() == 4) { qx = n.rotation[0]; qy = n.rotation[1]; qz = n.rotation[2]; qw = n.rotation[3]; }
    if (n.scale.size() == 3) { sx = n.scale[0]; sy = n.scale[1]; sz = n.scale[2]; }
    const double r[9] = {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy + qz * qw), 2 * (qx * qz - qy * qw),
                         2 * (qx * qy - qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz + qx * qw),
                         2 * (qx * qz + qy * qw), 2 * (qy * qz - qx * qw), 1 - 2 * (qx * qx + qy * qy)};
    const double s[3] = {sx, sy, sz};
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) a.m[c * 4 + row] = r[c * 3 + row] * s[c];
    a.m[12] = tx;
    a.m[13] = ty;
    a.m[14] = tz;
    return a;
}

int defaultSceneIndex(const tinygltf::Model& model) {
    if (model.scenes.empty()) return -1;
    return model.defaultScene >= 0 && size_t(model.defaultScene) < model.scenes.size() ? model.defaultScene : 0;
}

std::vector<int> rootNodes(const tinygltf::Model& model) {
    if (const int s = defaultSceneIndex(model); s >= 0) return model.scenes[size_t(s)].nodes;
    std::vector<bool> is_child(model.nodes.size(), false);
    for (const auto& n : model.nodes)
        for (int c : n.children)
            if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = true;
    std::vector<int> roots;
    for (size_t i = 0; i < model.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(int(i));
    return roots;
}

namespace {

struct Walk {
    const std::string& file;
    const tinygltf::Model& model;
    const NodeVisitor& visit;
    std::vector<int> path;  // ancestors of the node being visited
    size_t visits = 0;

    Status fail(const std::string& where, const std::string& problem) const {
        return Status::failure(file + ": " + where + ": " + problem);
    }

    Status node(int n, const Affine& parent, bool apply_own_transform) {
        const std::string where = "nodes[" + std::to_string(n) + "]";
        if (n < 0 || size_t(n) >= model.nodes.size())
            return fail("nodes", "index " + std::to_string(n) + " out of range (" + std::to_string(model.nodes.size()) + " nodes)");
        if (std::find(path.begin(), path.end(), n) != path.end()) return fail(where, "the node hierarchy has a cycle");
        if (path.size() > kMaxNodeDepth) return fail(where, "node hierarchy deeper than " + std::to_string(kMaxNodeDepth));
        if (++visits > kMaxNodeVisits)
            return fail("nodes", "more than " + std::to_string(kMaxNodeVisits) + " node visits (nodes shared by many parents)");
        const tinygltf::Node& nd = model.nodes[size_t(n)];
        const Affine world = apply_own_transform ? parent * localTransform(nd) : parent;
        for (double v : world.m)
            if (!std::isfinite(v)) return fail(where, "transform is not finite");
        if (Status s = visit(n, world, path); !s.ok) return s;
        path.push_back(n);
        for (int child : nd.children)
            if (Status s = node(child, world, true); !s.ok) return s;
        path.pop_back();
        return Status::success();
    }
};

}  // namespace

Status walkNodes(const std::string& file, const tinygltf::Model& model, const std::vector<int>& roots,
                 bool apply_root_transform, const NodeVisitor& visit) {
    Walk walk{file, model, visit, {}, 0};
    for (int r : roots)
        if (Status s = walk.node(r, Affine{}, apply_root_transform); !s.ok) return s;
    return Status::success();
}

}  // namespace apparent
