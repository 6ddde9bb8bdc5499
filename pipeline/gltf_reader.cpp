#include "pipeline/gltf_reader.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <algorithm>
#include <set>

#include <draco/compression/decode.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "pipeline/mesh_check.h"
#include "pipeline/scene_json.h"

namespace apparent {

namespace fs = std::filesystem;
using mesh4d::Vec3;
using nlohmann::json;

namespace {

// A node graph is walked depth first from the roots; a node reached through several parents is
// visited once per path, so both the depth and the total number of visits are bounded.
constexpr size_t kMaxNodeDepth = 1000;
constexpr size_t kMaxNodeVisits = 1'000'000;

// Column-major 4x4 affine matrix, as glTF stores node matrices.
struct Affine {
    double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    Affine operator*(const Affine& o) const {
        Affine r;
        for (int c = 0; c < 4; ++c)
            for (int row = 0; row < 4; ++row) {
                double s = 0;
                for (int k = 0; k < 4; ++k) s += m[k * 4 + row] * o.m[c * 4 + k];
                r.m[c * 4 + row] = s;
            }
        return r;
    }
    Vec3 apply(const Vec3& p) const {
        return {m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]};
    }
    double det3() const {
        return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
               m[8] * (m[1] * m[6] - m[5] * m[2]);
    }
};

Affine localTransform(const tinygltf::Node& n) {
    Affine a;
    if (n.matrix.size() == 16) {
        for (int i = 0; i < 16; ++i) a.m[i] = n.matrix[i];
        return a;
    }
    // T * R * S (glTF 2.0 section 5.25).
    double tx = 0, ty = 0, tz = 0, qx = 0, qy = 0, qz = 0, qw = 1, sx = 1, sy = 1, sz = 1;
    if (n.translation.size() == 3) { tx = n.translation[0]; ty = n.translation[1]; tz = n.translation[2]; }
    if (n.rotation.size() == 4) { qx = n.rotation[0]; qy = n.rotation[1]; qz = n.rotation[2]; qw = n.rotation[3]; }
    if (n.scale.size() == 3) { sx = n.scale[0]; sy = n.scale[1]; sz = n.scale[2]; }
    const double r[9] = {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy + qz * qw), 2 * (qx * qz - qy * qw),
                         2 * (qx * qy - qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz + qx * qw),
                         2 * (qx * qz + qy * qw), 2 * (qy * qz - qx * qw), 1 - 2 * (qx * qx + qy * qy)};
    const double s[3] = {sx, sy, sz};
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) a.m[c * 4 + row] = r[c * 3 + row] * s[c];
    a.m[12] = tx;
    a.m[13] = ty;
    a.m[14] = tz;
    return a;
}

// File access for tinygltf, confined to the glTF file's folder and to a size limit.
struct Confinement {
    fs::path root;
    size_t max_bytes;
    std::string violation;  // first refused path, for our own message
};

bool insideRoot(const Confinement& c, const std::string& filepath) {
    std::error_code ec;
    const std::string p = fs::weakly_canonical(fs::path(filepath), ec).string();
    const std::string root = c.root.string();
    return !ec && p.compare(0, root.size(), root) == 0 && (p.size() == root.size() || p[root.size()] == '/');
}

bool confinedExists(const std::string& abs_filename, void* user) {
    // tinygltf also probes candidates outside the folder (such as "./name"): those just do not exist.
    if (!insideRoot(*static_cast<Confinement*>(user), abs_filename)) return false;
    std::error_code ec;
    return fs::is_regular_file(abs_filename, ec);
}

std::string confinedExpand(const std::string& path, void*) { return path; }

bool confinedRead(std::vector<unsigned char>* out, std::string* err, const std::string& filepath, void* user) {
    auto* c = static_cast<Confinement*>(user);
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::path(filepath), ec);
    if (!insideRoot(*c, filepath)) {
        if (c->violation.empty()) c->violation = filepath;
        if (err) *err += "refused: " + filepath + " is outside the glTF file's folder\n";
        return false;
    }
    const auto size = fs::file_size(p, ec);
    if (ec) {
        if (err) *err += "cannot read " + filepath + "\n";
        return false;
    }
    if (size > c->max_bytes) {
        if (err) *err += filepath + " is larger than the limit of " + std::to_string(c->max_bytes) + " bytes (raise with --max-file-bytes)\n";
        return false;
    }
    std::ifstream in(p, std::ios::binary);
    out->resize(size_t(size));
    if (size && !in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size))) {
        if (err) *err += "cannot read " + filepath + "\n";
        return false;
    }
    return true;
}

// Images are not needed for geometry: accept them undecoded (the library is built without stb).
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;
}

bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err = "writing is not allowed while reading";
    return false;
}

std::string firstLine(const std::string& s) {
    std::string t = s.substr(0, s.find('\n'));
    while (!t.empty() && (t.back() == '\r' || t.back() == ' ')) t.pop_back();
    return t;
}

