#include "pipeline/input/scene_fields.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "mesh4d/robust.h"
#include "pipeline/input/json_limits.h"

namespace apparent {

using nlohmann::json;
using mesh4d::Vec3;

void FieldReader::fail(const std::string& path, const std::string& problem) {
    // Keys come from the file: printed escaped and cut, so the message stays one line.
    if (status_->ok) *status_ = Status::failure(printable(file_, 4096) + ": " + printable(path) + ": " + printable(problem, 4096));
}

void FieldReader::warn(const std::string& path, const std::string& problem) {
    warnings_.push_back(printable(file_, 4096) + ": " + printable(path) + ": " + printable(problem, 4096));
}

std::string fieldList(const std::vector<std::string>& keys) {
    std::string list;
    for (const std::string& k : keys) list += (list.empty() ? "" : ", ") + k;
    return list;
}

namespace {

bool isComment(const std::string& key) { return key.rfind('_', 0) == 0; }

}  // namespace

void FieldReader::checkKeys(const json& obj, const std::string& path, const std::vector<std::string>& known) {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        if (isComment(it.key()) || std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
        const std::string near = nearestField(it.key(), known);
        fail(join(path, it.key()), "unknown field (" + (near.empty() ? std::string() : "did you mean " + near + "?; ") +
                                       "known: " + fieldList(known) + ")");
        return;
    }
}

void FieldReader::warnUnknownKeys(const json& obj, const std::string& path, const std::vector<std::string>& known) {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        if (isComment(it.key()) || std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
        const std::string near = nearestField(it.key(), known);
        warn(join(path, it.key()), "unknown field, ignored" + (near.empty() ? std::string() : " (did you mean " + near + "?)") +
                                       "; known fields: " + fieldList(known));
    }
}

bool FieldReader::object(const json& parent, const char* key, const std::string& path, const json** out) {
    auto it = parent.find(key);
    if (it == parent.end()) return false;
    if (!it->is_object()) {
        fail(join(path, key), "expected an object, got " + typeName(*it));
        return false;
    }
    *out = &*it;
    return true;
}

void FieldReader::number(const json& parent, const char* key, const std::string& path, double* out) {
    auto it = parent.find(key);
    if (it == parent.end()) return;
    readNumber(*it, join(path, key), out);
}

void FieldReader::vec3(const json& parent, const char* key, const std::string& path, Vec3* out) {
    auto it = parent.find(key);
    if (it == parent.end()) return;
    const std::string p = join(path, key);
    if (!it->is_array() || it->size() != 3) {
        fail(p, "expected an array of 3 numbers, got " + describe(*it));
        return;
    }
    double v[3];
    for (int i = 0; i < 3; ++i) readNumber((*it)[size_t(i)], p + "[" + std::to_string(i) + "]", &v[i]);
    *out = {v[0], v[1], v[2]};
}

void FieldReader::axisVec3(const json& parent, const char* key, const std::string& path, Vec3* out) {
    Vec3 v = *out;
    vec3(parent, key, path, &v);
    if (z_up_ && parent.contains(key)) v = {v.x, v.z, -v.y};
    *out = v;
}

void FieldReader::string(const json& parent, const char* key, const std::string& path, std::string* out) {
    auto it = parent.find(key);
    if (it == parent.end()) return;
    if (!it->is_string()) {
        fail(join(path, key), "expected a string, got " + typeName(*it));
        return;
    }
    *out = it->get<std::string>();
}

std::string FieldReader::join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
}

void FieldReader::readNumber(const json& j, const std::string& path, double* out) {
    if (!j.is_number()) {
        fail(path, "expected a number, got " + describe(j));
        return;
    }
    const double v = j.get<double>();
    if (!std::isfinite(v)) {
        fail(path, "must be finite");
        return;
    }
    *out = v;
}

std::string FieldReader::describe(const json& j) {
    return std::string(j.type_name()) + " " + jsonForMessage(j, 37);
}

std::string formatNumber(double v) {
    std::ostringstream os;
    os.precision(17);
    os << v;
    return os.str();
}

