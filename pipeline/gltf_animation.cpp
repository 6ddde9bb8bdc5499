#include "pipeline/gltf_animation.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "pipeline/scene_fields.h"

namespace apparent {

using mesh4d::Quat;
using mesh4d::Vec3;

namespace {

struct Reader {
    const std::string& file;
    const tinygltf::Model& model;
    Status status;

    bool fail(const std::string& where, const std::string& problem) {
        if (status.ok) status = Status::failure(file + ": " + where + ": " + problem);
        return false;
    }

    // Accessor `index` as `components` FLOAT values per element, `count` elements expected (0: any
    // count up to kMaxKeys), every range checked before anything is allocated.
    bool floats(int index, const std::string& where, int components, const char* type_name, size_t count,
                std::vector<double>* values) {
        if (index < 0 || size_t(index) >= model.accessors.size())
            return fail(where, "accessor " + std::to_string(index) + " out of range (" + std::to_string(model.accessors.size()) +
                                   " accessors)");
        const tinygltf::Accessor& a = model.accessors[size_t(index)];
        const std::string aw = "accessors[" + std::to_string(index) + "]";
        if (tinygltf::GetNumComponentsInType(uint32_t(a.type)) != components)
            return fail(aw + ".type", std::string("expected ") + type_name + " for " + where);
        if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            return fail(aw + ".componentType", "expected FLOAT (5126) for " + where + " (integer keys are not read), got " +
                                                   std::to_string(a.componentType));
        if (a.sparse.isSparse) return fail(aw + ".sparse", "sparse animation accessors are not read");
        if (a.count == 0) return fail(aw + ".count", "is 0 (" + where + ")");
        if (a.count > kMaxKeys) return fail(aw + ".count", std::to_string(a.count) + " keys exceed the limit of " + std::to_string(kMaxKeys));
        if (count != 0 && a.count != count)
            return fail(aw + ".count", std::to_string(a.count) + " values for " + std::to_string(count) + " key times (" + where + ")");
        if (a.bufferView < 0 || size_t(a.bufferView) >= model.bufferViews.size())
            return fail(aw + ".bufferView", "missing or out of range (" + std::to_string(model.bufferViews.size()) + " bufferViews)");
        const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
        const std::string bw = "bufferViews[" + std::to_string(a.bufferView) + "]";
        if (v.buffer < 0 || size_t(v.buffer) >= model.buffers.size())
            return fail(bw + ".buffer", "out of range (" + std::to_string(model.buffers.size()) + " buffers)");
        const auto& data = model.buffers[size_t(v.buffer)].data;
        if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
            return fail(bw, "byteOffset " + std::to_string(v.byteOffset) + " + byteLength " + std::to_string(v.byteLength) +
                                " exceeds the buffer's " + std::to_string(data.size()) + " bytes");
        const size_t elem = 4 * size_t(components);
        const size_t stride = v.byteStride ? v.byteStride : elem;
        if (stride < elem) return fail(bw + ".byteStride", "smaller than an element");
        const size_t length = v.byteLength;
        if (a.byteOffset > length || length - a.byteOffset < elem || (a.count - 1) > (length - a.byteOffset - elem) / stride)
            return fail(aw, "count " + std::to_string(a.count) + " with byteOffset " + std::to_string(a.byteOffset) +
                                " reaches past " + bw + " (" + std::to_string(length) + " bytes)");
        const uint8_t* base = data.data() + v.byteOffset + a.byteOffset;
        values->assign(a.count * size_t(components), 0.0);
        for (size_t i = 0; i < a.count; ++i)
            for (int c = 0; c < components; ++c) {
                float f;
                std::memcpy(&f, base + i * stride + size_t(c) * 4, 4);
                if (!std::isfinite(f))
                    return fail(aw, "element " + std::to_string(i) + " is not finite (" + where + ")");
                (*values)[i * size_t(components) + size_t(c)] = f;
            }
        return true;
    }
};

}  // namespace

Status readNodeAnimation(const std::string& file, const tinygltf::Model& model, int node, NodeAnimation* out,
                         std::vector<std::pair<std::string, std::string>>* warnings) {
    *out = NodeAnimation{};
    Reader r{file, model, Status::success()};
    for (size_t ai = 0; ai < model.animations.size(); ++ai) {
        const tinygltf::Animation& anim = model.animations[ai];
        for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
            const tinygltf::AnimationChannel& ch = anim.channels[ci];
            if (ch.target_node != node) continue;
            const std::string where = "animations[" + std::to_string(ai) + "].channels[" + std::to_string(ci) + "]";
            const std::string& path = ch.target_path;
            if (path == "scale" || path == "weights") {
                warnings->push_back({where + ".target.path", "'" + path + "' of nodes[" + std::to_string(node) + "] is not modelled (" +
                                                                  (path == "scale" ? "the node's rest scale is used" : "the mesh's rest shape is used") + ")"});
                continue;
            }
            if (path != "translation" && path != "rotation") {
                warnings->push_back({where + ".target.path", "'" + path + "' is not modelled"});
                continue;
            }
            AnimatedProperty& p = path == "translation" ? out->translation : out->rotation;
            if (p.present)
                return Status::failure(file + ": " + where + ": a second channel animates nodes[" + std::to_string(node) + "]." +
                                       path + " (the first is " + p.field + "): keep one");
            if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
                return Status::failure(file + ": " + where + ".sampler: " + std::to_string(ch.sampler) + " out of range (" +
                                       std::to_string(anim.samplers.size()) + " samplers)");
            const tinygltf::AnimationSampler& sm = anim.samplers[size_t(ch.sampler)];
            const std::string sw = "animations[" + std::to_string(ai) + "].samplers[" + std::to_string(ch.sampler) + "]";
            const std::string interp = sm.interpolation.empty() ? "LINEAR" : sm.interpolation;
            if (interp == "CUBICSPLINE")
                return Status::failure(file + ": " + sw + ".interpolation: CUBICSPLINE is not modelled (export with LINEAR "
                                       "or STEP; in Blender, the glTF exporter's animation sampling gives LINEAR keys)");
            if (interp != "LINEAR" && interp != "STEP")
                return Status::failure(file + ": " + sw + ".interpolation: '" + interp + "' (expected LINEAR or STEP)");
            p.present = true;
            p.step = interp == "STEP";
            p.field = where;
            if (!r.floats(sm.input, sw + ".input", 1, "SCALAR", 0, &p.times)) return r.status;
            for (size_t k = 1; k < p.times.size(); ++k)
                if (!(p.times[k] > p.times[k - 1]))
                    return Status::failure(file + ": " + sw + ".input: key times must increase: key " + std::to_string(k) + " at " +
                                           formatNumber(p.times[k]) + " s follows " + formatNumber(p.times[k - 1]) + " s");
            std::vector<double> values;
            const bool rot = path == "rotation";
            if (!r.floats(sm.output, sw + ".output", rot ? 4 : 3, rot ? "VEC4" : "VEC3", p.times.size(), &values)) return r.status;
            for (size_t k = 0; k < p.times.size(); ++k) {
                const double* v = &values[k * (rot ? 4 : 3)];
                if (!rot) {
                    p.translations.push_back({v[0], v[1], v[2]});
                    continue;
                }
                // glTF stores (x, y, z, w).
                const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
                if (!(n >= 0.5 && n <= 2))
                    return Status::failure(file + ": " + sw + ".output: key " + std::to_string(k) + " is a quaternion of length " +
                                           formatNumber(n) + ", not a rotation (expected unit length)");
                p.rotations.push_back({v[3] / n, v[0] / n, v[1] / n, v[2] / n});
            }
        }
    }
    return Status::success();
}

