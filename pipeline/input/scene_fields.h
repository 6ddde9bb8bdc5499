// The fields of a scene (docs/SCENES.md), read from JSON values in one place for both
// forms of a scene: the JSON scene file and a scene authored in glTF, whose scene and node
// `extras` hold the same fields (docs/SCENES.md "Scenes in glTF"). Every field is read and checked by
// the same code whichever file it comes from, so the two forms accept the same values and give
// the same errors, each one line "file: field path: problem (valid range)".
//
// The object fields are one table (objectFields()): the JSON reader refuses a key outside it (a
// typo there is almost always a mistake), the glTF reader warns instead (other tools keep their
// own custom properties in extras) and names the nearest field when the key looks misspelt.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/input/scene.h"

namespace apparent {

// Reads fields of JSON objects, remembering the first error as "file: path: problem" and
// collecting warnings as "file: path: problem". Keys starting with '_' are comments everywhere.
class FieldReader {
public:
    FieldReader(const std::string& file, Status* status) : file_(file), status_(status) {}

    bool failed() const { return !status_->ok; }
    void fail(const std::string& path, const std::string& problem);
    void warn(const std::string& path, const std::string& problem);
    const std::vector<std::string>& warnings() const { return warnings_; }

    // Unknown keys are errors (JSON scene files: they are usually typos).
    void checkKeys(const nlohmann::json& obj, const std::string& path, const std::vector<std::string>& known);
    // Unknown keys are warnings naming the key, the nearest known field when it looks misspelt, and
    // the known fields (glTF extras, where other tools keep custom properties).
    void warnUnknownKeys(const nlohmann::json& obj, const std::string& path, const std::vector<std::string>& known);

    bool object(const nlohmann::json& parent, const char* key, const std::string& path, const nlohmann::json** out);
    void number(const nlohmann::json& parent, const char* key, const std::string& path, double* out);
    void vec3(const nlohmann::json& parent, const char* key, const std::string& path, mesh4d::Vec3* out);
    // A position or direction in the scene's axes: as vec3, then turned from Z-up to glTF's Y-up,
    // (x, y, z) -> (x, z, -y), when the source is Z-up (setZUp; see readUpAxis).
    void axisVec3(const nlohmann::json& parent, const char* key, const std::string& path, mesh4d::Vec3* out);
    void setZUp(bool z_up) { z_up_ = z_up; }
    bool zUp() const { return z_up_; }
    void string(const nlohmann::json& parent, const char* key, const std::string& path, std::string* out);
    void readNumber(const nlohmann::json& j, const std::string& path, double* out);

    static std::string join(const std::string& path, const std::string& key);
    static std::string typeName(const nlohmann::json& j) { return j.type_name(); }
    static std::string describe(const nlohmann::json& j);  // type and a short dump, for messages

private:
    std::string file_;
    Status* status_;
    std::vector<std::string> warnings_;
    bool z_up_ = false;
};

// "a, b, c": field names for messages.
std::string fieldList(const std::vector<std::string>& keys);

// 17 significant digits: a number in a message reads back as the same double.
std::string formatNumber(double v);

// The known field closest to `key` by edit distance when the key looks like a misspelling of it
// (at most 2 edits, and fewer than half the key's length; a name cut short, or the first word of
// a name with a unit, "fov" for "fov_deg", counts as one edit); empty otherwise.
std::string nearestField(const std::string& key, const std::vector<std::string>& known);

// Where an object comes from, which decides who gives the fields name, mesh and position.
enum class ObjectSource {
    JsonScene,  // every field from the JSON object; mesh is required
    GltfNode,   // name, mesh and position are the node's own (its name, subtree and world
                // translation): those keys in its extras are ignored with a warning
};

// What an object field's reader needs besides the JSON: the folder that resolves mesh paths.
struct ObjectContext {
    std::filesystem::path folder;
};

// One object field of the table: the keys it reads (one field may read a group of keys that
// are only meaningful together, such as direction with gamma or rapidity) and how.
struct ObjectField {
    std::vector<std::string> keys;
    bool given_by_gltf_node;  // name, mesh, position: a glTF node gives them itself
    void (*read)(FieldReader& r, const nlohmann::json& j, const std::string& path, const ObjectContext& context,
                 ObjectSpec* obj);
    // The field states the object's motion: a keyframed glTF node (its motion from the animation)
    // refuses it.
    bool states_motion = false;
};

// The object fields in the order they are read (errors report the first problem in this order).
const std::vector<ObjectField>& objectFields();
// Every key of the table, in order.
std::vector<std::string> objectFieldNames();
// The keys that make a glTF node an object: every object key its node does not give itself.
std::vector<std::string> objectMarkerKeys();

// Reads one object's fields from `j` (a JSON object) into `obj`, which holds the defaults (and, for
// a glTF node, the name, mesh and position the node gives). `folder` resolves a relative mesh path.
// Unknown keys: an error for ObjectSource::JsonScene, a warning for ObjectSource::GltfNode.
void readObjectFields(FieldReader& r, const nlohmann::json& j, const std::string& path,
                      const std::filesystem::path& folder, ObjectSource source, ObjectSpec* obj);

// The scene-level sections, each read from `parent` (the scene object, or a glTF scene's extras)
// at `top` (the path prefix: "" for a JSON scene file). Absent sections keep their defaults.
// readCamera reads the JSON camera object at `path`; checkCamera checks a camera from any source.
void readCamera(FieldReader& r, const nlohmann::json& cam, const std::string& path, CameraSpec* camera);
void checkCamera(FieldReader& r, const std::string& path, const CameraSpec& camera);
// camera.projection ("perspective", the default, or "orthographic") and camera.width (required and
// > 0 for orthographic; a warning with perspective), from the JSON camera object at `path`.
void readProjection(FieldReader& r, const nlohmann::json& cam, const std::string& path, CameraSpec* camera);
// The light's default direction follows camera.up: read the camera first.
void readLight(FieldReader& r, const nlohmann::json& parent, const std::string& top, Scene* scene);
void readFrames(FieldReader& r, const nlohmann::json& parent, const std::string& top, FrameSpec* frames);
// A tolerance as the command line and the scene's `tolerance` string write it: "vertex" (both 0),
// "T" (light-seconds > 0: absolute = T, relative = 0) or "Fx" (0 < F < 1, a fraction of each
// object's bounding-box diagonal: relative = F, absolute = 0). False, untouched, for anything else.
bool parseTolerance(const std::string& text, double* absolute, double* relative);
// The axes of a glTF scene's vectors (its extras "up": "y", the default, or "z"): glTF is Y-up,
// but a Blender user's custom properties (which Blender's glTF exporter copies into extras
// unchanged) are in Blender's Z-up axes. With "z", every position and direction of the scene's and
// nodes' extras (velocity, direction, light.position, light.direction) is turned into glTF's axes
// as Blender's exporter turns geometry, (x, y, z) -> (x, z, -y); rotation_deg and scale, which
// have no such single rule, are refused there (use the node's own rotation and scale).
void readUpAxis(FieldReader& r, const nlohmann::json& parent, const std::string& top);
void readModelAndTolerance(FieldReader& r, const nlohmann::json& parent, const std::string& top, Scene* scene);

}  // namespace apparent