std::string nearestField(const std::string& key, const std::vector<std::string>& known) {
    auto lower = [](std::string s) {
        for (char& c : s) c = char(std::tolower((unsigned char)c));
        return s;
    };
    // Edit distance with adjacent transpositions (optimal string alignment): "modle" is one edit
    // from "model", "velocty" one from "velocity". Case is ignored ("Velocity").
    auto distance = [](const std::string& a, const std::string& b) {
        std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
        for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
        for (size_t k = 0; k <= b.size(); ++k) d[0][k] = k;
        for (size_t i = 1; i <= a.size(); ++i)
            for (size_t k = 1; k <= b.size(); ++k) {
                d[i][k] = std::min({d[i - 1][k] + 1, d[i][k - 1] + 1, d[i - 1][k - 1] + (a[i - 1] == b[k - 1] ? 0 : 1)});
                if (i > 1 && k > 1 && a[i - 1] == b[k - 2] && a[i - 2] == b[k - 1]) d[i][k] = std::min(d[i][k], d[i - 2][k - 2] + 1);
            }
        return d[a.size()][b.size()];
    };
    const std::string k = lower(key);
    if (k.size() > 64) return {};  // no field is that long; keeps the table small
    std::string best;
    size_t best_d = SIZE_MAX;
    for (const std::string& f : known) {
        const std::string lf = lower(f);
        size_t d = distance(k, lf);
        // A truncated or extended name ("rotation" for "rotation_deg", "velocity_x") counts as near.
        if (k.size() >= 4 && lf.size() >= 4 && (lf.rfind(k, 0) == 0 || k.rfind(lf, 0) == 0)) d = std::min<size_t>(d, 1);
        // So does the first word of a name with a unit ("fov" for "fov_deg").
        if (k.size() >= 2 && lf.rfind(k + "_", 0) == 0) d = std::min<size_t>(d, 1);
        if (d < best_d) { best_d = d; best = f; }
    }
    // At most 2 edits, and fewer than half the key's length: "t1" is not a misspelt "t0".
    if (best_d <= 2 && 2 * best_d < k.size()) return best;
    return {};
}

