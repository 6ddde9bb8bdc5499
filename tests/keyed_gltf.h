// For the keyframe tests: a small glTF scene written here (JSON plus a .bin buffer), a camera at
// the origin looking down -Z and one object node holding a box of edge 1 (8 vertices, 12
// triangles), optionally animated by the channels given. Fields left at their defaults give a
// valid file; the hostile tests break one thing at a time.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace testkeys {

struct Channel {
    std::string path = "translation";     // target.path
    std::string interpolation = "LINEAR";
    std::vector<float> times;
    std::vector<float> values;            // 3 (translation, scale) or 4 (rotation, x y z w) per key
    std::string output_type;              // accessor type; default VEC3 / VEC4 from `path`
    int output_accessor = -1;             // >= 0: the sampler's output names this accessor instead
};

struct KeyedGltf {
    nlohmann::json object_extras = {{"t0", 0}};
    nlohmann::json scene_extras = {{"tolerance", "vertex"}, {"model", "relativistic"},
                                   {"frames", {{"start", 0}, {"end", 1}, {"fps", 10}}}};
    std::vector<double> translation{0, 0, -8};
    std::vector<double> rotation;  // x y z w; empty: none
    std::vector<double> parent_rotation;  // x y z w; non-empty: the box is the child of a node so turned
    std::vector<Channel> channels;

    // Writes dir/name.gltf and dir/name.bin; returns the .gltf path.
    std::string write(const std::string& dir, const std::string& name) const {
        using nlohmann::json;
        std::string blob;
        json views = json::array(), accessors = json::array();
        auto add = [&](const void* data, size_t bytes) {
            views.push_back({{"buffer", 0}, {"byteOffset", blob.size()}, {"byteLength", bytes}});
            blob.append(static_cast<const char*>(data), bytes);
            while (blob.size() % 4) blob.push_back('\0');
            return views.size() - 1;
        };
        std::vector<float> corners;
        for (int i = 0; i < 8; ++i)
            for (int c = 0; c < 3; ++c) corners.push_back((i >> c) & 1 ? 0.5f : -0.5f);
        // Two triangles per face, outward: the face of axis c at side s.
        std::vector<uint16_t> idx;
        const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
        for (const auto& f : faces)
            for (int t : {0, 1, 2, 0, 2, 3}) idx.push_back(uint16_t(f[t]));
        const size_t pv = add(corners.data(), corners.size() * 4);
        accessors.push_back({{"bufferView", pv}, {"componentType", 5126}, {"count", 8}, {"type", "VEC3"},
                             {"min", {-0.5, -0.5, -0.5}}, {"max", {0.5, 0.5, 0.5}}});
        const size_t iv = add(idx.data(), idx.size() * 2);
        accessors.push_back({{"bufferView", iv}, {"componentType", 5123}, {"count", idx.size()}, {"type", "SCALAR"}});
        json channels_json = json::array(), samplers = json::array();
        for (const Channel& ch : channels) {
            const size_t tv = add(ch.times.data(), ch.times.size() * 4);
            accessors.push_back({{"bufferView", tv}, {"componentType", 5126}, {"count", ch.times.size()}, {"type", "SCALAR"}});
            const size_t input = accessors.size() - 1;
            const int comps = ch.path == "rotation" ? 4 : 3;
            const std::string type = ch.output_type.empty() ? (comps == 4 ? "VEC4" : "VEC3") : ch.output_type;
            const size_t per = type == "VEC4" ? 4 : (type == "SCALAR" ? 1 : 3);
            const size_t ov = add(ch.values.data(), ch.values.size() * 4);
            accessors.push_back({{"bufferView", ov}, {"componentType", 5126}, {"count", ch.values.size() / per}, {"type", type}});
            const long output = ch.output_accessor >= 0 ? ch.output_accessor : long(accessors.size() - 1);
            samplers.push_back({{"input", input}, {"output", output}, {"interpolation", ch.interpolation}});
            channels_json.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", 1}, {"path", ch.path}}}});
        }
        json box = {{"name", "box"}, {"mesh", 0}, {"translation", translation}, {"extras", object_extras}};
        if (!rotation.empty()) box["rotation"] = rotation;
        json gltf = {
            {"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0, parent_rotation.empty() ? 1 : 2}}, {"extras", scene_extras}}}},
            {"nodes", {{{"name", "camera"}, {"camera", 0}}, box}},
            {"cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.01}, {"zfar", 1000}}}}}},
            {"meshes", {{{"name", "box"}, {"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
            {"accessors", accessors},
            {"bufferViews", views},
            {"buffers", {{{"byteLength", blob.size()}, {"uri", name + ".bin"}}}},
        };
        if (!parent_rotation.empty())
            gltf["nodes"].push_back({{"name", "frame"}, {"rotation", parent_rotation}, {"children", {1}}});
        if (!channels.empty()) gltf["animations"] = {{{"channels", channels_json}, {"samplers", samplers}}};
        std::ofstream(dir + "/" + name + ".bin", std::ios::binary) << blob;
        const std::string path = dir + "/" + name + ".gltf";
        std::ofstream(path) << gltf.dump();
        return path;
    }
};

}  // namespace testkeys
