#include "pipeline/input/gltf_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <set>

#include <tiny_gltf.h>

#include "pipeline/input/gltf_document.h"
#include "pipeline/input/gltf_look.h"
#include "pipeline/input/gltf_nodes.h"
#include "pipeline/input/mesh_check.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

const char* componentName(int c) {
    switch (c) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
    }
    return "unknown";
}

class Reader {
public:
    Reader(const std::string& file, const tinygltf::Model& model, const MeshLimits& limits, LoadedMesh* out,
           MeshWarnings* warnings)
        : file_(file), model_(model), limits_(limits), out_(out), warnings_(warnings) {}

    Status status;

    bool fail(const std::string& where, const std::string& problem) {
        if (status.ok) status = Status::failure(file_ + ": " + where + ": " + problem);
        return false;
    }

private:
    std::string file_;
    const tinygltf::Model& model_;
    MeshLimits limits_;
    LoadedMesh* out_;
    MeshWarnings* warnings_;
    size_t buffer_bytes_ = [this] {
        size_t n = 0;
        for (const auto& b : model_.buffers) n += b.data.size();
        return n;
    }();

    // Reads accessor `index` as `components` doubles per element, with every range checked and
    // sparse substitutions applied.
    // `integer`: indices (unsigned integers); else POSITION (FLOAT), or with `attribute` a vertex
    // attribute (FLOAT, or normalized UNSIGNED_BYTE or UNSIGNED_SHORT mapped to [0, 1]).
    bool readAccessor(int index, const std::string& where, int components, bool integer, std::vector<double>* values,
                      bool attribute = false) {
        if (index < 0 || size_t(index) >= model_.accessors.size())
            return fail(where, "accessor " + std::to_string(index) + " out of range (" + std::to_string(model_.accessors.size()) + " accessors)");
        const tinygltf::Accessor& a = model_.accessors[size_t(index)];
        const std::string aw = "accessors[" + std::to_string(index) + "]";
        const int ncomp = tinygltf::GetNumComponentsInType(uint32_t(a.type));
        if (ncomp != components) return fail(aw + ".type", "expected " + std::to_string(components) + " components, got " + std::to_string(ncomp));
        const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
        if (csize <= 0) return fail(aw + ".componentType", "invalid (" + std::to_string(a.componentType) + ")");
        const bool normalized = attribute && a.normalized &&
                                (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                 a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if (!integer && !normalized && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            return fail(aw + ".componentType", std::string(attribute ? "must be FLOAT or normalized UNSIGNED_BYTE or UNSIGNED_SHORT, got "
                                                                     : "POSITION must be FLOAT, got ") +
                                                   componentName(a.componentType));
        if (integer && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return fail(aw + ".componentType", std::string("indices must be unsigned integers, got ") + componentName(a.componentType));
        if (a.count == 0) return fail(aw + ".count", "is 0");
        const size_t count_limit = integer ? 3 * limits_.max_faces : limits_.max_vertices;
        if (a.count > count_limit)
            return fail(aw + ".count", std::to_string(a.count) + " exceeds the limit of " + std::to_string(count_limit) +
                                           (integer ? " (raise with --max-faces)" : " (raise with --max-vertices)"));
        const size_t elem = size_t(csize) * size_t(components);
        // Before allocating: elements without a bufferView are zeros plus sparse substitutions;
        // they may not outnumber the bytes of the file's buffers (any vertex a triangle uses is
        // named by at least one index byte), so a few hundred bytes cannot declare 50M elements.
        if (a.bufferView < 0 && a.count > buffer_bytes_ + 1)
            return fail(aw + ".count", std::to_string(a.count) + " elements without a bufferView, more than the " +
                                           std::to_string(buffer_bytes_) + " bytes of the file's buffers (refused)");

        auto decode = [&](const uint8_t* p, double* dst) {
            for (int c = 0; c < components; ++c) {
                const uint8_t* q = p + size_t(c) * size_t(csize);
                switch (a.componentType) {
                    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, q, 4); dst[c] = f; break; }
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: dst[c] = normalized ? *q / 255.0 : *q; break;
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, q, 2); dst[c] = normalized ? v / 65535.0 : v; break; }
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, q, 4); dst[c] = v; break; }
                }
            }
        };
        // A view's bytes [offset, offset + length) inside its buffer, checked.
        auto viewBytes = [&](int view_index, const std::string& vw, const uint8_t** base, size_t* length, size_t* stride) {
            if (view_index < 0 || size_t(view_index) >= model_.bufferViews.size())
                return fail(vw, "bufferView " + std::to_string(view_index) + " out of range (" + std::to_string(model_.bufferViews.size()) + " bufferViews)");
            const tinygltf::BufferView& v = model_.bufferViews[size_t(view_index)];
            const std::string bw = "bufferViews[" + std::to_string(view_index) + "]";
            if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size())
                return fail(bw + ".buffer", "out of range (" + std::to_string(model_.buffers.size()) + " buffers)");
            const auto& data = model_.buffers[size_t(v.buffer)].data;
            if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
                return fail(bw, "byteOffset " + std::to_string(v.byteOffset) + " + byteLength " + std::to_string(v.byteLength) +
                                    " exceeds the buffer's " + std::to_string(data.size()) + " bytes");
            *base = data.data() + v.byteOffset;
            *length = v.byteLength;
            *stride = v.byteStride ? v.byteStride : 0;
            return true;
        };

        // Step: dense data (absent bufferView means zeros, glTF 2.0 section 5.1.1).
        if (a.bufferView >= 0) {
            const uint8_t* base;
            size_t length, stride;
            if (!viewBytes(a.bufferView, aw + ".bufferView", &base, &length, &stride)) return false;
            if (stride == 0) stride = elem;
            if (stride < elem) return fail("bufferViews[" + std::to_string(a.bufferView) + "].byteStride", "smaller than an element");
            if (a.byteOffset > length || (a.count - 1) > (length - a.byteOffset - std::min(length - a.byteOffset, elem)) / stride ||
                a.byteOffset + (a.count - 1) * stride + elem > length)
                return fail(aw, "count " + std::to_string(a.count) + " with byteOffset " + std::to_string(a.byteOffset) +
                                    " reaches past bufferViews[" + std::to_string(a.bufferView) + "] (" + std::to_string(length) + " bytes)");
            // Allocated only now that the view holds every element.
            values->assign(a.count * size_t(components), 0.0);
            for (size_t i = 0; i < a.count; ++i) decode(base + a.byteOffset + i * stride, values->data() + i * size_t(components));
        }
        if (a.bufferView < 0) values->assign(a.count * size_t(components), 0.0);  // bounded above
        // Step: sparse substitutions.
        if (a.sparse.isSparse) {
            const auto& sp = a.sparse;
            const std::string sw = aw + ".sparse";
            if (sp.count <= 0 || size_t(sp.count) > a.count) return fail(sw + ".count", "out of range 1.." + std::to_string(a.count));
            const int isize = tinygltf::GetComponentSizeInBytes(uint32_t(sp.indices.componentType));
            if (isize != 1 && isize != 2 && isize != 4) return fail(sw + ".indices.componentType", "invalid");
            const uint8_t *ib, *vb;
            size_t ilen, vlen, unused;
            if (!viewBytes(sp.indices.bufferView, sw + ".indices.bufferView", &ib, &ilen, &unused)) return false;
            if (!viewBytes(sp.values.bufferView, sw + ".values.bufferView", &vb, &vlen, &unused)) return false;
            const size_t n = size_t(sp.count);
            if (size_t(sp.indices.byteOffset) > ilen || n * size_t(isize) > ilen - size_t(sp.indices.byteOffset))
                return fail(sw + ".indices", "reach past their bufferView");
            if (size_t(sp.values.byteOffset) > vlen || n * elem > vlen - size_t(sp.values.byteOffset))
                return fail(sw + ".values", "reach past their bufferView");
            for (size_t i = 0; i < n; ++i) {
                uint32_t target = 0;
                const uint8_t* q = ib + sp.indices.byteOffset + i * size_t(isize);
                if (isize == 1) target = *q;
                else if (isize == 2) { uint16_t v; std::memcpy(&v, q, 2); target = v; }
                else std::memcpy(&target, q, 4);
                if (target >= a.count) return fail(sw + ".indices", "index " + std::to_string(target) + " out of range (" + std::to_string(a.count) + " elements)");
                decode(vb + sp.values.byteOffset + i * elem, values->data() + size_t(target) * size_t(components));
            }
        }
        return true;
    }

    // The primitive's TEXCOORD_0, TEXCOORD_1 and COLOR_0 (for its `nv` vertices, just added) and the material of
    // its `nt` triangles, into the look (gltf_look.h); primitives without them get (0, 0), white
    // and glTF's default material.
    bool addLook(const tinygltf::Primitive& prim, const std::string& where, size_t nv, size_t nt) {
        look_.triangle_material.insert(look_.triangle_material.end(), nt, prim.material);
        if (nv == 0) return true;  // vertices an earlier primitive read (addMesh), or none
        for (const auto& [name, accessor] : prim.attributes) {
            const bool uv = name == "TEXCOORD_0" || name == "TEXCOORD_1", rgba = name == "COLOR_0";
            if (!uv && !rgba) {
                if (name != "POSITION" && name != "NORMAL" && name != "TANGENT") ignored_attributes_.insert(name);
                continue;
            }
            const int components = uv ? 2 : tinygltf::GetNumComponentsInType(
                                                 accessor >= 0 && size_t(accessor) < model_.accessors.size()
                                                     ? uint32_t(model_.accessors[size_t(accessor)].type)
                                                     : uint32_t(TINYGLTF_TYPE_VEC4));
            if (!uv && components != 3 && components != 4)
                return fail(where + ".attributes.COLOR_0", "must be VEC3 or VEC4");
            std::vector<double> values;
            if (!readAccessor(accessor, where + ".attributes." + name, components, false, &values, true)) return false;
            if (values.size() != nv * size_t(components))
                return fail(where + ".attributes." + name, "count " + std::to_string(values.size() / size_t(components)) +
                                                               " differs from POSITION's " + std::to_string(nv));
            for (double v : values)
                if (!std::isfinite(v)) return fail(where + ".attributes." + name, "a value is not finite");
            std::vector<double>& to = !uv ? look_.color : name == "TEXCOORD_0" ? look_.texcoord : look_.texcoord1;
            const size_t per = uv ? 2 : 4, first = out_->mesh.positions.size() - nv;
            to.resize(per * first, uv ? 0.0 : 1.0);  // earlier primitives without it
            for (size_t i = 0; i < nv; ++i)
                for (size_t c = 0; c < per; ++c) to.push_back(c < size_t(components) ? values[i * size_t(components) + c] : 1.0);
        }
        // Later primitives without an attribute: filled when the mesh is complete (finishLook).
        return true;
    }

