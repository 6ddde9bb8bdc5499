#include "pipeline/scene.h"

#include "pipeline/gltf_reader.h"
#include "pipeline/scene_json.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

namespace apparent {

using nlohmann::json;
using mesh4d::Vec3;

const char* modelName(Model m) {
    switch (m) {
        case Model::Instant: return "instant";
        case Model::Finite: return "finite";
        case Model::Relativistic: return "relativistic";
        case Model::Contracted: return "contracted";
    }
    return "?";
}

bool parseModel(const std::string& name, Model* out) {
    for (Model m : {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted}) {
        if (name == modelName(m)) {
            *out = m;
            return true;
        }
    }
    return false;
}

namespace {

// Reads fields of one JSON object, remembering the first error as "file: path: problem".
class FieldReader {
public:
    FieldReader(const std::string& file, Status* status) : file_(file), status_(status) {}

    bool failed() const { return !status_->ok; }

    void fail(const std::string& path, const std::string& problem) {
        if (status_->ok) *status_ = Status::failure(file_ + ": " + path + ": " + problem);
    }

    // Unknown keys are errors (they are usually typos); keys starting with '_' are comments.
    void checkKeys(const json& obj, const std::string& path, std::initializer_list<const char*> known) {
        std::set<std::string> allowed(known.begin(), known.end());
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            if (it.key().rfind('_', 0) == 0 || allowed.count(it.key())) continue;
            std::string list;
            for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
            fail(join(path, it.key()), "unknown field (known: " + list + ")");
            return;
        }
    }

    bool object(const json& parent, const char* key, const std::string& path, const json** out) {
        auto it = parent.find(key);
        if (it == parent.end()) return false;
        if (!it->is_object()) { fail(join(path, key), "expected an object, got " + typeName(*it)); return false; }
        *out = &*it;
        return true;
    }

    void number(const json& parent, const char* key, const std::string& path, double* out) {
        auto it = parent.find(key);
        if (it == parent.end()) return;
        readNumber(*it, join(path, key), out);
    }

    void vec3(const json& parent, const char* key, const std::string& path, Vec3* out) {
        auto it = parent.find(key);
        if (it == parent.end()) return;
        const std::string p = join(path, key);
        if (!it->is_array() || it->size() != 3) { fail(p, "expected an array of 3 numbers, got " + describe(*it)); return; }
        double v[3];
        for (int i = 0; i < 3; ++i) readNumber((*it)[i], p + "[" + std::to_string(i) + "]", &v[i]);
        *out = {v[0], v[1], v[2]};
    }

    void string(const json& parent, const char* key, const std::string& path, std::string* out) {
        auto it = parent.find(key);
        if (it == parent.end()) return;
        if (!it->is_string()) { fail(join(path, key), "expected a string, got " + typeName(*it)); return; }
        *out = it->get<std::string>();
    }

    static std::string join(const std::string& path, const std::string& key) {
        return path.empty() ? key : path + "." + key;
    }

    void readNumber(const json& j, const std::string& path, double* out) {
        if (!j.is_number()) { fail(path, "expected a number, got " + describe(j)); return; }
        const double v = j.get<double>();
        if (!std::isfinite(v)) { fail(path, "must be finite"); return; }
        *out = v;
    }

    static std::string typeName(const json& j) { return j.type_name(); }
    static std::string describe(const json& j) {
        std::string s = j.dump();
        if (s.size() > 40) s = s.substr(0, 37) + "...";
        return std::string(j.type_name()) + " " + s;
    }

private:
    std::string file_;
    Status* status_;
};

}  // namespace

bool isGltfPath(const std::string& path) {
    const auto dot = path.find_last_of('.');
    if (dot == std::string::npos) return false;
    std::string ext = path.substr(dot);
    for (char& c : ext) c = char(std::tolower((unsigned char)c));
    return ext == ".gltf" || ext == ".glb";
}