// Step: the object fields, one reader each, in the order they are read.
namespace {

void readName(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    r.string(j, "name", path, &obj->name);
}

void readMeshPath(FieldReader& r, const json& j, const std::string& path, const ObjectContext& context, ObjectSpec* obj) {
    std::string mesh;
    if (!j.contains("mesh")) r.fail(path + ".mesh", "missing (the path of an OBJ file)");
    r.string(j, "mesh", path, &mesh);
    if (!mesh.empty()) {
        const std::filesystem::path p(mesh);
        obj->mesh_path = (p.is_absolute() ? p : context.folder / p).lexically_normal().string();
        obj->mesh_text = mesh;
    } else if (j.contains("mesh") && !r.failed()) {
        r.fail(path + ".mesh", "empty path");
    }
}

void readPosition(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    r.vec3(j, "position", path, &obj->position);
}

void readT0(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    r.number(j, "t0", path, &obj->t0);
}

void readVelocity(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    r.axisVec3(j, "velocity", path, &obj->velocity);
}

// An exactly stated speed: a unit direction with gamma or rapidity (docs/SCENES.md).
void readExactSpeed(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    const bool has_dir = j.contains("direction"), has_gamma = j.contains("gamma"), has_rap = j.contains("rapidity");
    if (r.failed() || !(has_dir || has_gamma || has_rap)) return;
    if (j.contains("velocity")) {
        r.fail(path + ".velocity", "give either velocity or direction with gamma or rapidity, not both");
        return;
    }
    if (!has_dir || has_gamma == has_rap) {
        r.fail(path + (has_dir ? ".gamma" : ".direction"), "an exact speed needs direction and exactly one of gamma, rapidity");
        return;
    }
    Vec3 d;
    r.axisVec3(j, "direction", path, &d);
    if (!r.failed() && !(mesh4d::norm(d) > 0)) r.fail(path + ".direction", "must be non-zero");
    if (!r.failed()) obj->direction = d / mesh4d::norm(d);
    obj->direction_given = d;
    if (has_gamma) {
        r.number(j, "gamma", path, &obj->gamma);
        // gamma^2 must stay finite with room to spare (1 - b^2 = 1/gamma^2).
        if (!r.failed() && !(obj->gamma >= 1 && obj->gamma <= 1e15)) r.fail(path + ".gamma", "must be in [1, 1e15]");
        obj->speed = ObjectSpec::Speed::Gamma;
        obj->rapidity = std::acosh(obj->gamma);
    } else {
        r.number(j, "rapidity", path, &obj->rapidity);
        if (!r.failed() && !(obj->rapidity >= 0 && obj->rapidity <= 35))
            r.fail(path + ".rapidity", "must be in [0, 35] (gamma up to about 8e14)");
        obj->speed = ObjectSpec::Speed::Rapidity;
        obj->gamma = std::cosh(obj->rapidity);
    }
    if (!r.failed()) obj->velocity = obj->direction * std::tanh(obj->rapidity);
}

void readRotation(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    if (r.zUp() && j.contains("rotation_deg"))
        r.fail(path + ".rotation_deg", "not read with the scene's \"up\": \"z\" (no single axis rule); rotate the node itself");
    r.vec3(j, "rotation_deg", path, &obj->rotation_deg);
}

void readScale(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    auto it = j.find("scale");
    if (it == j.end()) return;
    if (r.zUp() && it->is_array())
        r.fail(path + ".scale", "an array is not read with the scene's \"up\": \"z\" (no single axis rule); scale the node itself");
    if (it->is_array()) {
        r.vec3(j, "scale", path, &obj->scale);
    } else {
        double s = 1;
        r.readNumber(*it, path + ".scale", &s);
        obj->scale = {s, s, s};
    }
    for (int i = 0; i < 3 && !r.failed(); ++i)
        if (!(obj->scale[i] != 0)) r.fail(path + ".scale", "must be non-zero");
}

// Read after the speed: a mirror must be at rest.
void readMirror(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    auto it = j.find("mirror");
    if (it == j.end()) return;
    if (!it->is_boolean()) r.fail(path + ".mirror", "expected true or false, got " + FieldReader::describe(*it));
    else obj->mirror = it->get<bool>();
    // A mirror at rest keeps the reflection a plane reflection of the light paths (docs/DESIGN.md section 8).
    if (!r.failed() && obj->mirror && (obj->speed != ObjectSpec::Speed::Velocity || mesh4d::norm(obj->velocity) != 0))
        r.fail(path + ".mirror", "a mirror must be at rest (velocity [0, 0, 0])");
}

// `color`: [r, g, b] or [r, g, b, a]; `material`: {base_color, metallic, roughness, emissive}.
void readMaterial(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    ObjectSpec::Material& m = obj->material;
    auto unit = [&](const json& v, const std::string& at, double* out) {
        r.readNumber(v, at, out);
        if (!r.failed() && !(*out >= 0 && *out <= 1)) r.fail(at, formatNumber(*out) + " is outside [0, 1]");
    };
    auto colour = [&](const json& v, const std::string& at, double* out, size_t least, size_t most) {
        if (!v.is_array() || v.size() < least || v.size() > most)
            return r.fail(at, std::string("expected ") + (least == most ? "[r, g, b]" : "[r, g, b] or [r, g, b, a]") +
                                  " (linear, each in [0, 1]), got " + FieldReader::describe(v));
        for (size_t i = 0; i < v.size() && !r.failed(); ++i) unit(v[i], at + "[" + std::to_string(i) + "]", &out[i]);
    };
    const auto c = j.find("color"), mat = j.find("material");
    if (c != j.end() && mat != j.end())
        return r.fail(path + ".color", "give either color or material.base_color, not both");
    if (c != j.end()) {
        m.given = true;
        colour(*c, path + ".color", m.base_color.data(), 3, 4);
    }
    if (mat == j.end()) return;
    m.given = true;
    if (!mat->is_object())
        return r.fail(path + ".material", "expected an object {base_color, metallic, roughness, emissive}, got " +
                                              FieldReader::describe(*mat));
    for (const auto& [key, value] : mat->items()) {
        const std::string at = path + ".material." + key;
        if (key == "base_color") colour(value, at, m.base_color.data(), 3, 4);
        else if (key == "metallic") unit(value, at, &m.metallic);
        else if (key == "roughness") unit(value, at, &m.roughness);
        else if (key == "emissive") colour(value, at, m.emissive.data(), 3, 3);
        else r.fail(at, "unknown field (material has base_color, metallic, roughness, emissive)");
        if (r.failed()) return;
    }
}

void readExists(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    auto it = j.find("exists");
    if (it == j.end()) return;
    const std::string p = path + ".exists";
    if (!it->is_array() || it->size() != 2) {
        r.fail(p, "expected [from, to] (proper or lab time since t0), got " + FieldReader::describe(*it));
        return;
    }
    // null stands for "forever" at that end; +-1e30 and beyond are treated the same way.
    double v[2] = {obj->exists_from, obj->exists_to};
    for (int i = 0; i < 2; ++i)
        if (!(*it)[size_t(i)].is_null()) r.readNumber((*it)[size_t(i)], p + "[" + std::to_string(i) + "]", &v[i]);
    if (!r.failed() && !(v[0] < v[1]))
        r.fail(p, "from (" + formatNumber(v[0]) + ") must be less than to (" + formatNumber(v[1]) + ")");
    obj->exists_from = v[0];
    obj->exists_to = v[1];
}

// A spin about the object's origin, rad/s in its centre frame (mesh4d/motion/worldline.h); an axial
// vector, turned with the scene's axes as positions are (a rotation keeps axial vectors' rule).
// Read after the mirror: a mirror must be at rest.
void readAngularVelocity(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    r.axisVec3(j, "angular_velocity", path, &obj->angular_velocity);
    if (!r.failed() && obj->mirror && mesh4d::norm(obj->angular_velocity) != 0)
        r.fail(path + ".angular_velocity", "a mirror must be at rest (angular_velocity [0, 0, 0])");
}

// A constant proper acceleration of the origin (mesh4d/motion/worldline.h), in the scene's axes.
void readAcceleration(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    r.axisVec3(j, "acceleration", path, &obj->acceleration);
    if (!r.failed() && obj->mirror && mesh4d::norm(obj->acceleration) != 0)
        r.fail(path + ".acceleration", "a mirror must be at rest (acceleration [0, 0, 0])");
}

// A circular orbit (mesh4d/motion/motion.h Orbit): center and axis in the scene's axes (as
// angular_velocity), the speed, the orientation. Read after the speed and the mirror: the orbit is
// the whole motion.
void readOrbit(FieldReader& r, const json& j, const std::string& path, const ObjectContext&, ObjectSpec* obj) {
    const json* o = nullptr;
    const std::string p = path + ".orbit";
    if (r.failed() || !r.object(j, "orbit", path, &o)) return;
    r.checkKeys(*o, p, {"center", "axis", "speed", "orientation"});
    for (const char* key : {"center", "axis", "speed"})
        if (!r.failed() && !o->contains(key)) r.fail(p + "." + key, "missing (the orbit needs center, axis and speed)");
    mesh4d::Orbit orbit;
    Vec3 axis{0, 0, 0};
    std::string orientation = "fixed";
    r.axisVec3(*o, "center", p, &orbit.center);
    r.axisVec3(*o, "axis", p, &axis);
    r.number(*o, "speed", p, &orbit.speed);
    r.string(*o, "orientation", p, &orientation);
    if (r.failed()) return;
    if (!(mesh4d::norm(axis) > 0)) return r.fail(p + ".axis", "must be non-zero");
    if (!(orbit.speed > 0 && orbit.speed < 1)) return r.fail(p + ".speed", "must be > 0 and < 1 (the speed of light)");
    if (orientation != "fixed" && orientation != "locked")
        return r.fail(p + ".orientation", "expected \"fixed\" or \"locked\", got \"" + orientation + "\"");
    if (obj->mirror) return r.fail(p, "a mirror must be at rest (remove orbit)");
    if (obj->speed != ObjectSpec::Speed::Velocity || mesh4d::norm(obj->velocity) != 0)
        return r.fail(p, "the orbit gives the motion: velocity must be [0, 0, 0] (no gamma or rapidity)");
    orbit.axis = axis / mesh4d::norm(axis);
    obj->orbit_axis_given = axis;
    orbit.locked = orientation == "locked";
    obj->kinds.orbit = std::make_shared<const mesh4d::Orbit>(orbit);
}

}  // namespace

