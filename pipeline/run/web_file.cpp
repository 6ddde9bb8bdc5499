#include "pipeline/run/web_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "exporters/atomic_file.h"
#include "exporters/gltf_json.h"
#include "mesh4d/angles.h"
#include "pipeline/input/gltf_document.h"
#include "pipeline/input/gltf_nodes.h"
#include "pipeline/input/scene_fields.h"

namespace apparent {

using mesh4d::Vec3;
using nlohmann::json;

namespace {

constexpr int kFloat = 5126, kUnsignedInt = 5125, kUnsignedShort = 5123;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// A number as JSON: an integral double as an integer ("2", not "2.0"; it reads back as the same
// double), every other one as nlohmann writes doubles (the shortest form that reads back the same).
json num(double v) {
    if (v == std::floor(v) && std::fabs(v) < 1e15 && !(v == 0 && std::signbit(v))) return json((long long)v);
    return json(v);
}
json array3(const Vec3& v) { return json::array({num(v.x), num(v.y), num(v.z)}); }
// A float32 bound as its shortest decimal ("0.05", which reads back as the same float).
json shortestFloat(float f) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof(text), f).ptr;
    return num(std::strtod(std::string(text, end).c_str(), nullptr));
}

// +0 in every component (a -0 is written: it can reach the outputs' signs).
bool plusZero(double v) { return v == 0 && !std::signbit(v); }
bool plusZero(const Vec3& v) { return plusZero(v.x) && plusZero(v.y) && plusZero(v.z); }

// The BIN chunk and the views and accessors over it.
class Buffers {
public:
    json views = json::array(), accessors = json::array();
    std::string bin;

    int view(const void* data, size_t bytes, int target) {
        bin.append((const char*)data, bytes);
        json v = {{"buffer", 0}, {"byteOffset", bin.size() - bytes}, {"byteLength", bytes}};
        if (target) v["target"] = target;
        bin.resize((bin.size() + 3) & ~size_t(3), '\0');  // every view starts 4-aligned
        views.push_back(v);
        return int(views.size()) - 1;
    }

    // A float accessor of `components` per element (VEC2, VEC3, VEC4), with min and max when asked.
    int floats(const std::vector<float>& values, int components, int target, bool bounds) {
        const char* types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
        const size_t count = values.size() / size_t(components);
        json a = {{"bufferView", view(values.data(), values.size() * 4, target)}, {"componentType", kFloat},
                  {"count", count}, {"type", types[components]}};
        if (bounds) {
            json lo = json::array(), hi = json::array();
            for (int c = 0; c < components; ++c) {
                float l = INFINITY, h = -INFINITY;
                for (size_t i = 0; i < count; ++i) {
                    l = std::min(l, values[i * size_t(components) + size_t(c)]);
                    h = std::max(h, values[i * size_t(components) + size_t(c)]);
                }
                lo.push_back(shortestFloat(l));
                hi.push_back(shortestFloat(h));
            }
            a["min"] = lo;
            a["max"] = hi;
        }
        accessors.push_back(a);
        return int(accessors.size()) - 1;
    }

    // Indices as uint16 when `vertices` fit (half the bytes), else uint32.
    int indices(const std::vector<uint32_t>& values, size_t vertices) {
        int view_index = 0, type = kUnsignedInt;
        if (vertices <= 65535) {
            const std::vector<uint16_t> narrow(values.begin(), values.end());
            view_index = view(narrow.data(), narrow.size() * 2, kElementArrayBuffer);
            type = kUnsignedShort;
        } else {
            view_index = view(values.data(), values.size() * 4, kElementArrayBuffer);
        }
        accessors.push_back({{"bufferView", view_index}, {"componentType", type}, {"count", values.size()}, {"type", "SCALAR"}});
        return int(accessors.size()) - 1;
    }
};


// The glTF document as it grows: meshes, the look's lists, and the rounding each mesh met.
struct Document {
    Buffers buffers;
    json meshes = json::array(), materials = json::array(), textures = json::array(), samplers = json::array(),
         images = json::array();
    std::set<std::string> extensions;
};