// The JSON of a .gltf file or of a .glb's first chunk; empty with a message on a malformed header.
bool extractJson(const std::string& path, const std::vector<unsigned char>& bytes, bool binary, std::string* json,
                 std::string* problem) {
    if (!binary) {
        json->assign(bytes.begin(), bytes.end());
        return true;
    }
    // GLB header (glTF 2.0 section 4.4): magic, version, length; then chunk 0 = JSON.
    if (bytes.size() < 20) { *problem = "GLB shorter than its 20-byte header"; return false; }
    uint32_t h[5];
    std::memcpy(h, bytes.data(), 20);
    if (h[1] != 2) { *problem = "GLB version " + std::to_string(h[1]) + " (only 2 is glTF 2.0)"; return false; }
    if (h[2] > bytes.size()) { *problem = "GLB header length " + std::to_string(h[2]) + " exceeds the file size " + std::to_string(bytes.size()); return false; }
    if (h[4] != 0x4E4F534Au) { *problem = "GLB first chunk is not JSON"; return false; }
    if (uint64_t(h[3]) + 20 > h[2]) { *problem = "GLB JSON chunk length " + std::to_string(h[3]) + " exceeds the file"; return false; }
    (void)path;
    json->assign(bytes.begin() + 20, bytes.begin() + 20 + h[3]);
    return true;
}

// Buffer URIs must stay inside the glTF file's folder: no absolute paths, no other scheme than
// data:, no ".." that climbs out (checked on the percent-decoded text, as tinygltf decodes it).
bool checkBufferUris(const nlohmann::json& j, std::string* problem) {
    auto buffers = j.find("buffers");
    if (buffers == j.end() || !buffers->is_array()) return true;
    for (size_t i = 0; i < buffers->size(); ++i) {
        const auto& b = (*buffers)[i];
        if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string()) continue;
        const std::string raw = b["uri"].get<std::string>();
        if (raw.rfind("data:", 0) == 0) continue;
        std::string uri;
        for (size_t k = 0; k < raw.size(); ++k) {
            if (raw[k] == '%' && k + 2 < raw.size() && std::isxdigit((unsigned char)raw[k + 1]) &&
                std::isxdigit((unsigned char)raw[k + 2])) {
                uri += char(std::stoi(raw.substr(k + 1, 2), nullptr, 16));
                k += 2;
            } else {
                uri += raw[k];
            }
        }
        const std::string where = "buffers[" + std::to_string(i) + "].uri";
        const auto colon = uri.find(':'), slash = uri.find('/');
        const bool scheme = colon != std::string::npos && (slash == std::string::npos || colon < slash);
        if (uri.empty() || uri[0] == '/' || uri[0] == '\\' || scheme) {
            *problem = where + ": '" + raw + "' is not a relative path inside the glTF file's folder (refused)";
            return false;
        }
        const std::string normal = fs::path(uri).lexically_normal().generic_string();
        if (normal == ".." || normal.rfind("../", 0) == 0) {
            *problem = where + ": '" + raw + "' leaves the glTF file's folder (refused)";
            return false;
        }
    }
    return true;
}

// Standard base64 (RFC 4648), for data: URIs; returns false on a malformed string.
bool decodeBase64(const std::string& in, std::vector<unsigned char>* out) {
    auto value = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        if (c == '+') return 62;
        if (c == '/') return 63;
        return -1;
    };
    uint32_t acc = 0;
    int bits = 0;
    for (char c : in) {
        if (c == '=') break;
        const int v = value(c);
        if (v < 0) return false;
        acc = (acc << 6) | uint32_t(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out->push_back(static_cast<unsigned char>((acc >> bits) & 0xff));
        }
    }
    return true;
}

// The bytes of buffers[index]: the GLB's BIN chunk, a data: URI, or a file inside `root`.
bool bufferBytes(const nlohmann::json& j, size_t index, const std::vector<unsigned char>& glb, bool binary,
                 const fs::path& root, size_t max_bytes, std::vector<unsigned char>* out) {
    const auto& b = j["buffers"][index];
    if (!b.is_object()) return false;
    if (!b.contains("uri")) {
        // GLB BIN chunk: after the JSON chunk, padded to 4 bytes (glTF 2.0 section 4.4.3).
        if (!binary || index != 0 || glb.size() < 20) return false;
        uint32_t json_len;
        std::memcpy(&json_len, glb.data() + 12, 4);
        const size_t at = 20 + size_t(json_len);
        if (at + 8 > glb.size()) return false;
        uint32_t bin_len, bin_type;
        std::memcpy(&bin_len, glb.data() + at, 4);
        std::memcpy(&bin_type, glb.data() + at + 4, 4);
        if (bin_type != 0x004E4942u || at + 8 + size_t(bin_len) > glb.size()) return false;
        out->assign(glb.begin() + long(at + 8), glb.begin() + long(at + 8 + bin_len));
        return true;
    }
    if (!b["uri"].is_string()) return false;
    const std::string uri = b["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
        const auto comma = uri.find(";base64,");
        return comma != std::string::npos && decodeBase64(uri.substr(comma + 8), out);
    }
    // Relative file (checkBufferUris has refused escapes already).
    std::error_code ec;
    const fs::path p = root / uri;
    const auto size = fs::file_size(p, ec);
    if (ec || size > max_bytes) return false;
    std::ifstream in(p, std::ios::binary);
    out->resize(size_t(size));
    return size == 0 || bool(in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size)));
}