const std::vector<ObjectField>& objectFields() {
    static const std::vector<ObjectField> table = {
        {{"name"}, true, &readName},
        {{"mesh"}, true, &readMeshPath},
        {{"position"}, true, &readPosition},
        {{"t0"}, false, &readT0},
        {{"velocity"}, false, &readVelocity, true},
        {{"direction", "gamma", "rapidity"}, false, &readExactSpeed, true},
        {{"rotation_deg"}, false, &readRotation},
        {{"scale"}, false, &readScale},
        {{"mirror"}, false, &readMirror},
        {{"exists"}, false, &readExists},
        {{"color", "material"}, false, &readMaterial},
        {{"angular_velocity"}, false, &readAngularVelocity, true},
        {{"acceleration"}, false, &readAcceleration, true},
        {{"orbit"}, false, &readOrbit, true},
    };
    return table;
}

std::vector<std::string> objectFieldNames() {
    std::vector<std::string> names;
    for (const ObjectField& f : objectFields()) names.insert(names.end(), f.keys.begin(), f.keys.end());
    return names;
}

std::vector<std::string> objectMarkerKeys() {
    std::vector<std::string> names;
    for (const ObjectField& f : objectFields())
        if (!f.given_by_gltf_node) names.insert(names.end(), f.keys.begin(), f.keys.end());
    return names;
}

