#include "exporters/gltf.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include <tiny_gltf.h>

#include "exporters/atomic_file.h"

namespace apparent {

namespace {

class GlbBuilder {
public:
    tinygltf::Model model;

    GlbBuilder() {
        model.asset.version = "2.0";
        model.asset.generator = "apparent";
        model.buffers.emplace_back();  // buffer 0 without uri: the GLB BIN chunk
    }

    int addView(const void* data, size_t n, int target) {
        auto& b = model.buffers[0].data;
        while (b.size() % 4) b.push_back(0);  // accessors need 4-byte alignment for float/uint32
        tinygltf::BufferView v;
        v.buffer = 0;
        v.byteOffset = b.size();
        v.byteLength = n;
        v.target = target;
        const auto* p = static_cast<const uint8_t*>(data);
        b.insert(b.end(), p, p + n);
        model.bufferViews.push_back(v);
        return int(model.bufferViews.size()) - 1;
    }

    int addAccessor(int view, int component, int type, size_t count, std::vector<double> min_v = {},
                    std::vector<double> max_v = {}) {
        tinygltf::Accessor a;
        a.bufferView = view;
        a.componentType = component;
        a.type = type;
        a.count = count;
        a.minValues = std::move(min_v);
        a.maxValues = std::move(max_v);
        model.accessors.push_back(a);
        return int(model.accessors.size()) - 1;
    }