// Calls fn(primitive, draco_extension, "meshes[m].primitives[p]") for every primitive with a
// KHR_draco_mesh_compression object; stops and returns false as soon as fn does.
template <class Fn>
bool forEachDracoPrimitive(const nlohmann::json& j, Fn fn) {
    auto meshes = j.find("meshes");
    if (meshes == j.end() || !meshes->is_array()) return true;
    for (size_t m = 0; m < meshes->size(); ++m) {
        const nlohmann::json& mesh = (*meshes)[m];
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
        for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
            const nlohmann::json& prim = mesh["primitives"][p];
            if (!prim.is_object() || !prim.contains("extensions") || !prim["extensions"].is_object()) continue;
            auto dr = prim["extensions"].find("KHR_draco_mesh_compression");
            if (dr == prim["extensions"].end()) continue;
            if (!fn(prim, *dr, "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]")) return false;
        }
    }
    return true;
}

// References tinygltf's Draco decoder follows without checking them, checked here.
bool checkDracoReferences(const nlohmann::json& j, std::string* problem) {
    using nlohmann::json;
    auto arraySize = [&](const char* key) {
        auto it = j.find(key);
        return it != j.end() && it->is_array() ? it->size() : size_t(0);
    };
    const size_t n_views = arraySize("bufferViews"), n_buffers = arraySize("buffers"), n_accessors = arraySize("accessors");
    return forEachDracoPrimitive(j, [&](const json& prim, const json& draco, const std::string& where) {
        const json* dr = &draco;
        const std::string dwhere = where + ".extensions.KHR_draco_mesh_compression";
        if (!dr->is_object() || !dr->contains("bufferView") || !(*dr)["bufferView"].is_number_integer()) {
            *problem = dwhere + ".bufferView: missing or not an integer";
            return false;
        }
        const long long bv = (*dr)["bufferView"].get<long long>();
        if (bv < 0 || size_t(bv) >= n_views) {
            *problem = dwhere + ".bufferView: " + std::to_string(bv) + " out of range (" + std::to_string(n_views) + " bufferViews)";
            return false;
        }
        const json& view = j["bufferViews"][size_t(bv)];
        const long long buf = view.is_object() && view.contains("buffer") && view["buffer"].is_number_integer()
                                  ? view["buffer"].get<long long>() : -1;
        if (buf < 0 || size_t(buf) >= n_buffers) {
            *problem = "bufferViews[" + std::to_string(bv) + "].buffer: out of range (" + std::to_string(n_buffers) + " buffers)";
            return false;
        }
        const json& buffer = j["buffers"][size_t(buf)];
        auto num = [](const json& o, const char* key) {  // a missing or non-number field counts as 0
            return o.is_object() && o.contains(key) && o[key].is_number() ? o[key].get<double>() : 0.0;
        };
        const double len = num(view, "byteLength"), off = num(view, "byteOffset"), blen = num(buffer, "byteLength");
        if (!(off >= 0 && len >= 0 && off + len <= blen)) {
            *problem = "bufferViews[" + std::to_string(bv) + "]: byteOffset + byteLength exceeds buffers[" + std::to_string(buf) + "].byteLength";
            return false;
        }
        if (prim.contains("indices")) {
            const auto& ind = prim["indices"];
            if (!ind.is_number_integer() || ind.get<long long>() < 0 || size_t(ind.get<long long>()) >= n_accessors) {
                *problem = where + ".indices: accessor out of range (" + std::to_string(n_accessors) + " accessors)";
                return false;
            }
        }
        if (!dr->contains("attributes") || !(*dr)["attributes"].is_object() || !prim.contains("attributes") ||
            !prim["attributes"].is_object()) {
            *problem = dwhere + ".attributes: missing";
            return false;
        }
        for (auto it = (*dr)["attributes"].begin(); it != (*dr)["attributes"].end(); ++it) {
            auto acc = prim["attributes"].find(it.key());
            if (acc == prim["attributes"].end() || !acc->is_number_integer() || acc->get<long long>() < 0 ||
                size_t(acc->get<long long>()) >= n_accessors) {
                *problem = where + ".attributes." + it.key() + ": accessor missing or out of range";
                return false;
            }
            // Draco numbers attributes 0, 1, ... in the order they were added; an id past a
            // small bound cannot name a decoded attribute, and tinygltf would dereference null.
            if (!it.value().is_number_integer() || it.value().get<long long>() < 0 ||
                it.value().get<long long>() >= (long long)(*dr)["attributes"].size()) {
                *problem = dwhere + ".attributes." + it.key() + ": Draco attribute id out of range";
                return false;
            }
        }
        return true;
    });
}

