#include "pipeline/input/gltf_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <set>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "mesh4d/angles.h"
#include "pipeline/input/gltf_animation.h"
#include "pipeline/input/gltf_document.h"
#include "pipeline/input/gltf_nodes.h"
#include "pipeline/input/scene_fields.h"

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
    Affine parent;       // the world transform of the node's parent (identity for a root)
};

// A keyframed object (mesh4d/motion/keyed.h): the node's animated translation and rotation, composed
// with its parent's transform as its static ones are, become the lab path; the pose at t0 is the
// rest pose (obj->linear, obj->position) and each key's turn is relative to it.
Status readKeyframedPath(const std::string& path, const tinygltf::Model& model, const ObjectNode& o, const json& ex,
                         const NodeAnimation& an, ObjectSpec* obj) {
    const tinygltf::Node& node = model.nodes[size_t(o.node)];
    const std::string where = "nodes[" + std::to_string(o.node) + "]";
    const std::string field = an.translation.present ? an.translation.field : an.rotation.field;
    auto fail = [&](const std::string& at, const std::string& problem) { return Status::failure(path + ": " + at + ": " + problem); };
    if (node.matrix.size() == 16)
        return fail(where + ".matrix", "an animated node must give translation, rotation and scale, not a matrix (glTF 2.0 section 3.11)");
    // The velocity comes from the path; a spin or acceleration with it is not modelled.
    for (const ObjectField& f : objectFields())
        for (const std::string& key : f.keys)
            if (f.states_motion && ex.contains(key))
                return fail(where + ".extras." + key, "the node's path is keyframed (" + field + "): its motion comes from "
                                                      "the animation, remove " + key);
    if (ex.contains("mirror") && ex["mirror"] == true)
        return fail(where + ".extras.mirror", "a mirror must be at rest, and the node's path is keyframed (" + field + ")");
    // Step: STEP keys are a jump, an infinite speed, unless they hold one value.
    for (const AnimatedProperty* p : {&an.translation, &an.rotation}) {
        if (!p->present || !p->step) continue;
        for (size_t k = 1; k < p->times.size(); ++k) {
            const bool same = p == &an.translation ? p->translations[k] == p->translations[k - 1]
                                                   : (p->rotations[k].w == p->rotations[k - 1].w && p->rotations[k].x == p->rotations[k - 1].x &&
                                                      p->rotations[k].y == p->rotations[k - 1].y && p->rotations[k].z == p->rotations[k - 1].z);
            if (!same)
                return fail(p->field, "STEP interpolation jumps at lab time " + formatNumber(p->times[k]) +
                                          " s: an infinite speed (refused; use LINEAR)");
        }
    }
    // Step: the parent's linear part must turn the node's turns into turns: a similarity c U.
    const double* P = o.parent.m;
    const Vec3 c0{P[0], P[1], P[2]}, c1{P[4], P[5], P[6]}, c2{P[8], P[9], P[10]};
    const double scale2 = (mesh4d::norm2(c0) + mesh4d::norm2(c1) + mesh4d::norm2(c2)) / 3;
    const double off = std::max({std::fabs(mesh4d::norm2(c0) - scale2), std::fabs(mesh4d::norm2(c1) - scale2), std::fabs(mesh4d::norm2(c2) - scale2),
                                 std::fabs(mesh4d::dot(c0, c1)), std::fabs(mesh4d::dot(c1, c2)), std::fabs(mesh4d::dot(c0, c2))});
    if (an.rotation.present && !(scale2 > 0 && off <= 1e-9 * scale2))
        return fail(where, "an animated rotation under a parent whose transform shears or scales unequally is not a turn "
                           "(apply the parent's scale in the authoring tool)");
    const double c = std::sqrt(scale2);
    const double det_sign = o.parent.det3() < 0 ? -1.0 : 1.0;
    // Step: the key times of both channels, merged (a segment of either stays a segment).
    std::vector<double> times = an.translation.times;
    times.insert(times.end(), an.rotation.times.begin(), an.rotation.times.end());
    // A CUBICSPLINE channel is followed through LINEAR samples within 1e-6 of its spline
    // (gltf_animation.h cubicSamples; relative to the largest keyed translation, at least 1).
    for (const AnimatedProperty* p : {&an.translation, &an.rotation}) {
        double scale = 1;
        for (const Vec3& v : p->translations) scale = std::max(scale, mesh4d::norm(v));
        const std::vector<double> samples = cubicSamples(*p, scale);
        if (!samples.empty() && !std::isfinite(samples[0]))
            return fail(p->field, "CUBICSPLINE: following the spline within 1e-6 would take more than " + std::to_string(kMaxKeys) +
                                      " linear keys");
        times.insert(times.end(), samples.begin(), samples.end());
    }
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    if (times.size() > kMaxKeys)
        return fail(field, "more than " + std::to_string(kMaxKeys) + " keys in all");
    const Vec3 t_static = node.translation.size() == 3 ? Vec3{node.translation[0], node.translation[1], node.translation[2]} : Vec3{};
    const mesh4d::Quat r_static = node.rotation.size() == 4 ? mesh4d::Quat{node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]}
                                                            : mesh4d::Quat{};
    auto translation = [&](double t) { return an.translation.present ? translationAt(an.translation, t) : t_static; };
    auto rotation = [&](double t) { return an.rotation.present ? rotationAt(an.rotation, t) : r_static; };
    // The node's world transform at lab time t (its local TRS with the animated values).
    auto worldAt = [&](double t) {
        tinygltf::Node n;  // the transform's fields only
        const Vec3 tr = translation(t);
        const mesh4d::Quat r = rotation(t);
        n.translation = {tr.x, tr.y, tr.z};
        n.rotation = {r.x, r.y, r.z, r.w};
        n.scale = node.scale;
        return o.parent * localTransform(n);
    };
    // Step: the rest pose at t0, and the path: the centre and the turn relative to that pose (in
    // the lab: the node's turn conjugated by the parent's rotation U = P / c).
    const Affine rest = worldAt(obj->t0);
    obj->position = rest.apply({0, 0, 0});
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row) obj->linear[size_t(col * 3 + row)] = rest.m[col * 4 + row];
    const mesh4d::Quat r0_inv = mesh4d::conjugate(rotation(obj->t0));
    auto keys = std::make_shared<mesh4d::KeyPath>();
    for (double t : times) {
        keys->times.push_back(t);
        keys->positions.push_back(worldAt(t).apply({0, 0, 0}));
        const mesh4d::Quat d = mesh4d::multiply(rotation(t), r0_inv);
        const Vec3 v{d.x, d.y, d.z};
        // U v = (P v) / c (det U < 0: a mirroring parent turns the other way, -U is the rotation).
        const Vec3 pv = an.rotation.present ? Vec3{P[0] * v.x + P[4] * v.y + P[8] * v.z, P[1] * v.x + P[5] * v.y + P[9] * v.z,
                                                   P[2] * v.x + P[6] * v.y + P[10] * v.z} / c * det_sign
                                            : v;
        keys->turns.push_back({d.w, pv.x, pv.y, pv.z});
        if (!mesh4d::isFinite(keys->positions.back()))
            return fail(field, "the path at lab time " + formatNumber(t) + " s is not finite");
        if (!(std::isfinite(d.w) && std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z)))
            return fail(an.rotation.field, "the rotation at lab time " + formatNumber(t) + " s is not a turn (the spline passes through 0)");
    }
    // Step: the centre slower than light on every segment (the vertices are checked per model).
    const mesh4d::KeyedSpeed fastest = mesh4d::fastestCentreSegment(*keys);
    if (!(fastest.speed < 1))
        return fail(field, "the path moves at " + formatNumber(fastest.speed) + " (light-seconds per second) from lab time " +
                               formatNumber(fastest.lab_time) + " s, which must be < 1 (the speed of light)");
    obj->speed = ObjectSpec::Speed::Velocity;
    obj->velocity = mesh4d::meanVelocity(*keys);
    obj->keys = keys;
    obj->keys_field = field;
    return Status::success();
}

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
        Affine parent;
        for (int a : ancestors) parent = parent * localTransform(model.nodes[size_t(a)]);
        objects.push_back({n, world, &ex, parent});
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
        // An orthographic glTF camera: xmag is half the view's width (glTF 2.0 section 3.10.3).
        if (cam.type == "orthographic") {
            c.projection = CameraSpec::Projection::Orthographic;
            c.width = 2 * cam.orthographic.xmag;
            if (!(c.width > 0) || !std::isfinite(c.width))
                r.fail("cameras[" + std::to_string(node.camera) + "].orthographic.xmag",
                       "must be > 0 (half the view's width), got " + formatNumber(cam.orthographic.xmag));
        }
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
            r.warnUnknownKeys(cx, where + ".extras", {"instant_delay", "velocity", "look_at", "up"});
            r.number(cx, "instant_delay", where + ".extras", &scene->camera.instant_delay);
            r.axisVec3(cx, "velocity", where + ".extras", &scene->camera.velocity);
            // look_at and up as the JSON camera's, kept as written (the node's orientation gives an
            // up orthogonal to the view, and the default light follows up); the node must look the
            // same way (within 1e-6 rad) or the extras are ignored with a warning.
            CameraSpec given = scene->camera;
            r.axisVec3(cx, "look_at", where + ".extras", &given.look_at);
            r.axisVec3(cx, "up", where + ".extras", &given.up);
            if (!r.failed() && (cx.contains("look_at") || cx.contains("up"))) {
                const Vec3 f0 = scene->camera.look_at - scene->camera.position, f1 = given.look_at - given.position;
                const Vec3 r0 = mesh4d::cross(f0, scene->camera.up), r1 = mesh4d::cross(f1, given.up);
                auto angle = [](const Vec3& a, const Vec3& b) {
                    return std::atan2(mesh4d::norm(mesh4d::cross(a, b)), mesh4d::dot(a, b));
                };
                if (mesh4d::norm(r1) > 0 && angle(f0, f1) <= 1e-6 && angle(r0, r1) <= 1e-6)
                    scene->camera = given;
                else
                    r.warn(where + ".extras", "look_at and up ignored: they do not look the way the node does "
                                              "(the node's rotation gives the camera)");
            }
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
        // Step: a node whose translation or rotation is animated follows that path.
        NodeAnimation an;
        std::vector<std::pair<std::string, std::string>> animation_warnings;
        if (!r.failed()) {
            if (Status s = readNodeAnimation(path, model, o.node, &an, &animation_warnings); !s.ok) return s;
            for (const auto& w : animation_warnings) r.warn(w.first, w.second);
        }
        if (!r.failed() && an.animated())
            if (Status s = readKeyframedPath(path, model, o, *o.extras, an, &obj); !s.ok) return s;
        scene->objects.push_back(obj);
    }
    // Step: channels that move no object node are not modelled: one warning each.
    for (size_t ai = 0; ai < model.animations.size() && !r.failed(); ++ai)
        for (size_t ci = 0; ci < model.animations[ai].channels.size(); ++ci) {
            const int target = model.animations[ai].channels[ci].target_node;
            if (target >= 0 && size_t(target) < is_object.size() && is_object[size_t(target)]) continue;
            r.warn("animations[" + std::to_string(ai) + "].channels[" + std::to_string(ci) + "]",
                   target < 0 ? std::string("has no target node: not modelled")
                              : "animates nodes[" + std::to_string(target) + "], which is not an object node (no object fields in its extras): not modelled");
        }
    scene->warnings = r.warnings();
    return status;
}

}  // namespace apparent