public:
    // What addLook gathered, over every primitive read.
    GltfLookParts& look() { return look_; }
    const std::set<std::string>& ignoredAttributes() const { return ignored_attributes_; }

private:
    GltfLookParts look_;
    std::set<std::string> ignored_attributes_;

public:
    // The vertices and triangles mesh `mesh_index` adds per instance, from the accessors' counts
    // alone (nothing read); out-of-range references count 0 (addMesh refuses them).
    void countMesh(int mesh_index, size_t* vertices, size_t* triangles) const {
        *vertices = *triangles = 0;
        if (mesh_index < 0 || size_t(mesh_index) >= model_.meshes.size()) return;
        auto count = [&](int accessor) -> size_t {
            return accessor >= 0 && size_t(accessor) < model_.accessors.size() ? model_.accessors[size_t(accessor)].count : 0;
        };
        for (const tinygltf::Primitive& prim : model_.meshes[size_t(mesh_index)].primitives) {
            auto pos = prim.attributes.find("POSITION");
            if (pos == prim.attributes.end() || (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP)) continue;
            const size_t nv = count(pos->second), n = prim.indices >= 0 ? count(prim.indices) : nv;
            *vertices += nv;
            *triangles += prim.mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : (n >= 2 ? n - 2 : 0);
        }
    }

    // Adds the triangles of mesh `mesh_index` placed by `world` (a node's world transform).
    bool addMesh(int mesh_index, const Affine& world) {
        if (size_t(mesh_index) >= model_.meshes.size())
            return fail("nodes.mesh", "mesh " + std::to_string(mesh_index) + " out of range (" + std::to_string(model_.meshes.size()) + " meshes)");
        const tinygltf::Mesh& mesh = model_.meshes[size_t(mesh_index)];
        const bool mirrored = world.det3() < 0;  // a mirroring transform flips the winding
        // Primitives that read the same vertex accessors read the same vertices (an accessor is
        // its data): their first vertex here, by those accessors.
        std::map<std::vector<std::pair<std::string, int>>, std::pair<uint32_t, size_t>> shared;
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const std::string where = "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(p) + "]";
            // Step: which primitives hold surfaces.
            if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
                ++warnings_->points_lines_skipped;
                continue;
            }
            if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
                return fail(where + ".mode", "invalid (" + std::to_string(prim.mode) + ")");
            auto pos_it = prim.attributes.find("POSITION");
            if (pos_it == prim.attributes.end()) return fail(where + ".attributes", "no POSITION");

            // Step: positions, transformed to the node's world frame in double (once per set of
            // vertex accessors: a primitive sharing an earlier one's uses its vertices).
            std::vector<std::pair<std::string, int>> vertex_accessors;
            for (const auto& [name, accessor] : prim.attributes)
                if (name == "POSITION" || name == "TEXCOORD_0" || name == "TEXCOORD_1" || name == "COLOR_0")
                    vertex_accessors.emplace_back(name, accessor);
            const auto earlier = shared.find(vertex_accessors);
            const bool reused = earlier != shared.end();
            std::vector<double> pos;
            if (!reused && !readAccessor(pos_it->second, where + ".attributes.POSITION", 3, false, &pos)) return false;
            const size_t nv = reused ? earlier->second.second : pos.size() / 3;
            const uint32_t base = reused ? earlier->second.first : uint32_t(out_->mesh.positions.size());
            if (!reused) shared.emplace(vertex_accessors, std::make_pair(base, nv));
            if (!reused && out_->mesh.positions.size() + nv > limits_.max_vertices)
                return fail(where, "more than " + std::to_string(limits_.max_vertices) + " vertices in all (raise with --max-vertices)");
            for (size_t i = 0; i < pos.size() / 3; ++i) {
                const Vec3 v{pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
                if (!mesh4d::isFinite(v)) return fail(where + ".attributes.POSITION", "vertex " + std::to_string(i) + " is not finite");
                // Derived, not only read: a finite node scale can still overflow the product.
                const Vec3 placed = world.apply(v);
                if (!mesh4d::isFinite(placed))
                    return fail(where + ".attributes.POSITION", "vertex " + std::to_string(i) + " is not finite after the node transforms");
                out_->mesh.positions.push_back(placed);
            }

            // Step: indices, or 0..n-1 for non-indexed primitives.
            std::vector<double> idx;
            if (prim.indices >= 0) {
                if (!readAccessor(prim.indices, where + ".indices", 1, true, &idx)) return false;
            } else {
                idx.resize(nv);
                for (size_t i = 0; i < nv; ++i) idx[i] = double(i);
            }
            for (size_t i = 0; i < idx.size(); ++i)
                if (idx[i] >= double(nv))
                    return fail(where + ".indices", "index " + std::to_string((unsigned long long)idx[i]) + " out of range (" + std::to_string(nv) + " vertices)");

            // Step: triangles from lists, strips and fans (glTF 2.0 section 3.7.2.1).
            const size_t triangles_before = out_->mesh.triangles.size();
            auto add = [&](size_t a, size_t b, size_t c) {
                std::array<uint32_t, 3> t{base + uint32_t(idx[a]), base + uint32_t(idx[b]), base + uint32_t(idx[c])};
                if (mirrored) std::swap(t[1], t[2]);
                out_->mesh.triangles.push_back(t);
            };
            const size_t n = idx.size();
            if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
                if (n % 3) return fail(where + ".indices", "count " + std::to_string(n) + " is not a multiple of 3");
                for (size_t i = 0; i + 2 < n; i += 3) add(i, i + 1, i + 2);
            } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                ++warnings_->strips_fans_triangulated;
                for (size_t i = 0; i + 2 < n; ++i) i % 2 ? add(i + 1, i, i + 2) : add(i, i + 1, i + 2);
            } else {
                ++warnings_->strips_fans_triangulated;
                for (size_t i = 1; i + 1 < n; ++i) add(i, i + 1, 0);
            }
            if (out_->mesh.triangles.size() > limits_.max_faces)
                return fail(where, "more than " + std::to_string(limits_.max_faces) + " triangles in all (raise with --max-faces)");

            // Step: the look: texture coordinates, vertex colours and the triangles' material.
            if (!addLook(prim, where, reused ? 0 : nv, out_->mesh.triangles.size() - triangles_before)) return false;

            // Step: the first material with a base colour gives the object's colour.
            if (!out_->has_color && prim.material >= 0 && size_t(prim.material) < model_.materials.size()) {
                const auto& f = model_.materials[size_t(prim.material)].pbrMetallicRoughness.baseColorFactor;
                if (f.size() == 4) {
                    out_->has_color = true;
                    for (int c = 0; c < 4; ++c) out_->color[size_t(c)] = f[size_t(c)];
                }
            }
        }
        return true;
    }
};


}  // namespace

