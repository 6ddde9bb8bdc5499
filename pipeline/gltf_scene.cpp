#include "pipeline/gltf_scene.h"

#include <algorithm>
#include <filesystem>
#include <memory>
#include <set>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "mesh4d/angles.h"
#include "pipeline/gltf_document.h"
#include "pipeline/gltf_nodes.h"
#include "pipeline/scene_fields.h"

namespace apparent {

namespace fs = std::filesystem;
using mesh4d::Vec3;
using nlohmann::json;

namespace {

// A node that carries an object, as found by the walk.
struct ObjectNode {
    int node;
    Affine world;
    const json* extras;  // in the document
};

}  // namespace

Status loadGltfScene(const std::string& path, Scene* scene) {
    *scene = Scene{};
    scene->path = path;
    std::shared_ptr<const GltfDocument> doc;
    if (Status s = openGltf(path, MeshLimits{}, &doc); !s.ok) return s;
    const tinygltf::Model& model = doc->model;
    const int si = defaultSceneIndex(model);
    if (si < 0) return Status::failure(path + ": scenes: none (a scene file needs a scene whose nodes carry extras)");

    Status status;
    FieldReader r(path, &status);
    const std::vector<std::string> markers = objectMarkerKeys();

    // Step: walk the default scene's nodes once: the first camera node, and the object nodes in
    // walk order. A node whose extras hold only near-misses of object fields is reported.
    std::vector<ObjectNode> objects;
    std::vector<bool> is_object(model.nodes.size(), false);
    std::set<std::string> names;
    int camera_node = -1;
    Affine camera_world;
    std::string near_miss;  // the first such near-miss, for the message when no object is found
    const Status walked = walkNodes(path, model, model.scenes[size_t(si)].nodes, true,
                                    [&](int n, const Affine& world, const std::vector<int>& ancestors) {
        const std::string where = "nodes[" + std::to_string(n) + "]";
        const tinygltf::Node& node = model.nodes[size_t(n)];
        if (node.camera >= 0 && camera_node < 0 && size_t(node.camera) < model.cameras.size()) {
            camera_node = n;
            camera_world = world;
        }
        // A camera node without a mesh is the camera: its extras are camera fields (velocity,
        // instant_delay), even where their names are object fields too.
        if (node.camera >= 0 && node.mesh < 0) return Status::success();
        const json& ex = doc->node_extras[size_t(n)];
        if (!ex.is_object()) return Status::success();
        const bool marked = std::any_of(markers.begin(), markers.end(), [&](const std::string& k) { return ex.contains(k); });
        if (!marked) {
            for (auto it = ex.begin(); it != ex.end(); ++it) {
                const std::string near = it.key().rfind('_', 0) == 0 ? std::string() : nearestField(it.key(), markers);
                if (near.empty()) continue;
                const std::string at = where + ".extras." + it.key();
                r.warn(at, "looks like the object field " + near + ", but the node's extras hold none of the object fields (" +
                               fieldList(markers) + "), so the node is not an object");
                if (near_miss.empty()) near_miss = at + " looks like a misspelt " + near;
            }
            return Status::success();
        }
        for (int a : ancestors)
            if (is_object[size_t(a)])
                return Status::failure(path + ": " + where + ": is inside object nodes[" + std::to_string(a) + "] (objects cannot nest)");
        if (node.name.empty() || node.name.find('#') != std::string::npos)
            return Status::failure(path + ": " + where + ".name: an object node needs a name without '#'");
        if (!names.insert(node.name).second)
            return Status::failure(path + ": " + where + ".name: '" + node.name + "' names two object nodes");
        is_object[size_t(n)] = true;
        objects.push_back({n, world, &ex});
        return Status::success();
    });
    if (!walked.ok) return walked;

    // Step: the camera node. glTF cameras look down local -Z with +Y up.
    if (camera_node >= 0) {
        const tinygltf::Node& node = model.nodes[size_t(camera_node)];
        CameraSpec& c = scene->camera;
        const Vec3 pos = camera_world.apply({0, 0, 0});
        const Vec3 ahead = camera_world.apply({0, 0, -1}) - pos, up = camera_world.apply({0, 1, 0}) - pos;
        c.position = pos;
        c.look_at = pos + ahead / mesh4d::norm(ahead);
        c.up = up;
        const auto& cam = model.cameras[size_t(node.camera)];
        if (cam.type == "perspective") c.fov_deg = cam.perspective.yfov * 180.0 / mesh4d::kPi;
    }

    // Step: the scene's extras: light, frames, model and tolerance, read as in a JSON scene.
    const std::string top = "scenes[" + std::to_string(si) + "].extras";
    json sx = doc->scene_extras[size_t(si)];
    if (!sx.is_object()) {
        if (!sx.is_null()) r.warn(top, "expected an object of scene fields, got " + FieldReader::typeName(sx) + "; ignored");
        sx = json::object();
    }
    for (const char* key : {"camera", "objects"})
        if (sx.contains(key))
            r.warn(FieldReader::join(top, key), std::string("ignored: in glTF the ") +
                                                    (key[0] == 'c' ? "camera is the first node with a camera" : "objects are the nodes whose extras hold object fields"));
    sx.erase("camera");
    sx.erase("objects");
    r.warnUnknownKeys(sx, top, {"frames", "light", "model", "tolerance", "up"});
    readUpAxis(r, sx, top);  // before any vector is read
    // The camera node's extras (its velocity in the scene's axes, like every vector in extras).
    if (camera_node >= 0) {
        const std::string where = "nodes[" + std::to_string(camera_node) + "]";
        if (const json& cx = doc->node_extras[size_t(camera_node)]; cx.is_object() && !is_object[size_t(camera_node)]) {
            r.warnUnknownKeys(cx, where + ".extras", {"instant_delay", "velocity"});
            r.number(cx, "instant_delay", where + ".extras", &scene->camera.instant_delay);
            r.axisVec3(cx, "velocity", where + ".extras", &scene->camera.velocity);
        }
        checkCamera(r, where, scene->camera);
    }
    readLight(r, sx, top, scene);
    readFrames(r, sx, top, &scene->frames);
    readModelAndTolerance(r, sx, top, scene);

    // Step: the objects, read by the JSON scene's object readers from their nodes' extras.
    if (objects.empty() && !r.failed())
        r.fail("nodes", "no node carries object extras (" + fieldList(markers) + ") in scene " + std::to_string(si) +
                            (near_miss.empty() ? std::string() : "; " + near_miss));
    const std::string file = fs::path(path).filename().string();
    const fs::path folder = fs::path(path).parent_path();
    for (const ObjectNode& o : objects) {
        if (r.failed()) break;
        const tinygltf::Node& node = model.nodes[size_t(o.node)];
        ObjectSpec obj;
        obj.name = node.name;
        obj.mesh_text = file + "#" + node.name;
        obj.mesh_path = (folder / obj.mesh_text).lexically_normal().string();
        obj.position = o.world.apply({0, 0, 0});
        for (int c = 0; c < 3; ++c)
            for (int row = 0; row < 3; ++row) obj.linear[size_t(c * 3 + row)] = o.world.m[c * 4 + row];
        obj.field_path = "nodes[" + std::to_string(o.node) + "].extras";
        readObjectFields(r, *o.extras, obj.field_path, folder, ObjectSource::GltfNode, &obj);
        scene->objects.push_back(obj);
    }
    scene->warnings = r.warnings();
    return status;
}

}  // namespace apparent