// tinygltf 2.7 decodes Draco attributes into a 4-value stack array and dereferences the
// attribute named by each id without checking (tiny_gltf.h, GetAttributeForAllPoints and
// ParseDracoExtension): decode every Draco bufferView first and require each listed id to exist
// with at most 4 components.
bool checkDracoPayloads(const nlohmann::json& j, const std::vector<unsigned char>& file, bool binary,
                        const fs::path& root, size_t max_bytes, std::string* problem) {
    return forEachDracoPrimitive(j, [&](const json&, const json& draco, const std::string& prim_where) {
        const json* dr = &draco;
        const std::string where = prim_where + ".extensions.KHR_draco_mesh_compression";
        // checkDracoReferences has validated the indices and ranges used here.
        const auto& view = j["bufferViews"][(*dr)["bufferView"].get<size_t>()];
        const size_t buffer = view["buffer"].get<size_t>();
        std::vector<unsigned char> bytes;
        if (!bufferBytes(j, buffer, file, binary, root, max_bytes, &bytes)) return true;  // tinygltf reports it
        const size_t off = view.contains("byteOffset") && view["byteOffset"].is_number() ? view["byteOffset"].get<size_t>() : 0;
        const size_t len = view.contains("byteLength") && view["byteLength"].is_number() ? view["byteLength"].get<size_t>() : 0;
        if (off > bytes.size() || len > bytes.size() - off) {
            *problem = where + ".bufferView: reaches past buffers[" + std::to_string(buffer) + "] (" + std::to_string(bytes.size()) + " bytes)";
            return false;
        }
        draco::DecoderBuffer db;
        db.Init(reinterpret_cast<const char*>(bytes.data() + off), len);
        draco::Decoder decoder;
        auto decoded = decoder.DecodeMeshFromBuffer(&db);
        if (!decoded.ok()) {
            *problem = where + ": Draco cannot decode the bufferView: " + decoded.status().error_msg_string();
            return false;
        }
        const std::unique_ptr<draco::Mesh> dm = std::move(decoded).value();
        for (auto it = (*dr)["attributes"].begin(); it != (*dr)["attributes"].end(); ++it) {
            const draco::PointAttribute* a = dm->GetAttributeByUniqueId(uint32_t(it.value().get<long long>()));
            if (!a) {
                *problem = where + ".attributes." + it.key() + ": Draco attribute id " + it.value().dump() + " is not in the payload";
                return false;
            }
            if (a->num_components() < 1 || a->num_components() > 4) {
                *problem = where + ".attributes." + it.key() + ": " + std::to_string(a->num_components()) + " components (glTF allows 1 to 4)";
                return false;
            }
        }
        return true;
    });
}

const char* componentName(int c) {
    switch (c) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
    }
    return "unknown";
}

class Reader {
public:
    Reader(const std::string& file, const tinygltf::Model& model, const MeshLimits& limits, LoadedMesh* out,
           MeshWarnings* warnings)
        : file_(file), model_(model), limits_(limits), out_(out), warnings_(warnings) {}

    Status status;

    bool fail(const std::string& where, const std::string& problem) {
        if (status.ok) status = Status::failure(file_ + ": " + where + ": " + problem);
        return false;
    }

    // Step: walk the node graph from `roots`, applying transforms; cycles are errors.
    bool walk(int node, const Affine& parent, std::vector<int>& path, bool apply_own_transform) {
        if (node < 0 || size_t(node) >= model_.nodes.size())
            return fail("nodes", "index " + std::to_string(node) + " out of range (" + std::to_string(model_.nodes.size()) + " nodes)");
        for (int p : path)
            if (p == node) return fail("nodes[" + std::to_string(node) + "]", "the node hierarchy has a cycle");
        if (path.size() > kMaxNodeDepth)
            return fail("nodes[" + std::to_string(node) + "]", "node hierarchy deeper than " + std::to_string(kMaxNodeDepth));
        if (++visits_ > kMaxNodeVisits)
            return fail("nodes", "more than " + std::to_string(kMaxNodeVisits) + " node visits (nodes shared by many parents)");
        const tinygltf::Node& n = model_.nodes[size_t(node)];
        const Affine world = apply_own_transform ? parent * localTransform(n) : parent;
        for (int i = 0; i < 16; ++i)
            if (!std::isfinite(world.m[i])) return fail("nodes[" + std::to_string(node) + "]", "transform is not finite");
        path.push_back(node);
        if (n.mesh >= 0 && !addMesh(n.mesh, world)) return false;
        for (int child : n.children)
            if (!walk(child, world, path, true)) return false;
        path.pop_back();
        return true;
    }

private:
    size_t visits_ = 0;
    std::string file_;
    const tinygltf::Model& model_;
    MeshLimits limits_;
    LoadedMesh* out_;
    MeshWarnings* warnings_;