void readObjectFields(FieldReader& r, const json& j, const std::string& path, const std::filesystem::path& folder,
                      ObjectSource source, ObjectSpec* obj) {
    const ObjectContext context{folder};
    if (source == ObjectSource::JsonScene) {
        r.checkKeys(j, path, objectFieldNames());
    } else {
        // Step: in glTF the node gives name, mesh and position; other keys may be other tools' own.
        r.warnUnknownKeys(j, path, objectFieldNames());
        for (const ObjectField& f : objectFields())
            if (f.given_by_gltf_node)
                for (const std::string& key : f.keys)
                    if (j.contains(key))
                        r.warn(FieldReader::join(path, key),
                               "ignored: a glTF object's " + key + " is its node's own (" +
                                   (key == "name" ? "the node name" : key == "mesh" ? "the node's subtree" : "the node's world translation") +
                                   ")");
    }
    for (const ObjectField& f : objectFields()) {
        if (source == ObjectSource::GltfNode && f.given_by_gltf_node) continue;
        f.read(r, j, path, context, obj);
    }
}

// Step: the scene-level sections.

void readCamera(FieldReader& r, const json& cam, const std::string& path, CameraSpec* camera) {
    r.checkKeys(cam, path, {"position", "look_at", "up", "fov_deg", "instant_delay", "velocity", "projection", "width"});
    r.number(cam, "instant_delay", path, &camera->instant_delay);
    r.vec3(cam, "velocity", path, &camera->velocity);
    r.vec3(cam, "position", path, &camera->position);
    r.vec3(cam, "look_at", path, &camera->look_at);
    r.vec3(cam, "up", path, &camera->up);
    r.number(cam, "fov_deg", path, &camera->fov_deg);
    readProjection(r, cam, path, camera);
    checkCamera(r, path, *camera);
}