// Float32 of a double, and whether the double was one already.
struct Rounding {
    double largest = 0;  // largest |float(x) - x| of positions
    size_t attributes_changed = 0;
    std::vector<float> of(const std::vector<double>& values, size_t* changed) {
        std::vector<float> f(values.size());
        for (size_t i = 0; i < values.size(); ++i) {
            f[i] = float(values[i]);
            if (double(f[i]) != values[i]) ++*changed;
        }
        return f;
    }
};

// Writes `mesh` as one glTF mesh and returns its index; `note` gets a line when values changed.
int writeMesh(Document* doc, const LoadedMesh& mesh, const std::string& name, std::string* note) {
    const std::vector<Vec3>& p = mesh.mesh.positions;
    const auto& tris = mesh.mesh.triangles;
    const SurfaceLook* look = mesh.look.get();
    // Step: the look's materials, textures, samplers and images, placed after those written so far.
    const int material_offset = int(doc->materials.size()), texture_offset = int(doc->textures.size());
    std::vector<int> material_index;  // look material -> glTF material (-1: glTF's default)
    if (look) {
        const int sampler_offset = int(doc->samplers.size()), image_offset = int(doc->images.size());
        int written = 0;
        for (const std::string& m : look->materials) {
            // glTF's default material is "{}" in the look: written as none, as the input had it,
            // unless the mesh's colour came from a material (the reader's has_color).
            if (m == "{}" && !mesh.has_color) {
                material_index.push_back(-1);
                continue;
            }
            json j = json::parse(m);
            gltfjson::moveTextureIndices(&j, texture_offset);
            doc->materials.push_back(j);
            material_index.push_back(material_offset + written++);
        }
        for (const std::string& t : look->textures) {
            json j = json::parse(t);
            if (j.contains("source")) j["source"] = j["source"].get<int>() + image_offset;
            if (j.contains("sampler")) j["sampler"] = j["sampler"].get<int>() + sampler_offset;
            doc->textures.push_back(j);
        }
        for (const std::string& s : look->samplers) doc->samplers.push_back(json::parse(s));
        for (const LookImage& im : look->images) {
            json j = {{"bufferView", doc->buffers.view(im.bytes.data(), im.bytes.size(), 0)}, {"mimeType", im.mime_type}};
            if (!im.name.empty()) j["name"] = im.name;
            doc->images.push_back(j);
        }
        doc->extensions.insert(look->extensions.begin(), look->extensions.end());
    }
    auto materialOf = [&](size_t t) { return look && !look->triangle_material.empty() ? int(look->triangle_material[t]) : -1; };

    // Step: runs of triangles of one material, and whether their vertices are contiguous ranges.
    struct Run {
        size_t first, last;  // triangles [first, last)
        uint32_t lo, hi;     // the vertices they use, [lo, hi]
    };
    std::vector<Run> runs;
    for (size_t t = 0; t < tris.size(); ++t) {
        const auto [lo, hi] = std::minmax({tris[t][0], tris[t][1], tris[t][2]});
        if (runs.empty() || materialOf(t) != materialOf(runs.back().first)) runs.push_back({t, t, lo, hi});
        Run& r = runs.back();
        r.last = t + 1;
        r.lo = std::min(r.lo, lo);
        r.hi = std::max(r.hi, hi);
    }
    bool ranges = true;
    for (size_t k = 1; k < runs.size(); ++k) ranges = ranges && runs[k].lo > runs[k - 1].hi;

    // Step: the vertex attributes, once for the whole mesh when materials share vertices (every
    // primitive then reads them: gltf_reader.h), else per run over its range.
    json shared_attributes;
    Rounding rounding;
    auto attributesOf = [&](const std::vector<uint32_t>& vertices) {
        std::vector<double> pos, uv0, uv1, rgba;
        for (uint32_t v : vertices) {
            for (int c = 0; c < 3; ++c) {
                pos.push_back(p[v][c]);
                rounding.largest = std::max(rounding.largest, std::fabs(double(float(p[v][c])) - p[v][c]));
            }
            if (look && !look->texcoord.empty()) uv0.insert(uv0.end(), &look->texcoord[2 * v], &look->texcoord[2 * v] + 2);
            if (look && !look->texcoord1.empty()) uv1.insert(uv1.end(), &look->texcoord1[2 * v], &look->texcoord1[2 * v] + 2);
            if (look && !look->color.empty()) rgba.insert(rgba.end(), &look->color[4 * v], &look->color[4 * v] + 4);
        }
        size_t unused = 0;
        json attributes = {{"POSITION", doc->buffers.floats(rounding.of(pos, &unused), 3, kArrayBuffer, true)}};
        if (!uv0.empty()) attributes["TEXCOORD_0"] = doc->buffers.floats(rounding.of(uv0, &rounding.attributes_changed), 2, kArrayBuffer, false);
        if (!uv1.empty()) attributes["TEXCOORD_1"] = doc->buffers.floats(rounding.of(uv1, &rounding.attributes_changed), 2, kArrayBuffer, false);
        if (!rgba.empty()) attributes["COLOR_0"] = doc->buffers.floats(rounding.of(rgba, &rounding.attributes_changed), 4, kArrayBuffer, false);
        return attributes;
    };
    if (!ranges) {
        std::vector<uint32_t> all(p.size());
        for (uint32_t v = 0; v < all.size(); ++v) all[v] = v;
        shared_attributes = attributesOf(all);
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const Vec3& v : p)
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], v[c]);
            hi[c] = std::max(hi[c], v[c]);
        }
    // Step: one primitive per run.
    json primitives = json::array();
    for (size_t k = 0; k < runs.size(); ++k) {
        std::vector<uint32_t> vertices, local;  // the run's vertices, and its triangles' corners among them
        if (ranges) {
            const uint32_t begin = k == 0 ? 0 : runs[k].lo, end = k + 1 == runs.size() ? uint32_t(p.size()) : runs[k + 1].lo;
            for (uint32_t v = begin; v < end; ++v) vertices.push_back(v);
            for (size_t t = runs[k].first; t < runs[k].last; ++t)
                for (uint32_t v : tris[t]) local.push_back(v - begin);
        } else {
            for (size_t t = runs[k].first; t < runs[k].last; ++t)
                for (uint32_t v : tris[t]) local.push_back(v);
        }
        const json attributes = ranges ? attributesOf(vertices) : shared_attributes;
        json prim = {{"attributes", attributes}, {"indices", doc->buffers.indices(local, ranges ? vertices.size() : p.size())}};
        const int m = materialOf(runs[k].first);
        if (m >= 0 && material_index[size_t(m)] >= 0) prim["material"] = material_index[size_t(m)];
        primitives.push_back(prim);
    }
    doc->meshes.push_back({{"name", name}, {"primitives", primitives}});

    // Step: what float32 changed, relative to the mesh's size.
    const double diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    std::string changed;
    if (rounding.largest > 0)
        changed = "its vertex positions to float32 (moved up to " + formatNumber(rounding.largest) + ", " +
                  formatNumber(rounding.largest / (diagonal > 0 ? diagonal : 1)) + " of its bounding-box diagonal)";
    if (rounding.attributes_changed)
        changed += (changed.empty() ? "" : "; ") + std::to_string(rounding.attributes_changed) +
                   " texture coordinate or colour values to float32";
    if (!changed.empty()) *note = name + ": the web file rounds " + changed;
    return int(doc->meshes.size()) - 1;
}

