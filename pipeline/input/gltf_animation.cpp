#include "pipeline/input/gltf_animation.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "pipeline/input/scene_fields.h"

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

    // Accessor `index` as `components` FLOAT values per element, keys x per_key elements expected
    // (keys 0: any count up to kMaxKeys), every range checked before anything is allocated.
    bool floats(int index, const std::string& where, int components, const char* type_name, size_t keys, size_t per_key,
                std::vector<double>* values) {
        const size_t count = keys * per_key;
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
            return fail(aw + ".count", std::to_string(a.count) + " values for " + std::to_string(keys) + " key times" +
                                           (per_key == 3 ? " (CUBICSPLINE: 3 per key, " : " (") + where + ")");
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
            if (interp != "LINEAR" && interp != "STEP" && interp != "CUBICSPLINE")
                return Status::failure(file + ": " + sw + ".interpolation: '" + interp + "' (expected LINEAR, STEP or CUBICSPLINE)");
            p.present = true;
            p.step = interp == "STEP";
            p.cubic = interp == "CUBICSPLINE";
            p.field = where;
            if (!r.floats(sm.input, sw + ".input", 1, "SCALAR", 0, 1, &p.times)) return r.status;
            for (size_t k = 1; k < p.times.size(); ++k)
                if (!(p.times[k] > p.times[k - 1]))
                    return Status::failure(file + ": " + sw + ".input: key times must increase: key " + std::to_string(k) + " at " +
                                           formatNumber(p.times[k]) + " s follows " + formatNumber(p.times[k - 1]) + " s");
            std::vector<double> values;
            const bool rot = path == "rotation";
            const size_t comps = rot ? 4 : 3;
            // CUBICSPLINE: in-tangent, value, out-tangent per key (glTF 2.0 appendix C).
            if (!r.floats(sm.output, sw + ".output", int(comps), rot ? "VEC4" : "VEC3", p.times.size(), p.cubic ? 3 : 1, &values))
                return r.status;
            if (p.cubic) {
                p.tangents.assign(2 * comps * p.times.size(), 0.0);
                std::vector<double> middle(comps * p.times.size());
                for (size_t k = 0; k < p.times.size(); ++k)
                    for (size_t c = 0; c < comps; ++c) {
                        p.tangents[(2 * k) * comps + c] = values[(3 * k) * comps + c];
                        p.tangents[(2 * k + 1) * comps + c] = values[(3 * k + 2) * comps + c];
                        middle[k * comps + c] = values[(3 * k + 1) * comps + c];
                    }
                values.swap(middle);
            }
            for (size_t k = 0; k < p.times.size(); ++k) {
                const double* v = &values[k * comps];
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
                if (p.cubic)  // the spline runs through the values as written (tangents scale with them)
                    p.rotations.back() = {v[3], v[0], v[1], v[2]};
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

namespace {
// The cubic Hermite spline of glTF 2.0 appendix C over key interval j at fraction f, per component:
// (2f^3 - 3f^2 + 1) v_j + d (f^3 - 2f^2 + f) b_j + (-2f^3 + 3f^2) v_{j+1} + d (f^3 - f^2) a_{j+1},
// d the interval's length, b the out-tangents and a the in-tangents.
void hermite(const AnimatedProperty& p, size_t comps, const double* v0, const double* v1, size_t j, double f, double* out) {
    const double d = p.times[j + 1] - p.times[j];
    const double f2 = f * f, f3 = f2 * f;
    const double* b0 = &p.tangents[(2 * j + 1) * comps];
    const double* a1 = &p.tangents[(2 * (j + 1)) * comps];
    for (size_t c = 0; c < comps; ++c)
        out[c] = (2 * f3 - 3 * f2 + 1) * v0[c] + d * (f3 - 2 * f2 + f) * b0[c] + (-2 * f3 + 3 * f2) * v1[c] + d * (f3 - f2) * a1[c];
}
}  // namespace

Vec3 translationAt(const AnimatedProperty& p, double t) {
    if (p.translations.size() == 1) return p.translations[0];
    double f = 0;
    const size_t j = interval(p.times, t, &f);
    if (p.step) return f < 1 ? p.translations[j] : p.translations[j + 1];
    if (p.cubic) {
        const Vec3 &a = p.translations[j], &b = p.translations[j + 1];
        const double v0[3] = {a.x, a.y, a.z}, v1[3] = {b.x, b.y, b.z};
        double out[3];
        hermite(p, 3, v0, v1, j, f, out);
        return {out[0], out[1], out[2]};
    }
    return p.translations[j] + (p.translations[j + 1] - p.translations[j]) * f;
}

Quat rotationAt(const AnimatedProperty& p, double t) {
    auto unit = [](const Quat& q) {
        const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
        return Quat{q.w / n, q.x / n, q.y / n, q.z / n};
    };
    if (p.rotations.size() == 1) return unit(p.rotations[0]);
    double f = 0;
    const size_t j = interval(p.times, t, &f);
    if (p.step) return f < 1 ? p.rotations[j] : p.rotations[j + 1];
    if (p.cubic) {  // components in glTF's order (x, y, z, w), then normalised (appendix C)
        const Quat &a = p.rotations[j], &b = p.rotations[j + 1];
        const double v0[4] = {a.x, a.y, a.z, a.w}, v1[4] = {b.x, b.y, b.z, b.w};
        double out[4];
        hermite(p, 4, v0, v1, j, f, out);
        return unit({out[3], out[0], out[1], out[2]});
    }
    return mesh4d::slerp(p.rotations[j], p.rotations[j + 1], f);
}

std::vector<double> cubicSamples(const AnimatedProperty& p, double scale) {
    std::vector<double> out;
    if (!p.cubic) return out;
    const size_t comps = p.rotations.empty() ? 3 : 4;
    const double eps = 1e-6 * scale;
    for (size_t j = 0; j + 1 < p.times.size(); ++j) {
        // max |p''| over the interval: p'' is linear in f, so at an end (per unit time: / d^2).
        const double d = p.times[j + 1] - p.times[j];
        const double* b0 = &p.tangents[(2 * j + 1) * comps];
        const double* a1 = &p.tangents[(2 * (j + 1)) * comps];
        double v0[4], v1[4];
        if (comps == 3) {
            const Vec3 &a = p.translations[j], &b = p.translations[j + 1];
            v0[0] = a.x, v0[1] = a.y, v0[2] = a.z, v1[0] = b.x, v1[1] = b.y, v1[2] = b.z;
        } else {
            const Quat &a = p.rotations[j], &b = p.rotations[j + 1];
            v0[0] = a.x, v0[1] = a.y, v0[2] = a.z, v0[3] = a.w, v1[0] = b.x, v1[1] = b.y, v1[2] = b.z, v1[3] = b.w;
        }
        double m0 = 0, m1 = 0;
        for (size_t c = 0; c < comps; ++c) {
            const double at0 = -6 * v0[c] - 4 * d * b0[c] + 6 * v1[c] - 2 * d * a1[c];
            const double at1 = 6 * v0[c] + 2 * d * b0[c] - 6 * v1[c] + 4 * d * a1[c];
            m0 += at0 * at0;
            m1 += at1 * at1;
        }
        const double M = std::sqrt(std::max(m0, m1)) / (d * d);
        // Sub-steps h with h^2 M / 8 <= eps: the chord of each within eps of the spline.
        const double n = M > 0 ? std::ceil(d / std::sqrt(8 * eps / M)) : 1.0;
        if (!(n <= double(kMaxKeys))) return {INFINITY};
        for (size_t i = 1; i < size_t(n); ++i) out.push_back(p.times[j] + d * double(i) / n);
        if (out.size() > kMaxKeys) return {INFINITY};
    }
    return out;
}

}  // namespace apparent