    // Reads accessor `index` as `components` doubles per element, with every range checked and
    // sparse substitutions applied.
    bool readAccessor(int index, const std::string& where, int components, bool integer, std::vector<double>* values) {
        if (index < 0 || size_t(index) >= model_.accessors.size())
            return fail(where, "accessor " + std::to_string(index) + " out of range (" + std::to_string(model_.accessors.size()) + " accessors)");
        const tinygltf::Accessor& a = model_.accessors[size_t(index)];
        const std::string aw = "accessors[" + std::to_string(index) + "]";
        const int ncomp = tinygltf::GetNumComponentsInType(uint32_t(a.type));
        if (ncomp != components) return fail(aw + ".type", "expected " + std::to_string(components) + " components, got " + std::to_string(ncomp));
        const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
        if (csize <= 0) return fail(aw + ".componentType", "invalid (" + std::to_string(a.componentType) + ")");
        if (!integer && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            return fail(aw + ".componentType", std::string("POSITION must be FLOAT, got ") + componentName(a.componentType));
        if (integer && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return fail(aw + ".componentType", std::string("indices must be unsigned integers, got ") + componentName(a.componentType));
        if (a.count == 0) return fail(aw + ".count", "is 0");
        const size_t count_limit = integer ? 3 * limits_.max_faces : limits_.max_vertices;
        if (a.count > count_limit)
            return fail(aw + ".count", std::to_string(a.count) + " exceeds the limit of " + std::to_string(count_limit) +
                                           (integer ? " (raise with --max-faces)" : " (raise with --max-vertices)"));
        const size_t elem = size_t(csize) * size_t(components);
        values->assign(a.count * size_t(components), 0.0);

        auto decode = [&](const uint8_t* p, double* dst) {
            for (int c = 0; c < components; ++c) {
                const uint8_t* q = p + size_t(c) * size_t(csize);
                switch (a.componentType) {
                    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, q, 4); dst[c] = f; break; }
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: dst[c] = *q; break;
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, q, 2); dst[c] = v; break; }
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, q, 4); dst[c] = v; break; }
                }
            }
        };
        // A view's bytes [offset, offset + length) inside its buffer, checked.
        auto viewBytes = [&](int view_index, const std::string& vw, const uint8_t** base, size_t* length, size_t* stride) {
            if (view_index < 0 || size_t(view_index) >= model_.bufferViews.size())
                return fail(vw, "bufferView " + std::to_string(view_index) + " out of range (" + std::to_string(model_.bufferViews.size()) + " bufferViews)");
            const tinygltf::BufferView& v = model_.bufferViews[size_t(view_index)];
            const std::string bw = "bufferViews[" + std::to_string(view_index) + "]";
            if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size())
                return fail(bw + ".buffer", "out of range (" + std::to_string(model_.buffers.size()) + " buffers)");
            const auto& data = model_.buffers[size_t(v.buffer)].data;
            if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
                return fail(bw, "byteOffset " + std::to_string(v.byteOffset) + " + byteLength " + std::to_string(v.byteLength) +
                                    " exceeds the buffer's " + std::to_string(data.size()) + " bytes");
            *base = data.data() + v.byteOffset;
            *length = v.byteLength;
            *stride = v.byteStride ? v.byteStride : 0;
            return true;
        };

        // Step: dense data (absent bufferView means zeros, glTF 2.0 section 5.1.1).
        if (a.bufferView >= 0) {
            const uint8_t* base;
            size_t length, stride;
            if (!viewBytes(a.bufferView, aw + ".bufferView", &base, &length, &stride)) return false;
            if (stride == 0) stride = elem;
            if (stride < elem) return fail("bufferViews[" + std::to_string(a.bufferView) + "].byteStride", "smaller than an element");
            if (a.byteOffset > length || (a.count - 1) > (length - a.byteOffset - std::min(length - a.byteOffset, elem)) / stride ||
                a.byteOffset + (a.count - 1) * stride + elem > length)
                return fail(aw, "count " + std::to_string(a.count) + " with byteOffset " + std::to_string(a.byteOffset) +
                                    " reaches past bufferViews[" + std::to_string(a.bufferView) + "] (" + std::to_string(length) + " bytes)");
            for (size_t i = 0; i < a.count; ++i) decode(base + a.byteOffset + i * stride, values->data() + i * size_t(components));
        }
        // Step: sparse substitutions.
        if (a.sparse.isSparse) {
            const auto& sp = a.sparse;
            const std::string sw = aw + ".sparse";
            if (sp.count <= 0 || size_t(sp.count) > a.count) return fail(sw + ".count", "out of range 1.." + std::to_string(a.count));
            const int isize = tinygltf::GetComponentSizeInBytes(uint32_t(sp.indices.componentType));
            if (isize != 1 && isize != 2 && isize != 4) return fail(sw + ".indices.componentType", "invalid");
            const uint8_t *ib, *vb;
            size_t ilen, vlen, unused;
            if (!viewBytes(sp.indices.bufferView, sw + ".indices.bufferView", &ib, &ilen, &unused)) return false;
            if (!viewBytes(sp.values.bufferView, sw + ".values.bufferView", &vb, &vlen, &unused)) return false;
            const size_t n = size_t(sp.count);
            if (size_t(sp.indices.byteOffset) > ilen || n * size_t(isize) > ilen - size_t(sp.indices.byteOffset))
                return fail(sw + ".indices", "reach past their bufferView");
            if (size_t(sp.values.byteOffset) > vlen || n * elem > vlen - size_t(sp.values.byteOffset))
                return fail(sw + ".values", "reach past their bufferView");
            for (size_t i = 0; i < n; ++i) {
                uint32_t target = 0;
                const uint8_t* q = ib + sp.indices.byteOffset + i * size_t(isize);
                if (isize == 1) target = *q;
                else if (isize == 2) { uint16_t v; std::memcpy(&v, q, 2); target = v; }
                else std::memcpy(&target, q, 4);
                if (target >= a.count) return fail(sw + ".indices", "index " + std::to_string(target) + " out of range (" + std::to_string(a.count) + " elements)");
                decode(vb + sp.values.byteOffset + i * elem, values->data() + size_t(target) * size_t(components));
            }
        }
        return true;
    }

    bool addMesh(int mesh_index, const Affine& world) {
        if (size_t(mesh_index) >= model_.meshes.size())
            return fail("nodes.mesh", "mesh " + std::to_string(mesh_index) + " out of range (" + std::to_string(model_.meshes.size()) + " meshes)");
        const tinygltf::Mesh& mesh = model_.meshes[size_t(mesh_index)];
        const bool mirrored = world.det3() < 0;  // a mirroring transform flips the winding
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const std::string where = "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(p) + "]";
            // Step: which primitives hold surfaces.
            if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
                ++warnings_->points_lines_skipped;
                continue;
            }
            if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
                return fail(where + ".mode", "invalid (" + std::to_string(prim.mode) + ")");
            auto pos_it = prim.attributes.find("POSITION");
            if (pos_it == prim.attributes.end()) return fail(where + ".attributes", "no POSITION");

            // Step: positions, transformed to the node's world frame in double.
            std::vector<double> pos;
            if (!readAccessor(pos_it->second, where + ".attributes.POSITION", 3, false, &pos)) return false;
            const size_t nv = pos.size() / 3;
            const uint32_t base = uint32_t(out_->mesh.positions.size());
            if (out_->mesh.positions.size() + nv > limits_.max_vertices)
                return fail(where, "more than " + std::to_string(limits_.max_vertices) + " vertices in all (raise with --max-vertices)");
            for (size_t i = 0; i < nv; ++i) {
                const Vec3 v{pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
                if (!mesh4d::isFinite(v)) return fail(where + ".attributes.POSITION", "vertex " + std::to_string(i) + " is not finite");
                out_->mesh.positions.push_back(world.apply(v));
            }

            // Step: indices, or 0..n-1 for non-indexed primitives.
            std::vector<double> idx;
            if (prim.indices >= 0) {
                if (!readAccessor(prim.indices, where + ".indices", 1, true, &idx)) return false;
            } else {
                idx.resize(nv);
                for (size_t i = 0; i < nv; ++i) idx[i] = double(i);
            }
            for (size_t i = 0; i < idx.size(); ++i)
                if (idx[i] >= double(nv))
                    return fail(where + ".indices", "index " + std::to_string((unsigned long long)idx[i]) + " out of range (" + std::to_string(nv) + " vertices)");

            // Step: triangles from lists, strips and fans (glTF 2.0 section 3.7.2.1).
            auto add = [&](size_t a, size_t b, size_t c) {
                std::array<uint32_t, 3> t{base + uint32_t(idx[a]), base + uint32_t(idx[b]), base + uint32_t(idx[c])};
                if (mirrored) std::swap(t[1], t[2]);
                out_->mesh.triangles.push_back(t);
            };
            const size_t n = idx.size();
            if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
                if (n % 3) return fail(where + ".indices", "count " + std::to_string(n) + " is not a multiple of 3");
                for (size_t i = 0; i + 2 < n; i += 3) add(i, i + 1, i + 2);
            } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                ++warnings_->strips_fans_triangulated;
                for (size_t i = 0; i + 2 < n; ++i) i % 2 ? add(i + 1, i, i + 2) : add(i, i + 1, i + 2);
            } else {
                ++warnings_->strips_fans_triangulated;
                for (size_t i = 1; i + 1 < n; ++i) add(i, i + 1, 0);
            }
            if (out_->mesh.triangles.size() > limits_.max_faces)
                return fail(where, "more than " + std::to_string(limits_.max_faces) + " triangles in all (raise with --max-faces)");

            // Step: the first material with a base colour gives the object's colour.
            if (!out_->has_color && prim.material >= 0 && size_t(prim.material) < model_.materials.size()) {
                const auto& f = model_.materials[size_t(prim.material)].pbrMetallicRoughness.baseColorFactor;
                if (f.size() == 4) {
                    out_->has_color = true;
                    for (int c = 0; c < 4; ++c) out_->color[size_t(c)] = f[size_t(c)];
                }
            }
        }
        return true;
    }
};