// Whether two meshes read are the same, values and look alike.
bool sameMesh(const LoadedMesh& a, const LoadedMesh& b) {
    if (a.mesh.positions != b.mesh.positions || a.mesh.triangles != b.mesh.triangles || a.has_color != b.has_color ||
        a.color != b.color || !a.look != !b.look)
        return false;
    if (!a.look) return true;
    const SurfaceLook &la = *a.look, &lb = *b.look;
    if (la.texcoord != lb.texcoord || la.texcoord1 != lb.texcoord1 || la.color != lb.color ||
        la.triangle_material != lb.triangle_material || la.materials != lb.materials || la.textures != lb.textures ||
        la.samplers != lb.samplers || la.extensions != lb.extensions || la.images.size() != lb.images.size())
        return false;
    for (size_t i = 0; i < la.images.size(); ++i)
        if (la.images[i].bytes != lb.images[i].bytes || la.images[i].mime_type != lb.images[i].mime_type ||
            la.images[i].name != lb.images[i].name)
            return false;
    return true;
}

// The object fields of one object (scene_fields.h), as its node's extras.
json objectExtras(const ObjectSpec& o) {
    json x = json::object();
    if (!plusZero(o.t0)) x["t0"] = num(o.t0);
    if (o.keys) {
        // A keyframed path's velocity is its mean (gltf_scene.h): the channels state the motion.
    } else if (o.speed == ObjectSpec::Speed::Velocity) {
        if (!plusZero(o.velocity)) x["velocity"] = array3(o.velocity);
    } else {
        x["direction"] = array3(o.direction_given);  // as written: normalised again on reading
        if (o.speed == ObjectSpec::Speed::Gamma) x["gamma"] = num(o.gamma);
        else x["rapidity"] = num(o.rapidity);
    }
    if (!plusZero(o.rotation_deg)) x["rotation_deg"] = array3(o.rotation_deg);
    if (o.scale != Vec3{1, 1, 1}) x["scale"] = array3(o.scale);
    if (o.mirror) x["mirror"] = true;
    if (o.exists_from > -INFINITY || o.exists_to < INFINITY)
        x["exists"] = {o.exists_from > -INFINITY ? num(o.exists_from) : json(nullptr),
                       o.exists_to < INFINITY ? num(o.exists_to) : json(nullptr)};
    if (o.material.given) {
        const ObjectSpec::Material& m = o.material;
        x["material"] = {{"base_color", m.base_color}, {"metallic", m.metallic}, {"roughness", m.roughness},
                         {"emissive", m.emissive}};
    }
    if (!plusZero(o.angular_velocity)) x["angular_velocity"] = array3(o.angular_velocity);
    if (!plusZero(o.acceleration)) x["acceleration"] = array3(o.acceleration);
    if (o.kinds.orbit)
        x["orbit"] = {{"center", array3(o.kinds.orbit->center)}, {"axis", array3(o.orbit_axis_given)},
                      {"speed", num(o.kinds.orbit->speed)}, {"orientation", o.kinds.orbit->locked ? "locked" : "fixed"}};
    // A node is an object when its extras hold an object field (gltf_scene.h): t0 = 0 at least.
    if (x.empty()) x["t0"] = 0;
    return x;
}