namespace {
// The key interval holding t: i with times[i] <= t < times[i + 1], and the fraction; clamped.
size_t interval(const std::vector<double>& times, double t, double* f) {
    const size_t n = times.size();
    if (n < 2 || !(t > times[0])) {
        *f = 0;
        return 0;
    }
    if (!(t < times[n - 1])) {
        *f = 1;
        return n - 2;
    }
    const size_t j = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    *f = (t - times[j]) / (times[j + 1] - times[j]);
    return j;
}
}  // namespace

Vec3 translationAt(const AnimatedProperty& p, double t) {
    if (p.translations.size() == 1) return p.translations[0];
    double f = 0;
    const size_t j = interval(p.times, t, &f);
    if (p.step) return f < 1 ? p.translations[j] : p.translations[j + 1];
    return p.translations[j] + (p.translations[j + 1] - p.translations[j]) * f;
}

Quat rotationAt(const AnimatedProperty& p, double t) {
    if (p.rotations.size() == 1) return p.rotations[0];
    double f = 0;
    const size_t j = interval(p.times, t, &f);
    if (p.step) return f < 1 ? p.rotations[j] : p.rotations[j + 1];
    return mesh4d::slerp(p.rotations[j], p.rotations[j + 1], f);
}

}  // namespace apparent