// Reads, checks and parses a glTF file into `model` (tinygltf), file access confined.
Status loadModel(const std::string& path, const MeshLimits& limits, tinygltf::Model* model, MeshWarnings* warnings) {
    // Step: read the file ourselves (size-limited) and check what tinygltf would not.
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec) return Status::failure(path + ": cannot open file");
    if (size > limits.max_file_bytes)
        return Status::failure(path + ": larger than the limit of " + std::to_string(limits.max_file_bytes) + " bytes (raise with --max-file-bytes)");
    std::vector<unsigned char> bytes(size_t(size), 0);
    {
        std::ifstream in(path, std::ios::binary);
        if (!in || (size && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size))))
            return Status::failure(path + ": cannot read file");
    }
    const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    std::string json_text, problem;
    if (!extractJson(path, bytes, binary, &json_text, &problem)) return Status::failure(path + ": " + problem);
    nlohmann::json j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return Status::failure(path + ": invalid JSON");
    if (!j.is_object()) return Status::failure(path + ": the glTF JSON is not an object");
    std::error_code canon_ec;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(path, canon_ec), canon_ec);
    if (canon_ec) return Status::failure(path + ": cannot resolve the path: " + canon_ec.message());
    if (!checkBufferUris(j, &problem) || !checkDracoReferences(j, &problem) ||
        !checkDracoPayloads(j, bytes, binary, canonical.parent_path(), limits.max_file_bytes, &problem))
        return Status::failure(path + ": " + problem);

    // Step: parse with tinygltf, file access confined to the glTF file's folder.
    Confinement conf{canonical.parent_path(), limits.max_file_bytes, {}};
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({&confinedExists, &confinedExpand, &confinedRead, &refuseWrite, &conf});
    loader.SetImageLoader(&skipImage, nullptr);
    std::string err, warn;
    const std::string base_dir = conf.root.string();
    const bool ok = binary ? loader.LoadBinaryFromMemory(model, &err, &warn, bytes.data(), unsigned(bytes.size()), base_dir)
                           : loader.LoadASCIIFromString(model, &err, &warn, json_text.c_str(), unsigned(json_text.size()), base_dir);
    if (!conf.violation.empty())
        return Status::failure(path + ": buffers: URI '" + conf.violation + "' is outside the glTF file's folder (refused)");
    if (!ok) return Status::failure(path + ": tinygltf: " + (err.empty() ? std::string("could not load the file") : firstLine(err)));
    if (!warn.empty()) warnings->other.push_back("tinygltf: " + firstLine(warn));
    return Status::success();
}