void readProjection(FieldReader& r, const json& cam, const std::string& path, CameraSpec* camera) {
    std::string projection = "perspective";
    r.string(cam, "projection", path, &projection);
    if (r.failed()) return;
    if (projection != "perspective" && projection != "orthographic")
        return r.fail(path + ".projection", "expected \"perspective\" (the default) or \"orthographic\", got \"" + projection + "\"");
    camera->projection = projection == "orthographic" ? CameraSpec::Projection::Orthographic : CameraSpec::Projection::Perspective;
    if (camera->orthographic() && !cam.contains("width"))
        return r.fail(path + ".width", "missing: an orthographic camera needs the view's width (scene units > 0)");
    r.number(cam, "width", path, &camera->width);
    if (r.failed()) return;
    if (camera->orthographic() && !(camera->width > 0))
        return r.fail(path + ".width", "must be > 0 (the orthographic view's width in scene units), got " + formatNumber(camera->width));
    if (!camera->orthographic() && cam.contains("width"))
        r.warn(path + ".width", "ignored: the view's width is read only with \"projection\": \"orthographic\" "
                                "(a perspective camera's view is set by fov_deg)");
    if (camera->orthographic() && cam.contains("fov_deg"))
        r.warn(path + ".fov_deg", "ignored: an orthographic camera's view is set by width");
}

void checkCamera(FieldReader& r, const std::string& path, const CameraSpec& c) {
    const Vec3 dir = c.look_at - c.position;
    if (!r.failed() && !(mesh4d::norm(dir) > 0)) r.fail(path + ".look_at", "must differ from camera.position");
    if (!r.failed() && !(mesh4d::norm(mesh4d::cross(dir, c.up)) > 0))
        r.fail(path + ".up", "must be non-zero and not parallel to the view direction");
    if (!r.failed() && !(c.fov_deg > 0 && c.fov_deg < 180)) r.fail(path + ".fov_deg", "must be in (0, 180)");
    // The camera is an observer: slower than light in every model (1 - |v|^2 without cancellation).
    if (!r.failed() && !(mesh4d::oneMinusNorm2(c.velocity.x, c.velocity.y, c.velocity.z) > 0))
        r.fail(path + ".velocity", "|velocity| = " + formatNumber(mesh4d::norm(c.velocity)) +
                                       " must be < 1 (the speed of light): the camera is an observer");
}

void readLight(FieldReader& r, const json& parent, const std::string& top, Scene* scene) {
    // A point light at `position` or a directional one towards `direction`; by default
    // directional from camera.up, i.e. overhead.
    scene->light.direction = scene->camera.up / std::max(mesh4d::norm(scene->camera.up), 1e-300);
    const json* li = nullptr;
    if (!r.object(parent, "light", top, &li)) {
        // The default key light: towards the camera's side of the scene, a little left and above
        // (back 1, left 0.45, up 0.15 in the camera's basis), 70% of the diffuse share. A box
        // facing the camera then shows front, top and left faces at 0.71, 0.52 and 0.43 of
        // full light, the others at the ambient 0.2 (docs/SCENES.md).
        const CameraSpec& c = scene->camera;
        const Vec3 f = c.look_at - c.position, right = mesh4d::cross(f, c.up);
        const double nf = mesh4d::norm(f), nr = mesh4d::norm(right);
        if (nf > 0 && nr > 0) {
            const Vec3 fu = f / nf, ru = right / nr, uu = mesh4d::cross(ru, fu);
            const Vec3 k = -1.0 * fu - 0.45 * ru + 0.15 * uu;
            scene->light.key_direction = k / mesh4d::norm(k);
            scene->light.key_weight = 0.7;
        }
        return;
    }
    const std::string lp = FieldReader::join(top, "light");
    r.checkKeys(*li, lp, {"position", "direction", "ambient"});
    if (li->contains("position") == li->contains("direction")) {
        r.fail(lp, "give exactly one of position (a point light) or direction (towards a distant light)");
    } else if (li->contains("position")) {
        scene->light.kind = LightSpec::Kind::Point;
        r.axisVec3(*li, "position", lp, &scene->light.position);
    } else {
        Vec3 d;
        r.axisVec3(*li, "direction", lp, &d);
        if (!r.failed() && !(mesh4d::norm(d) > 0)) r.fail(lp + ".direction", "must be non-zero");
        if (!r.failed()) scene->light.direction = d / mesh4d::norm(d);
        scene->light.direction_given = d;
    }
    r.number(*li, "ambient", lp, &scene->light.ambient);
    if (!r.failed() && !(scene->light.ambient >= 0 && scene->light.ambient <= 1)) r.fail(lp + ".ambient", "must be in [0, 1]");
}