// The camera node: glTF cameras look down their local -Z with +Y up (glTF 2.0 section 3.10.1).
json cameraNode(const CameraSpec& c, json* cameras) {
    const Vec3 f = (c.look_at - c.position) / mesh4d::norm(c.look_at - c.position);
    const Vec3 r0 = mesh4d::cross(f, c.up), r = r0 / mesh4d::norm(r0), u = mesh4d::cross(r, f);
    // The rotation whose columns are r, u, -f, as a unit quaternion (Shepperd's method).
    const double m[3][3] = {{r.x, u.x, -f.x}, {r.y, u.y, -f.y}, {r.z, u.z, -f.z}};
    double q[4];  // x, y, z, w
    const double trace = m[0][0] + m[1][1] + m[2][2];
    if (trace > 0) {
        const double s = 2 * std::sqrt(1 + trace);
        q[3] = s / 4, q[0] = (m[2][1] - m[1][2]) / s, q[1] = (m[0][2] - m[2][0]) / s, q[2] = (m[1][0] - m[0][1]) / s;
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        const double s = 2 * std::sqrt(1 + m[0][0] - m[1][1] - m[2][2]);
        q[3] = (m[2][1] - m[1][2]) / s, q[0] = s / 4, q[1] = (m[0][1] + m[1][0]) / s, q[2] = (m[0][2] + m[2][0]) / s;
    } else if (m[1][1] > m[2][2]) {
        const double s = 2 * std::sqrt(1 + m[1][1] - m[0][0] - m[2][2]);
        q[3] = (m[0][2] - m[2][0]) / s, q[0] = (m[0][1] + m[1][0]) / s, q[1] = s / 4, q[2] = (m[1][2] + m[2][1]) / s;
    } else {
        const double s = 2 * std::sqrt(1 + m[2][2] - m[0][0] - m[1][1]);
        q[3] = (m[1][0] - m[0][1]) / s, q[0] = (m[0][2] + m[2][0]) / s, q[1] = (m[1][2] + m[2][1]) / s, q[2] = s / 4;
    }
    json camera;
    if (c.orthographic()) {
        // xmag is half the view's width (the reader doubles it, exactly); ymag is for viewers.
        camera = {{"type", "orthographic"},
                  {"orthographic", {{"xmag", c.width / 2}, {"ymag", c.width / 2}, {"znear", 0.0}, {"zfar", 1e12}}}};
    } else {
        // yfov such that the reader's yfov * 180 / pi is fov_deg again, when a neighbour of the
        // nearest double does it.
        double yfov = c.fov_deg * mesh4d::kPi / 180;
        for (int step = 0; step < 8 && yfov * 180.0 / mesh4d::kPi != c.fov_deg; ++step)
            yfov = std::nextafter(yfov, yfov * 180.0 / mesh4d::kPi < c.fov_deg ? INFINITY : -INFINITY);
        camera = {{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 1e-3}}}};
    }
    cameras->push_back(camera);
    json node = {{"name", "camera"}, {"camera", int(cameras->size()) - 1}, {"translation", array3(c.position)},
                 {"rotation", {q[0], q[1], q[2], q[3]}}};
    json x = json::object();
    if (c.instant_delay != 0) x["instant_delay"] = num(c.instant_delay);
    if (!plusZero(c.velocity)) x["velocity"] = array3(c.velocity);
    // look_at and up as given: the node's rotation has an up orthogonal to the view, and the
    // default light follows up (scene_fields.h readLight).
    x["look_at"] = array3(c.look_at);
    x["up"] = array3(c.up);
    node["extras"] = x;
    return node;
}