nlohmann::json toJson(const tinygltf::Value& v) {
    switch (v.Type()) {
        case tinygltf::BOOL_TYPE: return v.Get<bool>();
        case tinygltf::INT_TYPE: return v.Get<int>();
        case tinygltf::REAL_TYPE: return v.Get<double>();
        case tinygltf::STRING_TYPE: return v.Get<std::string>();
        case tinygltf::ARRAY_TYPE: {
            nlohmann::json a = nlohmann::json::array();
            for (size_t i = 0; i < v.ArrayLen(); ++i) a.push_back(toJson(v.Get(int(i))));
            return a;
        }
        case tinygltf::OBJECT_TYPE: {
            nlohmann::json o = nlohmann::json::object();
            for (const auto& key : v.Keys()) o[key] = toJson(v.Get(key));
            return o;
        }
        default: return nullptr;
    }
}

}  // namespace

Status loadGltfScene(const std::string& path, Scene* scene) {
    *scene = Scene{};
    scene->path = path;
    tinygltf::Model model;
    MeshWarnings warnings;
    if (Status s = loadModel(path, MeshLimits{}, &model, &warnings); !s.ok) return s;
    if (model.scenes.empty()) return Status::failure(path + ": scenes: none (a scene file needs a scene whose nodes carry extras)");
    const size_t si = model.defaultScene >= 0 && size_t(model.defaultScene) < model.scenes.size() ? size_t(model.defaultScene) : 0;

    // Step: scene-level extras give frames, model and tolerance.
    nlohmann::json root = nlohmann::json::object();
    SceneJsonPaths paths;
    paths.top = "scenes[" + std::to_string(si) + "].extras";
    const nlohmann::json sx = toJson(model.scenes[si].extras);
    if (sx.is_object())
        for (const char* key : {"frames", "model", "tolerance", "light"})
            if (sx.contains(key)) root[key] = sx[key];

    // Step: walk the node tree; nodes whose extras carry object fields become objects, the first
    // camera node becomes the camera.
    const std::string file = fs::path(path).filename().string();
    nlohmann::json objects = nlohmann::json::array();
    std::set<std::string> names;
    std::string problem;
    size_t visits = 0;
    std::function<bool(int, const Affine&, int, std::vector<int>&)> visit =
        [&](int n, const Affine& parent, int owner, std::vector<int>& stack) -> bool {
        const std::string where = "nodes[" + std::to_string(n) + "]";
        if (n < 0 || size_t(n) >= model.nodes.size()) { problem = "nodes: index " + std::to_string(n) + " out of range"; return false; }
        if (std::find(stack.begin(), stack.end(), n) != stack.end()) { problem = where + ": the node hierarchy has a cycle"; return false; }
        if (stack.size() > kMaxNodeDepth) { problem = where + ": node hierarchy deeper than " + std::to_string(kMaxNodeDepth); return false; }
        if (++visits > kMaxNodeVisits) { problem = "nodes: more than " + std::to_string(kMaxNodeVisits) + " node visits (nodes shared by many parents)"; return false; }
        const tinygltf::Node& node = model.nodes[size_t(n)];
        const Affine world = parent * localTransform(node);
        stack.push_back(n);
        if (node.camera >= 0 && !root.contains("camera") && size_t(node.camera) < model.cameras.size()) {
            // glTF cameras look down local -Z with +Y up.
            const Vec3 pos = world.apply({0, 0, 0});
            const Vec3 ahead = world.apply({0, 0, -1}) - pos, up = world.apply({0, 1, 0}) - pos;
            const Vec3 look = pos + ahead / mesh4d::norm(ahead);
            const auto& cam = model.cameras[size_t(node.camera)];
            root["camera"] = {{"position", {pos.x, pos.y, pos.z}}, {"look_at", {look.x, look.y, look.z}},
                              {"up", {up.x, up.y, up.z}}};
            if (cam.type == "perspective") root["camera"]["fov_deg"] = cam.perspective.yfov * 180.0 / 3.14159265358979323846;
            if (const nlohmann::json cx = toJson(node.extras); cx.is_object() && cx.contains("instant_delay"))
                root["camera"]["instant_delay"] = cx["instant_delay"];
            paths.camera = where;
        }
        const nlohmann::json ex = toJson(node.extras);
        const bool is_object = ex.is_object() && (ex.contains("velocity") || ex.contains("t0") || ex.contains("exists"));
        if (is_object) {
            if (owner >= 0) { problem = where + ": is inside object nodes[" + std::to_string(owner) + "] (objects cannot nest)"; return false; }
            if (node.name.empty() || node.name.find('#') != std::string::npos) { problem = where + ".name: an object node needs a name without '#'"; return false; }
            if (!names.insert(node.name).second) { problem = where + ".name: '" + node.name + "' names two object nodes"; return false; }
            nlohmann::json obj = nlohmann::json::object();
            // Known object fields are taken from the extras; other custom properties are ignored.
            for (const char* key : {"t0", "velocity", "exists", "rotation_deg", "scale", "mirror"})
                if (ex.contains(key)) obj[key] = ex[key];
            obj["name"] = node.name;
            obj["mesh"] = file + "#" + node.name;
            const Vec3 pos = world.apply({0, 0, 0});
            obj["position"] = {pos.x, pos.y, pos.z};
            objects.push_back(obj);
            paths.objects.push_back(where + ".extras");
            std::array<double, 9> linear{};
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r) linear[size_t(c * 3 + r)] = world.m[c * 4 + r];
            paths.linear.push_back(linear);
            owner = n;
        }
        for (int child : node.children)
            if (!visit(child, world, owner, stack)) return false;
        stack.pop_back();
        return true;
    };
    for (int r : model.scenes[si].nodes) {
        std::vector<int> stack;
        if (!visit(r, Affine{}, -1, stack)) return Status::failure(path + ": " + problem);
    }
    if (objects.empty())
        return Status::failure(path + ": nodes: no node carries object extras (velocity, t0 or exists) in scene " + std::to_string(si));
    root["objects"] = objects;
    return parseScene(root, path, paths, scene);
}