Status readGltf(const std::string& path_and_node, const MeshLimits& limits, LoadedMesh* out, MeshWarnings* warnings) {
    const auto hash = path_and_node.rfind('#');
    const std::string path = path_and_node.substr(0, hash);
    const std::string node_name = hash == std::string::npos ? "" : path_and_node.substr(hash + 1);
    *out = LoadedMesh{};
    std::shared_ptr<const GltfDocument> doc;
    if (Status s = openGltf(path, limits, &doc); !s.ok) return s;
    warnings->other.insert(warnings->other.end(), doc->warnings.begin(), doc->warnings.end());
    const tinygltf::Model& model = doc->model;

    // Step: choose the roots: one named node (in its own frame), or the whole file's.
    std::vector<int> roots;
    bool own_transform = true;
    if (!node_name.empty()) {
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (model.nodes[i].name == node_name) roots.push_back(int(i));
        if (roots.empty()) return Status::failure(path + ": nodes: no node named '" + node_name + "'");
        if (roots.size() > 1) return Status::failure(path + ": nodes: " + std::to_string(roots.size()) + " nodes are named '" + node_name + "'");
        own_transform = false;
    } else {
        roots = rootNodes(model);
    }
    // Skins and animations are not read: the meshes are taken as stored (their bind pose). A node
    // read in its own frame ("file.gltf#Node") leaves its own channels to the glTF scene, whose
    // object nodes follow them (gltf_scene.h): those alone are no reason to warn.
    bool animated = false;
    for (const auto& a : model.animations)
        for (const auto& ch : a.channels)
            if (own_transform || std::find(roots.begin(), roots.end(), ch.target_node) == roots.end()) animated = true;
    if (!model.skins.empty() || animated)
        warnings->other.push_back(std::to_string(model.skins.size()) + " skins and " + std::to_string(model.animations.size()) +
                                  " animations: skin and animation ignored: the bind pose is used");
    Reader reader(path, model, limits, out, warnings);
    // Step: count what the node instances add before reading any of it: a small file whose nodes
    // share children (a DAG) multiplies its meshes; the sum is what the limits bound.
    size_t instances = 0, total_vertices = 0, total_triangles = 0;
    const Status counted = walkNodes(path, model, roots, own_transform, [&](int node, const Affine&, const std::vector<int>&) {
        size_t nv = 0, nt = 0;
        reader.countMesh(model.nodes[size_t(node)].mesh, &nv, &nt);
        if (nt) ++instances;
        total_vertices += nv;
        total_triangles += nt;
        // One instance over a limit is refused by its accessor's count (readAccessor), naming it.
        if (instances > 1 && total_triangles > limits.max_faces)
            return Status::failure(path + ": nodes: " + std::to_string(instances) + " mesh instances hold more than " +
                                   std::to_string(limits.max_faces) + " triangles after node expansion (raise with --max-faces)");
        if (instances > 1 && total_vertices > limits.max_vertices)
            return Status::failure(path + ": nodes: " + std::to_string(instances) + " mesh instances hold more than " +
                                   std::to_string(limits.max_vertices) + " vertices after node expansion (raise with --max-vertices)");
        return Status::success();
    });
    if (!counted.ok) return counted;
    const Status walked = walkNodes(path, model, roots, own_transform, [&](int node, const Affine& world, const std::vector<int>&) {
        const int mesh = model.nodes[size_t(node)].mesh;
        if (mesh >= 0 && !reader.addMesh(mesh, world)) return reader.status;
        return Status::success();
    });
    if (!walked.ok) return walked;

    // Step: what is left must be a surface.
    if (out->mesh.triangles.empty())
        return Status::failure(path + ": no triangles in " + (node_name.empty() ? "the scene" : "node '" + node_name + "'") +
                               (warnings->points_lines_skipped
                                    ? " (" + std::to_string(warnings->points_lines_skipped) + " point or line primitives skipped)"
                                    : std::string()));
    GltfLookParts& look = reader.look();
    warnings->degenerate_dropped += dropDegenerateTriangles(&out->mesh, &look.triangle_material);
    if (out->mesh.triangles.empty()) return Status::failure(path + ": every triangle is degenerate (zero area)");
    for (const std::string& name : reader.ignoredAttributes())
        warnings->other.push_back("attribute " + name + ": not carried to the outputs (TEXCOORD_0, TEXCOORD_1 and COLOR_0 are)");
    return buildGltfLook(path, *doc, std::move(look), out->mesh.positions.size(), warnings, &out->look);
}

}  // namespace apparent