// The scene's extras: frames, model, tolerance and a light other than the default.
json sceneExtras(const Scene& s, Model model) {
    json x = {{"frames", {{"start", num(s.frames.start)}, {"end", num(s.frames.end)}, {"fps", num(s.frames.fps)}}},
              {"model", modelName(model)}};
    if (s.tolerance_relative > 0) x["tolerance"] = formatNumber(s.tolerance_relative) + "x";
    else if (s.tolerance == 0) x["tolerance"] = "vertex";
    else x["tolerance"] = num(s.tolerance);
    // The default light (no `light` in the scene) is the one with a key light (scene.h LightSpec).
    if (s.light.key_weight == 0) {
        json light = {{"ambient", num(s.light.ambient)}};
        if (s.light.kind == LightSpec::Kind::Point) light["position"] = array3(s.light.position);
        else light["direction"] = array3(s.light.direction_given);
        x["light"] = light;
    }
    return x;
}

// A float accessor's values as the file stores them (`components` per element), read through its
// view's stride; false when they do not lie inside the buffer.
bool storedFloats(const tinygltf::Model& m, int index, int components, std::vector<float>* out) {
    if (index < 0 || size_t(index) >= m.accessors.size()) return false;
    const tinygltf::Accessor& a = m.accessors[size_t(index)];
    if (a.componentType != kFloat || a.sparse.isSparse || a.bufferView < 0 || size_t(a.bufferView) >= m.bufferViews.size()) return false;
    const tinygltf::BufferView& v = m.bufferViews[size_t(a.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size()) return false;
    const std::vector<unsigned char>& data = m.buffers[size_t(v.buffer)].data;
    const size_t element = 4 * size_t(components), stride = v.byteStride ? v.byteStride : element;
    const size_t first = v.byteOffset + a.byteOffset;
    if (a.count > 0 && (first + (a.count - 1) * stride + element > data.size() || first + (a.count - 1) * stride + element > v.byteOffset + v.byteLength))
        return false;
    out->resize(a.count * size_t(components));
    for (size_t i = 0; i < a.count; ++i) std::memcpy(out->data() + i * size_t(components), data.data() + first + i * stride, element);
    return true;
}

// A keyframed object's node as its glTF scene gives it: the node's own translation, rotation and
// scale (the path's keys are relative to them), and its translation and rotation channels copied
// value for value (float32 as stored) into `animation`. The node must be a root of the scene's
// default scene (a parent's transform would have to be written too). Fails naming the field.
Status keyedNode(const std::string& file, const ObjectSpec& o, Buffers* buffers, json* node, json* animation) {
    std::shared_ptr<const GltfDocument> doc;
    if (Status s = openGltf(file, MeshLimits{}, &doc); !s.ok) return s;
    const tinygltf::Model& m = doc->model;
    int n = -1;
    for (size_t i = 0; i < m.nodes.size(); ++i)
        if (m.nodes[i].name == o.name) n = n == -1 ? int(i) : -2;
    const int si = defaultSceneIndex(m);
    const std::string where = "nodes[" + std::to_string(n) + "]";
    if (n < 0 || si < 0) return Status::failure(file + ": " + o.keys_field + ": the keyframed node '" + o.name + "' is not one node of the file (the web file)");
    const auto& roots = m.scenes[size_t(si)].nodes;
    if (std::find(roots.begin(), roots.end(), n) == roots.end())
        return Status::failure(file + ": " + where + ": a keyframed object under a parent node is not carried by the web file yet");
    const tinygltf::Node& source = m.nodes[size_t(n)];
    if (source.translation.size() == 3) (*node)["translation"] = source.translation;
    if (source.rotation.size() == 4) (*node)["rotation"] = source.rotation;
    if (source.scale.size() == 3) (*node)["scale"] = source.scale;
    for (size_t ai = 0; ai < m.animations.size(); ++ai)
        for (size_t ci = 0; ci < m.animations[ai].channels.size(); ++ci) {
            const tinygltf::AnimationChannel& c = m.animations[ai].channels[ci];
            if (c.target_node != n || (c.target_path != "translation" && c.target_path != "rotation")) continue;
            const std::string field = "animations[" + std::to_string(ai) + "].channels[" + std::to_string(ci) + "]";
            if (c.sampler < 0 || size_t(c.sampler) >= m.animations[ai].samplers.size())
                return Status::failure(file + ": " + field + ".sampler: out of range (the web file)");
            const tinygltf::AnimationSampler& sampler = m.animations[ai].samplers[size_t(c.sampler)];
            std::vector<float> times, values;
            if (!storedFloats(m, sampler.input, 1, &times) ||
                !storedFloats(m, sampler.output, c.target_path == "translation" ? 3 : 4, &values))
                return Status::failure(file + ": " + field + ": the keys are not float32 values inside their buffer (the web file)");
            const int input = buffers->floats(times, 1, 0, true);
            const int output = buffers->floats(values, c.target_path == "translation" ? 3 : 4, 0, false);
            (*animation)["samplers"].push_back({{"input", input}, {"output", output}, {"interpolation", sampler.interpolation}});
            (*animation)["channels"].push_back({{"sampler", (*animation)["samplers"].size() - 1},
                                                {"target", {{"node", -1}, {"path", c.target_path}}}});
        }
    return Status::success();
}

// The GLB container (glTF 2.0 section 4.4): header, JSON chunk (space-padded), BIN chunk.
std::string glb(const std::string& json_text, const std::string& bin) {
    auto u32 = [](std::string* out, uint32_t v) { out->append((const char*)&v, 4); };
    std::string j = json_text;
    j.resize((j.size() + 3) & ~size_t(3), ' ');
    std::string b = bin;
    b.resize((b.size() + 3) & ~size_t(3), '\0');
    std::string out;
    u32(&out, 0x46546C67);  // "glTF"
    u32(&out, 2);
    u32(&out, uint32_t(12 + 8 + j.size() + (b.empty() ? 0 : 8 + b.size())));
    u32(&out, uint32_t(j.size()));
    u32(&out, 0x4E4F534A);  // "JSON"
    out += j;
    if (!b.empty()) {
        u32(&out, uint32_t(b.size()));
        u32(&out, 0x004E4942);  // "BIN\0"
        out += b;
    }
    return out;
}

}  // namespace