Status readGltf(const std::string& path_and_node, const MeshLimits& limits, LoadedMesh* out, MeshWarnings* warnings) {
    const auto hash = path_and_node.rfind('#');
    const std::string path = path_and_node.substr(0, hash);
    const std::string node_name = hash == std::string::npos ? "" : path_and_node.substr(hash + 1);
    *out = LoadedMesh{};
    tinygltf::Model model;
    if (Status s = loadModel(path, limits, &model, warnings); !s.ok) return s;

    // Step: choose the roots: one named node, the default scene, the first scene, or every root node.
    Reader reader(path, model, limits, out, warnings);
    std::vector<int> roots;
    bool own_transform = true;
    if (!node_name.empty()) {
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (model.nodes[i].name == node_name) roots.push_back(int(i));
        if (roots.empty()) return Status::failure(path + ": nodes: no node named '" + node_name + "'");
        if (roots.size() > 1) return Status::failure(path + ": nodes: " + std::to_string(roots.size()) + " nodes are named '" + node_name + "'");
        own_transform = false;
    } else if (!model.scenes.empty()) {
        const int s = model.defaultScene >= 0 && size_t(model.defaultScene) < model.scenes.size() ? model.defaultScene : 0;
        roots = model.scenes[size_t(s)].nodes;
    } else {
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = true;
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(int(i));
    }
    for (int r : roots) {
        std::vector<int> path_stack;
        if (!reader.walk(r, Affine{}, path_stack, own_transform)) return reader.status;
    }

    // Step: what is left must be a surface.
    if (out->mesh.triangles.empty())
        return Status::failure(path + ": no triangles in " + (node_name.empty() ? "the scene" : "node '" + node_name + "'") +
                               (warnings->points_lines_skipped
                                    ? " (" + std::to_string(warnings->points_lines_skipped) + " point or line primitives skipped)"
                                    : std::string()));
    warnings->degenerate_dropped += dropDegenerateTriangles(&out->mesh);
    if (out->mesh.triangles.empty()) return Status::failure(path + ": every triangle is degenerate (zero area)");
    return Status::success();
}

}  // namespace apparent
