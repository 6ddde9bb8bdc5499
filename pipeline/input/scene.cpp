#include "pipeline/input/scene.h"

#include "pipeline/input/gltf_scene.h"
#include "pipeline/input/scene_fields.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/input/input_file.h"
#include "pipeline/input/json_limits.h"
#include "pipeline/input/mesh_input.h"

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

bool isGltfPath(const std::string& path) {
    const auto dot = path.find_last_of('.');
    if (dot == std::string::npos) return false;
    std::string ext = path.substr(dot);
    for (char& c : ext) c = char(std::tolower((unsigned char)c));
    return ext == ".gltf" || ext == ".glb";
}

namespace {

// A scene written in `units` into light-seconds (pipeline/input/units.h): every length times
// lightSecondsPer(units); times, speeds, angles and angular velocities stay.
void toLightSeconds(Scene* scene) {
    const double k = lightSecondsPer(scene->units);
    if (k == 1) return;
    scene->camera.position = scene->camera.position * k;
    scene->camera.look_at = scene->camera.look_at * k;
    scene->light.position = scene->light.position * k;
    if (scene->tolerance_relative == 0) scene->tolerance *= k;
    for (ObjectSpec& o : scene->objects) {
        o.position = o.position * k;
        o.scale = o.scale * k;  // the mesh's own lengths
        o.acceleration = o.acceleration * k;
        if (o.kinds.orbit) {
            mesh4d::Orbit orbit = *o.kinds.orbit;
            orbit.center = orbit.center * k;
            o.kinds.orbit = std::make_shared<const mesh4d::Orbit>(orbit);
        }
    }
}

// The JSON scene file's fields (docs/SCENES.md), read by the shared field readers.
Status readJsonScene(const json& root, const std::string& path, Scene* scene) {
    *scene = Scene{};
    scene->path = path;
    Status status;
    FieldReader r(path, &status);
    if (!root.is_object()) {
        r.fail("(top level)", "expected a JSON object, got " + FieldReader::typeName(root));
        return status;
    }
    r.checkKeys(root, "", {"camera", "light", "frames", "model", "tolerance", "objects", "units"});
    if (root.contains("units")) {
        std::string units;
        r.string(root, "units", "", &units);
        if (units == "m") scene->units = LengthUnit::Metre;
        else if (!r.failed() && units != "ls")
            r.fail("units", "unknown units '" + units + "' (ls: light-seconds and seconds, the default; m: metres and seconds)");
    }
    // Step: camera, light (whose default follows camera.up), frames, model and tolerance.
    if (const json* cam = nullptr; r.object(root, "camera", "", &cam)) readCamera(r, *cam, "camera", &scene->camera);
    readLight(r, root, "", scene);
    readFrames(r, root, "", &scene->frames);
    readModelAndTolerance(r, root, "", scene);

    // Step: objects.
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    auto objs = root.find("objects");
    if (objs == root.end()) {
        r.fail("objects", "missing (a list of moving objects)");
    } else if (!objs->is_array()) {
        r.fail("objects", "expected an array, got " + FieldReader::typeName(*objs));
    } else if (objs->empty()) {
        r.fail("objects", "empty: the scene has nothing to show");
    } else {
        for (size_t i = 0; i < objs->size() && !r.failed(); ++i) {
            const std::string p = "objects[" + std::to_string(i) + "]";
            if (!(*objs)[i].is_object()) { r.fail(p, "expected an object"); break; }
            ObjectSpec obj;
            obj.name = "object" + std::to_string(i);
            readObjectFields(r, (*objs)[i], p, folder, ObjectSource::JsonScene, &obj);
            obj.field_path = p;
            scene->objects.push_back(obj);
        }
    }
    if (status.ok) toLightSeconds(scene);
    scene->warnings = r.warnings();
    return status;
}

}  // namespace

Status loadScene(const std::string& path, Scene* scene) {
    if (isGltfPath(path)) return loadGltfScene(path, scene);
    // A mesh given where the scene belongs: say so rather than "invalid JSON at line 1".
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower((unsigned char)c));
    if (ext == ".obj" || ext == ".ply")
        return Status::failure(path + " is an " + (ext == ".obj" ? std::string("OBJ") : std::string("PLY")) +
                               " mesh, not a scene: name it in a scene's objects[].mesh (README \"Scene format\"), "
                               "or open a .json, .gltf or .glb scene");
    *scene = Scene{};
    scene->path = path;
    // Only a regular file, within the size limit of any input file, and nested shallowly enough
    // for nlohmann's recursive dump (json_limits.h).
    std::string text;
    if (Status s = readRegularFile(path, MeshLimits{}.max_file_bytes, &text, "scene file"); !s.ok) return s;
    if (Status s = checkJsonDepth(path, text, /*comments=*/true); !s.ok) return s;
    json root;
    try {
        root = json::parse(text, nullptr, true, /*ignore_comments=*/true);
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
    return readJsonScene(root, path, scene);
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
