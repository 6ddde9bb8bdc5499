// What needs the whole sequence (SequenceModel::finish, glb.h): the animation's keys, the
// reflections' nodes and the target frames' weights, then the JSON chunk written from the model.
#include <algorithm>
#include <cmath>
#include <map>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "exporters/glb/glb.h"
#include "exporters/gltf_json.h"
#include "mesh4d/angles.h"

namespace apparent::glb {

std::string SequenceModel::finish(double far) {
    // Clip planes in light-seconds: 1e-3 of, and 10 times, the farthest apparent point's
    // distance (the validator requires zfar > znear).
    far = far > 0 ? far : 1.0;

    const std::vector<std::pair<int, int>> samplers = animationSamplers();
    reflectionNodes();
    morphWeights();
    return jsonChunk(*this, samplers, far);
}

std::vector<std::pair<int, int>> SequenceModel::animationSamplers() {
    // STEP scale channels, at most 3 keys each so the file grows linearly with the frame
    // count: scale 0 until k/fps, 1 during frame k, 0 from (k+1)/fps on. The last frame keeps
    // scale 1 at the final key n/fps, which closes the sequence so that it lasts 1/fps too
    // (with one key per frame the last frame would have zero length).
    // All key times in one view, the distinct scale sequences (a handful: frame scales repeat)
    // in another, each channel's accessors pointing into them.
    const size_t n = frames;
    std::vector<float> all_times, all_scales;
    std::vector<std::pair<size_t, size_t>> time_keys(n);  // offset (floats) and count per frame
    std::vector<size_t> scale_key(n);                   // offset (floats) of the frame's scales
    std::map<std::vector<float>, size_t> distinct;
    std::vector<float> scales;
    for (size_t k = 0; k < n; ++k) {
        scales.clear();
        time_keys[k] = {all_times.size(), 0};
        auto key = [&](size_t i, float v) {
            all_times.push_back(float(double(i) / info.fps));
            scales.insert(scales.end(), {v, v, v});
            ++time_keys[k].second;
        };
        const float shown = frame_scales[k];
        if (k > 0) key(0, 0.0f);
        key(k, shown);
        key(k + 1, k + 1 == n ? shown : 0.0f);
        auto it = distinct.find(scales);
        if (it == distinct.end()) {
            it = distinct.emplace(scales, all_scales.size()).first;
            all_scales.insert(all_scales.end(), scales.begin(), scales.end());
        }
        scale_key[k] = it->second;
    }
    const int times_view = b.addView(all_times.data(), all_times.size() * 4, 0);
    const int scales_view = b.addView(all_scales.data(), all_scales.size() * 4, 0);
    std::map<size_t, int> scale_accessors;  // by offset
    std::vector<std::pair<int, int>> samplers(n);  // per frame, its input and output accessors
    for (size_t k = 0; k < n; ++k) {
        const auto [offset, count] = time_keys[k];
        const double lo = all_times[offset], hi = all_times[offset + count - 1];
        samplers[k].first =
            b.addAccessor(times_view, TINYGLTF_COMPONENT_TYPE_FLOAT, false, count, 4 * offset, &lo, &hi, 1);
        auto sa = scale_accessors.find(scale_key[k]);
        if (sa == scale_accessors.end())
            sa = scale_accessors
                     .emplace(scale_key[k], b.addAccessor(scales_view, TINYGLTF_COMPONENT_TYPE_FLOAT, true, count,
                                                          4 * scale_key[k]))
                     .first;
        samplers[k].second = sa->second;
    }
    return samplers;
}

// The reflections' nodes, children of their frame nodes (so shown and hidden with them).
void SequenceModel::reflectionNodes() {
    for (const Reflection& r : reflections) {
        gltfjson::Node child;
        child.name = reflectionName(b.nodes[1 + r.frame].name, r.mirror);
        child.mesh = r.mesh;
        child.has_mirror = true;
        child.mirror = r.mirror;
        b.nodes.push_back(std::move(child));
        b.nodes[1 + r.frame].children.push_back(int(b.nodes.size()) - 1);
    }
}

// The target frames' weights: the first `place` of the run's targets at 1 (cumulative
// differences), written as integers.
void SequenceModel::morphWeights() {
    for (const MorphNode& m : morph_nodes) {
        std::vector<int>& w = b.nodes[m.node].weights;
        w.assign(runs[m.run], 0);
        std::fill(w.begin(), w.begin() + std::ptrdiff_t(m.place), 1);
    }
}

namespace {

// A look's material (JSON text) with its texture references moved by `offset`.
std::string renumbered(const std::string& material, int offset) {
    if (offset == 0) return material;
    nlohmann::json j = nlohmann::json::parse(material);
    gltfjson::moveTextureIndices(&j, offset);
    return j.dump();
}

// A key and its array of records, strings or numbers (records and strings: left out when empty).
template <class Records>
void array(gltfjson::Text* t, const char* key, const Records& records) {
    if (records.empty()) return;
    t->key(key);
    t->open('[');
    for (const auto& r : records) gltfjson::write(t, r);
    t->close(']');
}

void strings(gltfjson::Text* t, const char* key, const std::vector<std::string>& list) {
    if (list.empty()) return;
    t->key(key);
    t->open('[');
    for (const std::string& s : list) t->value(s);
    t->close(']');
}

void numbers(gltfjson::Text* t, const char* key, const double* v, size_t count) {
    t->key(key);
    t->open('[');
    for (size_t i = 0; i < count; ++i) t->value(v[i]);
    t->close(']');
}

// One animation "frames" of STEP scale channels: channel k shows and hides frame node 1 + k.
void writeAnimation(gltfjson::Text* t, size_t n, const std::vector<std::pair<int, int>>& samplers) {
    t->key("animations");
    t->open('[');
    t->open('{');
    t->key("channels");
    t->open('[');
    for (size_t k = 0; k < n; ++k) {
        t->open('{');
        t->key("sampler");
        t->value(uint64_t(k));
        t->key("target");
        t->open('{');
        t->key("node");
        t->value(uint64_t(1 + k));
        t->key("path");
        t->value("scale");
        t->close('}');
        t->close('}');
    }
    t->close(']');
    t->key("name");
    t->value("frames");
    t->key("samplers");
    t->open('[');
    for (const auto& [input, output] : samplers) {
        t->open('{');
        t->key("input");
        t->value(input);
        t->key("interpolation");
        t->value("STEP");
        t->key("output");
        t->value(output);
        t->close('}');
    }
    t->close(']');
    t->close('}');
    t->close(']');
}

void writeAsset(gltfjson::Text* t) {
    t->key("asset");
    t->open('{');
    t->key("generator");
    t->value("apparent");
    t->key("version");
    t->value("2.0");
    t->close('}');
}

// Buffer 0: the GLB BIN chunk (its size: what the sink received); with meshopt buffer 1,
// the fallback buffer without data.
void writeBuffers(gltfjson::Text* t, const GlbBuilder& b) {
    t->key("buffers");
    t->open('[');
    t->open('{');
    t->key("byteLength");
    t->value(uint64_t(b.sinkSize()));
    t->close('}');
    if (std::any_of(b.views.begin(), b.views.end(), [](const gltfjson::BufferView& v) { return v.meshopt; })) {
        t->open('{');
        t->key("byteLength");
        t->value(uint64_t(b.fallback_size));
        t->key("extensions");
        t->open('{');
        t->key("EXT_meshopt_compression");
        t->open('{');
        t->key("fallback");
        t->value(true);
        t->close('}');
        t->close('}');
        t->close('}');
    }
    t->close(']');
}

// Clip planes in light-seconds: 1e-3 of, and 10 times, `far`.
// An orthographic camera (scene camera.projection): xmag and ymag are half the view's width and
// height, the height for a 16:9 screen (the raytracer's default picture), znear 0 at the image plane.
void writeCamera(gltfjson::Text* t, const SequenceInfo& info, double far) {
    t->key("cameras");
    t->open('[');
    t->open('{');
    if (info.camera.orthographic()) {
        t->key("orthographic");
        t->open('{');
        t->key("xmag");
        t->value(0.5 * info.camera.width);
        t->key("ymag");
        t->value(0.5 * info.camera.width * 9.0 / 16.0);
        t->key("zfar");
        t->value(10 * far);
        t->key("znear");
        t->value(0.0);
        t->close('}');
        t->key("type");
        t->value("orthographic");
        t->close('}');
        t->close(']');
        return;
    }
    t->key("perspective");
    t->open('{');
    const double yfov = info.camera.fov_deg * mesh4d::kPi / 180.0;
    if (yfov > 0) {
        t->key("yfov");
        t->value(yfov);
    }
    t->key("zfar");
    t->value(10 * far);
    t->key("znear");
    t->value(1e-3 * far);
    t->close('}');
    t->key("type");
    t->value("perspective");
    t->close('}');
    t->close(']');
}

// One material per object: a thin shell seen from both sides (the flanges), blended
// when not opaque (e.g. a mirror, to show the reflections behind it). With --shade
// doppler COLOR_0 holds the whole shaded colour (glTF multiplies it with the factor): a
// white factor, the plain colour kept in extras for viewers that switch between the two.
// An object whose look the file carries gets its input's materials instead (surface_look.h),
// their textures renumbered for the file; with --shade doppler its COLOR_0 is the modulation of
// them (mesh4d/doppler_colour.h).
void writeMaterials(gltfjson::Text* t, const SequenceModel& model) {
    const SequenceInfo& info = model.info;
    const bool shade_doppler = model.shade_doppler;
    if (!info.objects.empty()) {
        t->key("materials");
        t->open('[');
        for (size_t i = 0; i < info.objects.size(); ++i) {
            const ExportObject& o = info.objects[i];
            const int count = (i + 1 < model.material_first.size() ? model.material_first[i + 1] : model.materials) -
                              model.material_first[i];
            if (o.look && count == int(o.look->materials.size()) && model.lookPlace(o.look.get())) {
                const int offset = model.lookPlace(o.look.get())->texture;
                for (const std::string& m : o.look->materials) t->raw(renumbered(m, offset));
                continue;
            }
            t->open('{');
            if (o.base_color[3] < 1) {
                t->key("alphaMode");
                t->value("BLEND");
            }
            t->key("doubleSided");
            t->value(true);
            if (o.emissive[0] > 0 || o.emissive[1] > 0 || o.emissive[2] > 0) numbers(t, "emissiveFactor", o.emissive.data(), 3);
            const double plain[4] = {o.base_color[0], o.base_color[1], o.base_color[2], o.base_color[3]};
            const double white[4] = {1.0, 1.0, 1.0, o.base_color[3]};
            if (shade_doppler) {
                t->key("extras");
                t->open('{');
                numbers(t, "base_color", plain, 4);
                t->close('}');
            }
            if (!o.name.empty()) {
                t->key("name");
                t->value(o.name);
            }
            t->key("pbrMetallicRoughness");
            t->open('{');
            const double* factor = shade_doppler ? white : plain;
            // glTF's default factor (1, 1, 1, 1) is left out.
            if (std::any_of(factor, factor + 4, [](double c) { return !(std::fabs(c - 1.0) < 1e-12); }))
                numbers(t, "baseColorFactor", factor, 4);
            t->key("metallicFactor");
            t->value(o.metallic);
            t->key("roughnessFactor");
            t->value(o.roughness);
            t->close('}');
            t->close('}');
        }
        t->close(']');
    }
}

// The scene's light, resolved (ExportLight): "ambient", then "position" (a point light) or
// "direction" (towards a distant light), and with the default key light "key_direction" and
// "key_weight" (docs/GLTF.md "Scene extras").
void writeLight(gltfjson::Text* t, const ExportLight& light) {
    t->key("light");
    t->open('{');
    t->key("ambient");
    t->value(light.ambient);
    const mesh4d::Vec3& main = light.point ? light.position : light.direction;
    const double v[3] = {main.x, main.y, main.z};
    numbers(t, light.point ? "position" : "direction", v, 3);
    if (light.key_weight > 0) {
        const double k[3] = {light.key_direction.x, light.key_direction.y, light.key_direction.z};
        numbers(t, "key_direction", k, 3);
        t->key("key_weight");
        t->value(light.key_weight);
    }
    t->close('}');
}

// The looks' arrays, in look order (SequenceModel::looks): `count` of each look's, `write` one.
template <class Count, class Write>
void writeLookArray(gltfjson::Text* t, const SequenceModel& model, const char* key, const Count& count,
                    const Write& write) {
    size_t n = 0;
    for (const auto& p : model.looks) n += count(*p.look);
    if (n == 0) return;
    t->key(key);
    t->open('[');
    for (const auto& p : model.looks) write(p);
    t->close(']');
}

// The images: their views (written with the first frame) and types.
void writeImages(gltfjson::Text* t, const SequenceModel& model) {
    size_t view = 0;
    writeLookArray(t, model, "images", [](const SurfaceLook& l) { return l.images.size(); },
                   [&](const SequenceModel::LookPlace& p) {
                       for (const LookImage& im : p.look->images) {
                           t->open('{');
                           t->key("bufferView");
                           t->value(model.image_views[view++]);
                           t->key("mimeType");
                           t->value(im.mime_type);
                           if (!im.name.empty()) {
                               t->key("name");
                               t->value(im.name);
                           }
                           t->close('}');
                       }
                   });
}

void writeSamplers(gltfjson::Text* t, const SequenceModel& model) {
    writeLookArray(t, model, "samplers", [](const SurfaceLook& l) { return l.samplers.size(); },
                   [&](const SequenceModel::LookPlace& p) {
                       for (const std::string& s : p.look->samplers) t->raw(s);
                   });
}

// The textures, their image and sampler moved to the look's place in the file.
void writeTextures(gltfjson::Text* t, const SequenceModel& model) {
    writeLookArray(t, model, "textures", [](const SurfaceLook& l) { return l.textures.size(); },
                   [&](const SequenceModel::LookPlace& p) {
                       for (const std::string& tex : p.look->textures) {
                           nlohmann::json j = nlohmann::json::parse(tex);
                           if (j.contains("source")) j["source"] = j["source"].get<int>() + p.image;
                           if (j.contains("sampler")) j["sampler"] = j["sampler"].get<int>() + p.sampler;
                           t->raw(j.dump());
                       }
                   });
}

// Scene extras: what was computed, in which units, at which camera times, in which light.
void writeScenes(gltfjson::Text* t, const SequenceModel& model) {
    const SequenceInfo& info = model.info;
    t->key("scenes");
    t->open('[');
    t->open('{');
    t->key("extras");
    t->open('{');
    t->key("first_frame");
    t->value(int64_t(int(model.first_frame)));
    t->key("fps");
    t->value(info.fps);
    t->key("frame_times");
    t->open('[');
    for (const double time : model.frame_times) t->value(time);
    t->close(']');
    writeLight(t, info.light);
    t->key("model");
    t->value(info.model);
    t->key("objects");
    t->open('[');
    for (const ExportObject& o : info.objects) t->value(o.name);
    t->close(']');
    t->key("scene_file");
    t->value(info.scene_path);
    t->key("tolerance");
    t->value(info.tolerance);
    t->key("units");
    t->value(info.units);
    t->close('}');
    if (!info.model.empty()) {
        t->key("name");
        t->value(info.model);
    }
    t->key("nodes");
    t->open('[');
    for (const int node : model.scene_nodes) t->value(node);
    t->close(']');
    t->close('}');
    t->close(']');
}

}  // namespace

std::string jsonChunk(const SequenceModel& model, const std::vector<std::pair<int, int>>& samplers, double far) {
    const GlbBuilder& b = model.b;
    gltfjson::Text text;
    gltfjson::Text* t = &text;
    t->out.reserve(256 * (b.accessors.size() + b.views.size() + b.nodes.size()) + 1024);
    t->open('{');
    array(t, "accessors", b.accessors);
    writeAnimation(t, model.frames, samplers);
    writeAsset(t);
    array(t, "bufferViews", b.views);
    writeBuffers(t, b);
    writeCamera(t, model.info, far);
    strings(t, "extensionsRequired", model.extensions);
    strings(t, "extensionsUsed", model.extensions_used);
    writeImages(t, model);
    writeMaterials(t, model);
    array(t, "meshes", b.meshes);
    array(t, "nodes", b.nodes);
    writeSamplers(t, model);
    t->key("scene");
    t->value(0);
    writeScenes(t, model);
    writeTextures(t, model);
    t->close('}');
    return std::move(text.out);
}

}  // namespace apparent::glb