namespace {

std::string formatNumber(double v) {
    std::ostringstream os;
    os.precision(17);
    os << v;
    return os.str();
}

void readObject(FieldReader& r, const json& j, const std::string& path, const std::filesystem::path& folder,
                ObjectSpec* obj) {
    r.checkKeys(j, path, {"name", "mesh", "position", "t0", "velocity", "direction", "gamma", "rapidity",
                          "rotation_deg", "scale", "exists", "mirror"});
    r.string(j, "name", path, &obj->name);
    std::string mesh;
    if (!j.contains("mesh")) r.fail(path + ".mesh", "missing (the path of an OBJ file)");
    r.string(j, "mesh", path, &mesh);
    if (!mesh.empty()) {
        std::filesystem::path p(mesh);
        obj->mesh_path = (p.is_absolute() ? p : folder / p).lexically_normal().string();
        obj->mesh_text = mesh;
    } else if (j.contains("mesh") && !r.failed()) {
        r.fail(path + ".mesh", "empty path");
    }
    r.vec3(j, "position", path, &obj->position);
    r.number(j, "t0", path, &obj->t0);
    r.vec3(j, "velocity", path, &obj->velocity);
    // Step: an exactly stated speed, as a unit direction with gamma or rapidity.
    const bool has_dir = j.contains("direction"), has_gamma = j.contains("gamma"), has_rap = j.contains("rapidity");
    if (!r.failed() && (has_dir || has_gamma || has_rap)) {
        if (j.contains("velocity")) {
            r.fail(path + ".velocity", "give either velocity or direction with gamma or rapidity, not both");
        } else if (!has_dir || has_gamma == has_rap) {
            r.fail(path + (has_dir ? ".gamma" : ".direction"), "an exact speed needs direction and exactly one of gamma, rapidity");
        } else {
            Vec3 d;
            r.vec3(j, "direction", path, &d);
            if (!r.failed() && !(mesh4d::norm(d) > 0)) r.fail(path + ".direction", "must be non-zero");
            if (!r.failed()) obj->direction = d / mesh4d::norm(d);
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
    }
    r.vec3(j, "rotation_deg", path, &obj->rotation_deg);
    if (auto it = j.find("scale"); it != j.end()) {
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
    if (auto it = j.find("mirror"); it != j.end()) {
        if (!it->is_boolean()) r.fail(path + ".mirror", "expected true or false, got " + FieldReader::describe(*it));
        else obj->mirror = it->get<bool>();
        // A mirror at rest keeps the reflection a plane reflection of the light paths (docs/DESIGN.md section 8).
        if (!r.failed() && obj->mirror && (obj->speed != ObjectSpec::Speed::Velocity || mesh4d::norm(obj->velocity) != 0))
            r.fail(path + ".mirror", "a mirror must be at rest (velocity [0, 0, 0])");
    }
    if (auto it = j.find("exists"); it != j.end()) {
        const std::string p = path + ".exists";
        if (!it->is_array() || it->size() != 2) {
            r.fail(p, "expected [from, to] (proper or lab time since t0), got " + FieldReader::describe(*it));
        } else {
            // null stands for "forever" at that end; +-1e30 and beyond are treated the same way.
            double v[2] = {obj->exists_from, obj->exists_to};
            for (int i = 0; i < 2; ++i)
                if (!(*it)[i].is_null()) r.readNumber((*it)[i], p + "[" + std::to_string(i) + "]", &v[i]);
            if (!r.failed() && !(v[0] < v[1]))
                r.fail(p, "from (" + formatNumber(v[0]) + ") must be less than to (" + formatNumber(v[1]) + ")");
            obj->exists_from = v[0];
            obj->exists_to = v[1];
        }
    }
}

}  // namespace

Status loadScene(const std::string& path, Scene* scene) {
    if (isGltfPath(path)) return loadGltfScene(path, scene);
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        *scene = Scene{};
        scene->path = path;
        return Status::failure(path + ": cannot open scene file");
    }
    json root;
    try {
        root = json::parse(in, nullptr, true, /*ignore_comments=*/true);
    } catch (const json::parse_error& e) {
        // nlohmann's message reads "[json.exception.parse_error.101] parse error at line 3, column 5: ...";
        // keep it from "line".
        std::string what = e.what();
        const auto at = what.find("line ");
        return Status::failure(path + ": invalid JSON at " + (at == std::string::npos ? what : what.substr(at)));
    } catch (const json::exception& e) {
        // Not only parse errors: a number too large for a double throws out_of_range.406 (found by
        // fuzzing, data/fixtures/scene_number_overflow.json). Keep the message after "] ".
        const std::string what = e.what();
        const auto close = what.find("] ");
        return Status::failure(path + ": invalid JSON: " + (close == std::string::npos ? what : what.substr(close + 2)));
    }
    return parseScene(root, path, SceneJsonPaths{}, scene);
}

Status parseScene(const json& root, const std::string& path, const SceneJsonPaths& paths, Scene* scene) {
    *scene = Scene{};
    scene->path = path;
    Status status;
    FieldReader r(path, &status);
    const std::string top = paths.top;
    auto at = [&](const std::string& key) { return FieldReader::join(top, key); };
    if (!root.is_object()) {
        r.fail(top.empty() ? "(top level)" : top, "expected a JSON object, got " + FieldReader::typeName(root));
        return status;
    }
    r.checkKeys(root, top, {"camera", "light", "frames", "model", "tolerance", "objects"});
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();

    // Step: camera.
    if (const json* cam = nullptr; r.object(root, "camera", top, &cam)) {
        const std::string cp = paths.camera.empty() ? at("camera") : paths.camera;
        r.checkKeys(*cam, cp, {"position", "look_at", "up", "fov_deg", "instant_delay"});
        r.number(*cam, "instant_delay", cp, &scene->camera.instant_delay);
        r.vec3(*cam, "position", cp, &scene->camera.position);
        r.vec3(*cam, "look_at", cp, &scene->camera.look_at);
        r.vec3(*cam, "up", cp, &scene->camera.up);
        r.number(*cam, "fov_deg", cp, &scene->camera.fov_deg);
        const CameraSpec& c = scene->camera;
        const Vec3 dir = c.look_at - c.position;
        if (!r.failed() && !(mesh4d::norm(dir) > 0)) r.fail(cp + ".look_at", "must differ from camera.position");
        if (!r.failed() && !(mesh4d::norm(mesh4d::cross(dir, c.up)) > 0))
            r.fail(cp + ".up", "must be non-zero and not parallel to the view direction");
        if (!r.failed() && !(c.fov_deg > 0 && c.fov_deg < 180)) r.fail(cp + ".fov_deg", "must be in (0, 180)");
    }

    // Step: light (at rest): a point light at `position` or a directional one towards `direction`;
    // by default directional from camera.up, i.e. overhead.
    scene->light.direction = scene->camera.up / std::max(mesh4d::norm(scene->camera.up), 1e-300);
    if (const json* li = nullptr; r.object(root, "light", top, &li)) {
        const std::string lp = at("light");
        r.checkKeys(*li, lp, {"position", "direction", "ambient"});
        if (li->contains("position") == li->contains("direction")) {
            r.fail(lp, "give exactly one of position (a point light) or direction (towards a distant light)");
        } else if (li->contains("position")) {
            scene->light.kind = LightSpec::Kind::Point;
            r.vec3(*li, "position", lp, &scene->light.position);
        } else {
            Vec3 d;
            r.vec3(*li, "direction", lp, &d);
            if (!r.failed() && !(mesh4d::norm(d) > 0)) r.fail(lp + ".direction", "must be non-zero");
            if (!r.failed()) scene->light.direction = d / mesh4d::norm(d);
        }
        r.number(*li, "ambient", lp, &scene->light.ambient);
        if (!r.failed() && !(scene->light.ambient >= 0 && scene->light.ambient <= 1))
            r.fail(lp + ".ambient", "must be in [0, 1]");
    }

    // Step: frames.
    if (const json* fr = nullptr; r.object(root, "frames", top, &fr)) {
        const std::string fp = at("frames");
        r.checkKeys(*fr, fp, {"start", "end", "fps"});
        r.number(*fr, "start", fp, &scene->frames.start);
        r.number(*fr, "end", fp, &scene->frames.end);
        r.number(*fr, "fps", fp, &scene->frames.fps);
        if (!r.failed() && !(scene->frames.fps > 0)) r.fail(fp + ".fps", "must be > 0");
        if (!r.failed() && !(scene->frames.end > scene->frames.start))
            r.fail(fp + ".end", "must be greater than frames.start (" + formatNumber(scene->frames.start) + ")");
        // Very high frame rates late in time: each frame time start + k / fps is a double, so the
        // frame spacing must stay well above the spacing of doubles there, or frames would
        // collapse onto the same time (or be unevenly spaced). Ask for 1/1024 of a frame.
        if (!r.failed()) {
            const double t_max = std::max(std::fabs(scene->frames.start), std::fabs(scene->frames.end));
            const double ulp = std::nextafter(t_max, INFINITY) - t_max;
            if (!(1.0 / scene->frames.fps >= 1024 * ulp))
                r.fail(fp + ".fps", formatNumber(scene->frames.fps) + " frames per second near time " + formatNumber(t_max) +
                                        " s are closer than doubles resolve there (" + formatNumber(ulp) +
                                        " s); shift frames.start and the objects' t0 towards 0");
        }
    }

    // Step: model and tolerance.
    if (root.contains("model")) {
        std::string name;
        r.string(root, "model", top, &name);
        if (!r.failed() && !parseModel(name, &scene->model))
            r.fail(at("model"), "unknown model '" + name + "' (instant, finite, relativistic, contracted)");
    }
    // tolerance: light-seconds > 0, or "vertex" (0 inside: exact vertices, straight edges).
    if (auto tol = root.find("tolerance"); tol != root.end() && tol->is_string()) {
        if (tol->get<std::string>() != "vertex") r.fail(at("tolerance"), "expected a number > 0 or \"vertex\"");
        else scene->tolerance = 0;
    } else {
        r.number(root, "tolerance", top, &scene->tolerance);
        if (!r.failed() && !(scene->tolerance > 0)) r.fail(at("tolerance"), "must be > 0 (light-seconds) or \"vertex\"");
    }

    // Step: objects.
    auto objs = root.find("objects");
    if (objs == root.end()) {
        r.fail(at("objects"), "missing (a list of moving objects)");
    } else if (!objs->is_array()) {
        r.fail(at("objects"), "expected an array, got " + FieldReader::typeName(*objs));
    } else if (objs->empty()) {
        r.fail(at("objects"), "empty: the scene has nothing to show");
    } else {
        for (size_t i = 0; i < objs->size() && !r.failed(); ++i) {
            const std::string p = i < paths.objects.size() ? paths.objects[i] : "objects[" + std::to_string(i) + "]";
            if (!(*objs)[i].is_object()) { r.fail(p, "expected an object"); break; }
            ObjectSpec obj;
            obj.name = "object" + std::to_string(i);
            readObject(r, (*objs)[i], p, folder, &obj);
            obj.field_path = p;
            if (i < paths.linear.size()) obj.linear = paths.linear[i];
            scene->objects.push_back(obj);
        }
    }
    return status;
}

Status checkSceneForModel(const Scene& scene, Model model) {
    if (model == Model::Instant) return Status::success();
    for (size_t i = 0; i < scene.objects.size(); ++i) {
        if (scene.objects[i].speed != ObjectSpec::Speed::Velocity) continue;  // b < 1 by construction
        const double b = mesh4d::norm(scene.objects[i].velocity);
        if (!(b < 1)) {
            return Status::failure(scene.path + ": " + scene.objects[i].field_path + ".velocity: |velocity| = " +
                                   formatNumber(b) + " must be < 1 (the speed of light) for model " +
                                   modelName(model));
        }
    }
    return Status::success();
}

long long frameCount(const FrameSpec& frames) {
    // Start from the estimate and correct it so that the defining inequality holds exactly.
    const double span = (frames.end - frames.start) * frames.fps;
    if (!(span > 0)) return 0;
    if (span > 9e15) return std::numeric_limits<long long>::max();
    long long n = (long long)std::ceil(span);
    while (n > 0 && !(frameTime(frames, n - 1) < frames.end)) --n;
    while (frameTime(frames, n) < frames.end) ++n;
    return n;
}

double frameTime(const FrameSpec& frames, long long k) { return frames.start + double(k) / frames.fps; }

}  // namespace apparent