Status writeWebFile(const Scene& scene, Model model, const MeshLimits& limits, const std::string& path,
                    WebFileReport* report) {
    *report = WebFileReport{};
    auto refuse = [&](const std::string& field, const std::string& problem) {
        return Status::failure(scene.path + ": " + field + ": " + problem + " (the web file, --format web)");
    };
    // Step: what the web file cannot carry.
    if (scene.units != LengthUnit::LightSecond)
        return refuse("units", "a metre scene is not carried: a glTF scene is read in light-seconds");
    std::set<std::string> names;
    for (const ObjectSpec& o : scene.objects) {
        if (o.name.empty() || o.name.find('#') != std::string::npos)
            return refuse(o.field_path + ".name", "'" + o.name + "': an object of the web file needs a name without '#'");
        if (!names.insert(o.name).second) return refuse(o.field_path + ".name", "'" + o.name + "' names two objects");
    }

    // Step: the rest meshes, each file once, as their readers give them.
    Document doc;
    std::map<std::string, int> mesh_of;
    std::vector<std::pair<LoadedMesh, int>> written;  // meshes by content: two nodes of one glTF mesh
    json nodes = json::array(), cameras = json::array(), roots = json::array();
    json animation = {{"name", "paths"}, {"channels", json::array()}, {"samplers", json::array()}};
    MeshLimits mesh_limits = limits;
    mesh_limits.scene_path = scene.path;
    for (const ObjectSpec& o : scene.objects) {
        auto [it, fresh] = mesh_of.try_emplace(o.mesh_path, 0);
        if (fresh) {
            LoadedMesh mesh;
            MeshWarnings warnings;
            if (Status s = readMesh(o.mesh_path, mesh_limits, &mesh, &warnings); !s.ok) return s;
            const auto same = std::find_if(written.begin(), written.end(), [&](const auto& w) { return sameMesh(w.first, mesh); });
            if (same != written.end()) {
                it->second = same->second;
            } else {
                std::string note;
                it->second = writeMesh(&doc, mesh, o.name, &note);
                if (!note.empty()) report->notes.push_back(note);
                written.emplace_back(std::move(mesh), it->second);
            }
        }
        // Step: the object's node: translation, its linear map as a matrix, its fields in extras.
        json node = {{"name", o.name}, {"mesh", it->second}};
        const std::array<double, 9> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
        if (o.keys) {
            // Step: a keyframed path: the source node's transform and channels (their target set below).
            const size_t first_channel = animation["channels"].size();
            if (Status s = keyedNode(scene.path, o, &doc.buffers, &node, &animation); !s.ok) return s;
            for (size_t c = first_channel; c < animation["channels"].size(); ++c)
                animation["channels"][c]["target"]["node"] = nodes.size();
        } else if (o.linear == identity) {
            node["translation"] = array3(o.position);
        } else {
            const auto& l = o.linear;
            node["matrix"] = {l[0], l[1], l[2], 0.0, l[3], l[4], l[5], 0.0, l[6], l[7], l[8], 0.0,
                              o.position.x, o.position.y, o.position.z, 1.0};
        }
        node["extras"] = objectExtras(o);
        roots.push_back(nodes.size());
        nodes.push_back(node);
    }
    roots.push_back(nodes.size());
    nodes.push_back(cameraNode(scene.camera, &cameras));

    // Step: the document and its container.
    json gltf = {{"asset", {{"version", "2.0"}, {"generator", "apparent (web file)"}}},
                 {"scene", 0},
                 {"scenes", json::array({{{"name", "apparent"}, {"nodes", roots}, {"extras", sceneExtras(scene, model)}}})},
                 {"nodes", nodes},
                 {"cameras", cameras},
                 {"meshes", doc.meshes},
                 {"accessors", doc.buffers.accessors},
                 {"bufferViews", doc.buffers.views},
                 {"buffers", json::array({{{"byteLength", doc.buffers.bin.size()}}})}};
    for (const auto& [key, list] : {std::pair<const char*, const json*>{"materials", &doc.materials}, {"textures", &doc.textures},
                                    {"samplers", &doc.samplers}, {"images", &doc.images}})
        if (!list->empty()) gltf[key] = *list;
    if (!animation["channels"].empty()) gltf["animations"] = json::array({animation});
    if (!doc.extensions.empty()) gltf["extensionsUsed"] = std::vector<std::string>(doc.extensions.begin(), doc.extensions.end());
    const std::string bytes = glb(gltf.dump(), doc.buffers.bin);
    AtomicOutput out(path);
    std::string error;
    report->write_failed = true;
    if (out.fd() < 0) return Status::failure(out.openError());
    if (!out.commitBytes(bytes, &error)) return Status::failure(error);
    report->write_failed = false;
    report->bytes = bytes.size();
    return Status::success();
}

}  // namespace apparent