    // Adds frame k's mesh; returns the mesh index, or -1 for an empty frame.
    int addFrameMesh(const ExportFrame& f, double origin[3], double* max_err) {
        const auto& m = f.mesh;
        if (m.triangles.empty()) return -1;
        // Step: local origin at the bounding-box centre, so float32 offsets are as small as possible.
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (const auto& p : m.positions)
            for (int c = 0; c < 3; ++c) { lo[c] = std::min(lo[c], p[c]); hi[c] = std::max(hi[c], p[c]); }
        for (int c = 0; c < 3; ++c) origin[c] = 0.5 * (lo[c] + hi[c]);

        // Step: float32 positions relative to the origin, with accessor bounds from the floats.
        std::vector<float> pos(3 * m.positions.size());
        std::vector<double> pmin(3, INFINITY), pmax(3, -INFINITY);
        for (size_t i = 0; i < m.positions.size(); ++i) {
            for (int c = 0; c < 3; ++c) {
                const double rel = m.positions[i][c] - origin[c];
                const float fv = float(rel);
                pos[3 * i + c] = fv;
                pmin[c] = std::min(pmin[c], double(fv));
                pmax[c] = std::max(pmax[c], double(fv));
                *max_err = std::max(*max_err, std::fabs(double(fv) - rel));
            }
        }
        std::vector<float> emission(m.emission_times.begin(), m.emission_times.end());
        std::vector<uint32_t> idx;
        idx.reserve(3 * m.triangles.size());
        for (const auto& t : m.triangles) idx.insert(idx.end(), t.begin(), t.end());

        const int pos_acc = addAccessor(addView(pos.data(), pos.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                                        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, m.positions.size(), pmin, pmax);
        const int em_acc = addAccessor(addView(emission.data(), emission.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, emission.size());
        const int idx_acc = addAccessor(addView(idx.data(), idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, idx.size());
        tinygltf::Primitive prim;
        prim.attributes["POSITION"] = pos_acc;
        prim.attributes["_EMISSION_TIME"] = em_acc;
        prim.indices = idx_acc;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        prim.material = 0;
        tinygltf::Mesh mesh;
        mesh.name = "frame_" + std::to_string(f.index);
        mesh.primitives.push_back(prim);
        model.meshes.push_back(mesh);
        return int(model.meshes.size()) - 1;
    }
};

tinygltf::Value number(double v) { return tinygltf::Value(v); }

}  // namespace

bool writeAnimatedGlb(const std::string& path, const std::vector<ExportFrame>& frames, const SequenceInfo& info,
                      GlbStats* stats, std::string* error) {
    if (frames.empty()) {
        *error = path + ": no frames to write";
        return false;
    }
    GlbBuilder b;
    tinygltf::Material mat;
    mat.name = "apparent";
    mat.pbrMetallicRoughness.baseColorFactor = {0.8, 0.55, 0.2, 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.doubleSided = true;  // thin shells such as the flanges are seen from both sides
    b.model.materials.push_back(mat);

    // Step: one node per frame, visible only in its own time slot.
    tinygltf::Scene scene;
    scene.name = info.model;
    const size_t n = frames.size();
    double max_err = 0;
    for (size_t k = 0; k < n; ++k) {
        tinygltf::Node node;
        node.name = "frame_" + std::to_string(frames[k].index);
        double origin[3] = {0, 0, 0};
        node.mesh = b.addFrameMesh(frames[k], origin, &max_err);
        if (node.mesh >= 0) node.translation = {origin[0], origin[1], origin[2]};
        node.scale = {k == 0 ? 1.0 : 0.0, k == 0 ? 1.0 : 0.0, k == 0 ? 1.0 : 0.0};
        b.model.nodes.push_back(node);
        scene.nodes.push_back(int(k));
    }

    // Step: STEP scale channels, at most 3 keys each so the file grows linearly with the frame
    // count: scale 0 until k/fps, 1 during frame k, 0 from (k+1)/fps on. The last frame keeps
    // scale 1 at the final key n/fps, which closes the sequence so that it lasts 1/fps too
    // (with one key per frame the last frame would have zero length).
    tinygltf::Animation anim;
    anim.name = "frames";
    for (size_t k = 0; k < n; ++k) {
        std::vector<float> times, scales;
        auto key = [&](size_t i, float s) {
            times.push_back(float(double(i) / info.fps));
            scales.insert(scales.end(), {s, s, s});
        };
        if (k > 0) key(0, 0.0f);
        key(k, 1.0f);
        key(k + 1, k + 1 == n ? 1.0f : 0.0f);
        const int in_acc = b.addAccessor(b.addView(times.data(), times.size() * 4, 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                         TINYGLTF_TYPE_SCALAR, times.size(), {double(times.front())},
                                         {double(times.back())});
        const int out_acc = b.addAccessor(b.addView(scales.data(), scales.size() * 4, 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                          TINYGLTF_TYPE_VEC3, times.size());
        tinygltf::AnimationSampler s;
        s.input = in_acc;
        s.output = out_acc;
        s.interpolation = "STEP";
        anim.samplers.push_back(s);
        tinygltf::AnimationChannel c;
        c.sampler = int(k);
        c.target_node = int(k);
        c.target_path = "scale";
        anim.channels.push_back(c);
    }
    b.model.animations.push_back(anim);

    // Step: scene extras: what was computed, in which units, at which camera times.
    tinygltf::Value::Array frame_times;
    for (const auto& f : frames) frame_times.push_back(number(f.t_c));
    tinygltf::Value::Object extras{{"model", tinygltf::Value(info.model)},
                                   {"tolerance", number(info.tolerance)},
                                   {"units", tinygltf::Value(std::string("light-seconds, seconds, c = 1"))},
                                   {"fps", number(info.fps)},
                                   {"first_frame", tinygltf::Value(int(frames.front().index))},
                                   {"frame_times", tinygltf::Value(frame_times)},
                                   {"scene_file", tinygltf::Value(info.scene_path)}};
    scene.extras = tinygltf::Value(extras);
    b.model.scenes.push_back(scene);
    b.model.defaultScene = 0;

    // Step: write through a temporary file.
    AtomicOutput out(path);
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&b.model, out.tempPath(), /*embedImages=*/true, /*embedBuffers=*/true,
                                     /*prettyPrint=*/false, /*writeBinary=*/true)) {
        *error = path + ": tinygltf could not write the file";
        return false;
    }
    if (stats) {
        std::error_code ec;
        stats->bytes = size_t(std::filesystem::file_size(out.tempPath(), ec));
        stats->max_position_error = max_err;
    }
    return out.commit(error);
}

}  // namespace apparent