void readFrames(FieldReader& r, const json& parent, const std::string& top, FrameSpec* frames) {
    const json* fr = nullptr;
    if (!r.object(parent, "frames", top, &fr)) return;
    const std::string fp = FieldReader::join(top, "frames");
    r.checkKeys(*fr, fp, {"start", "end", "fps"});
    r.number(*fr, "start", fp, &frames->start);
    r.number(*fr, "end", fp, &frames->end);
    r.number(*fr, "fps", fp, &frames->fps);
    if (!r.failed() && !(frames->fps > 0)) r.fail(fp + ".fps", "must be > 0");
    if (!r.failed() && !(frames->end > frames->start))
        r.fail(fp + ".end", "must be greater than frames.start (" + formatNumber(frames->start) + ")");
    // Very high frame rates late in time: each frame time start + k / fps is a double, so the
    // frame spacing must stay well above the spacing of doubles there, or frames would collapse
    // onto the same time (or be unevenly spaced). Ask for 1/1024 of a frame.
    if (!r.failed()) {
        const double t_max = std::max(std::fabs(frames->start), std::fabs(frames->end));
        const double ulp = std::nextafter(t_max, INFINITY) - t_max;
        if (!(1.0 / frames->fps >= 1024 * ulp))
            r.fail(fp + ".fps", formatNumber(frames->fps) + " frames per second near time " + formatNumber(t_max) +
                                    " s are closer than doubles resolve there (" + formatNumber(ulp) +
                                    " s); shift frames.start and the objects' t0 towards 0");
    }
}

void readUpAxis(FieldReader& r, const json& parent, const std::string& top) {
    if (!parent.contains("up")) return;
    std::string up;
    r.string(parent, "up", top, &up);
    if (r.failed()) return;
    if (up != "y" && up != "z") r.fail(FieldReader::join(top, "up"), "expected \"y\" (glTF's axes, the default) or \"z\" (Blender's), got \"" + up + "\"");
    r.setZUp(up == "z");
}

bool parseTolerance(const std::string& text, double* absolute, double* relative) {
    if (text == "vertex") {
        *absolute = 0;
        *relative = 0;
        return true;
    }
    const bool is_relative = !text.empty() && text.back() == 'x';
    const std::string number = is_relative ? text.substr(0, text.size() - 1) : text;
    double v = 0;
    try {
        size_t used = 0;
        v = std::stod(number, &used);
        if (used != number.size() || std::isspace((unsigned char)number[0])) return false;
    } catch (const std::exception&) {
        return false;
    }
    if (!(v > 0) || !std::isfinite(v) || (is_relative && !(v < 1))) return false;
    *absolute = is_relative ? 0 : v;
    *relative = is_relative ? v : 0;
    return true;
}

void readModelAndTolerance(FieldReader& r, const json& parent, const std::string& top, Scene* scene) {
    auto at = [&](const std::string& key) { return FieldReader::join(top, key); };
    if (parent.contains("model")) {
        std::string name;
        r.string(parent, "model", top, &name);
        if (!r.failed() && !parseModel(name, &scene->model))
            r.fail(at("model"), "unknown model '" + name + "' (instant, finite, relativistic, contracted)");
    }
    // tolerance: light-seconds > 0, "vertex" (0 inside: exact vertices, straight edges), or
    // "<f>x": f times each object's bounding-box diagonal. Absent: kDefaultToleranceRelative x.
    if (auto tol = parent.find("tolerance"); tol != parent.end() && tol->is_string()) {
        if (!parseTolerance(tol->get<std::string>(), &scene->tolerance, &scene->tolerance_relative))
            r.fail(at("tolerance"), "expected a number > 0 (light-seconds), \"vertex\" or a fraction of each object's size "
                                    "such as \"1e-3x\", got \"" + tol->get<std::string>() + "\"");
    } else if (tol != parent.end()) {
        r.number(parent, "tolerance", top, &scene->tolerance);
        scene->tolerance_relative = 0;
        if (!r.failed() && !(scene->tolerance > 0)) r.fail(at("tolerance"), "must be > 0 (light-seconds) or \"vertex\"");
    }
}

}  // namespace apparent
