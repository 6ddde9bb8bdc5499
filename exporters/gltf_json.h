// The JSON chunk of a .glb sequence (exporters/glb/ SequenceModel): the glTF objects the
// exporter makes frame by frame, kept as small records, and their text, written once at the end.
//
// The text is the one nlohmann::json::dump() gives for the same document (the exporter's files
// were tinygltf's JSON parsed and dumped again by nlohmann until this writer replaced both): the
// keys of every object in byte order ("COLOR_0" < "NORMAL" < "POSITION" < "_DOPPLER" < ...,
// nlohmann's std::map), no spaces, integers in decimal, a double as the shortest text that reads
// back as the same double (Grisu2, nlohmann::detail::to_chars: "0.8", "1e-05", "2.0" for an
// integral value, "null" for a NaN or an infinity), strings escaped as nlohmann escapes them
// (\" \\ \b \f \n \r \t, other control bytes \u00xx; UTF-8 as it is; bytes that are not valid
// UTF-8 throw nlohmann's type_error, as before).
// Bounds: only the fields the exporter writes (gltf.h "Layout"); tinygltf's rules for them are
// kept: an accessor's byteOffset and a view's byteOffset only when not 0, a view's byteStride only
// when at least 4, min/max as integers for integer components.
#ifndef APPARENT_EXPORTERS_GLTF_JSON_H
#define APPARENT_EXPORTERS_GLTF_JSON_H

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace apparent::gltfjson {

// JSON text in nlohmann's dump() form, written in order: the caller gives an object's keys in
// byte order. Commas are placed by the writer.
class Text {
public:
    std::string out;

    void open(char bracket) {  // '{' or '['
        separate();
        out += bracket;
        first_ = true;
    }
    void close(char bracket) {
        out += bracket;
        first_ = false;
    }
    // A key of the open object; the next value is its value.
    void key(std::string_view k) {
        separate();
        string(k);
        out += ':';
        first_ = true;
    }
    void value(uint64_t v);
    void value(int64_t v);
    void value(int v) { value(int64_t(v)); }
    void value(double v);
    void value(bool v) {
        separate();
        out += v ? "true" : "false";
    }
    void value(std::string_view s) {
        separate();
        string(s);
    }
    void value(const char* s) { value(std::string_view(s)); }
    // A value given as JSON text already in this form (nlohmann::json::dump()).
    void raw(std::string_view json) {
        separate();
        out += json;
    }

private:
    void separate() {
        if (!first_) out += ',';
        first_ = false;
    }
    void string(std::string_view s);
    bool first_ = true;
};

// glTF vertex attributes, in the byte order of their names (so written in index order).
enum Attribute { kColor0, kNormal, kPosition, kTexcoord0, kTexcoord1, kDoppler, kEmissionTime, kProperTime, kAttributes };
const char* attributeName(int a);

struct Accessor {
    int view = -1;          // -1: none (Draco)
    int component = 0;      // glTF componentType
    bool vec3 = false;      // type VEC3, else SCALAR (or VEC2)
    bool vec2 = false;      // type VEC2
    bool normalized = false;
    uint8_t bounds = 0;     // min/max values (0: none)
    uint64_t count = 0, offset = 0;
    double min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
};

// A buffer view; with `meshopt` its EXT_meshopt_compression object (the view itself then lies in
// the fallback buffer 1).
struct BufferView {
    int buffer = 0;
    uint64_t offset = 0, length = 0, stride = 0;
    int target = 0;  // 34962, 34963 or 0: none
    bool meshopt = false;
    struct Meshopt {
        uint64_t offset = 0, length = 0, stride = 0, count = 0;
        bool indices = false, octahedral = false;
    } ext;
};

struct Primitive {
    std::array<int, kAttributes> attributes;  // accessor per Attribute, -1: absent
    int indices = -1, material = -1;
    std::vector<std::array<int, kAttributes>> targets;  // morph targets
    // KHR_draco_mesh_compression: its view (-1: none) and the Draco ids per Attribute (-1: absent).
    int draco_view = -1;
    std::array<int32_t, kAttributes> draco_ids;
    Primitive() {
        attributes.fill(-1);
        draco_ids.fill(-1);
    }
};

struct Mesh {
    std::string name;
    std::vector<Primitive> primitives;
};

struct Node {
    std::string name;
    int mesh = -1, camera = -1;
    bool has_translation = false, has_rotation = false, has_scale = false, has_mirror = false;
    double translation[3] = {0, 0, 0}, rotation[4] = {0, 0, 0, 1}, scale[3] = {1, 1, 1};
    std::vector<int> children;
    std::string mirror;        // extras {"mirror": ...} when has_mirror
    std::vector<int> weights;  // morph target weights (empty: none)
};

void write(Text* t, const Accessor& a);
void write(Text* t, const BufferView& v);
void write(Text* t, const Mesh& m);
void write(Text* t, const Node& n);

// Every textureInfo's "index" below `j` ("...Texture": {"index": i}) moved by `offset`: a
// material's textures renumbered when its file's textures are appended after others.
void moveTextureIndices(nlohmann::json* j, int offset);

}  // namespace apparent::gltfjson

#endif
