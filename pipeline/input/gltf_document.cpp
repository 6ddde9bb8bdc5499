#include "pipeline/input/gltf_document.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <string_view>

#if !defined(APPARENT_NO_DRACO)
#include <draco/compression/decode.h>
#endif
#include <nlohmann/json.hpp>

#include "pipeline/input/input_file.h"
#include "pipeline/input/json_limits.h"

namespace apparent {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A file a document was read from, as it was then: its resolved path, size and a 64-bit hash.
struct FileStamp {
    std::string path;
    size_t size = 0;
    uint64_t hash = 0;
};

uint64_t hashBytes(const std::vector<unsigned char>& bytes) {
    return std::hash<std::string_view>{}(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

// Reads a whole regular file of at most max_bytes (input_file.h); false if it cannot be read.
bool readFile(const fs::path& path, size_t max_bytes, std::vector<unsigned char>* bytes) {
    std::string text;
    if (!readRegularFile(path.string(), max_bytes, &text).ok) return false;
    bytes->assign(text.begin(), text.end());
    return true;
}

// File access for tinygltf, confined to the glTF file's folder and to a size limit.
struct Confinement {
    fs::path root;
    size_t max_bytes;
    std::string violation;         // first refused path, for our own message
    std::vector<FileStamp> read;   // every file read through the callbacks (external buffers)
    std::string scratch;           // the bytes of the file being read
};

// Decided on the resolved path: a symlink inside the folder that points out of it is outside.
bool insideRoot(const Confinement& c, const std::string& filepath) { return resolvesInside(filepath, c.root.string()); }

bool confinedExists(const std::string& abs_filename, void* user) {
    auto* c = static_cast<Confinement*>(user);
    // tinygltf also probes candidates outside the folder (such as "./name"): those just do not
    // exist. A name inside the folder that resolves out of it (a symlink) is a violation.
    if (!insideRoot(*c, abs_filename)) {
        const fs::path lexical = fs::absolute(fs::path(abs_filename)).lexically_normal();
        std::error_code ec;
        if (c->violation.empty() && fs::exists(lexical, ec) &&
            lexical.string().rfind(c->root.string() + "/", 0) == 0)
            c->violation = abs_filename;
        return false;
    }
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
    // Only regular files, size-limited (a FIFO or device is refused before it is read).
    if (Status s = readRegularFile(p.string(), c->max_bytes, &c->scratch); !s.ok) {
        if (err) *err += s.message + "\n";
        return false;
    }
    out->assign(c->scratch.begin(), c->scratch.end());
    c->scratch = {};
    c->read.push_back({p.string(), out->size(), hashBytes(*out)});
    return true;
}

// Images are not decoded (the library is built without stb): each keeps its file bytes (PNG or
// JPEG) in Image::image, for the outputs that carry the model's textures (GltfDocument).
bool keepImageBytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                    int size, void*) {
    if (bytes && size > 0) image->image.assign(bytes, bytes + size);
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

// Whether an entry of `array` ("images", "buffers") names the file `path` resolves to by its uri.
bool referencedBy(const nlohmann::json& j, const char* array, const std::string& path) {
    auto list = j.find(array);
    if (list == j.end() || !list->is_array()) return false;
    const std::string name = fs::path(path).filename().string();
    for (const auto& e : *list)
        if (e.is_object() && e.contains("uri") && e["uri"].is_string() &&
            fs::path(e["uri"].get<std::string>()).filename().string() == name)
            return true;
    return false;
}

// Buffer and image URIs must stay inside the glTF file's folder: no absolute paths, no other
// scheme than data:, no ".." that climbs out (checked on the percent-decoded text, as tinygltf
// decodes it).
bool checkFileUris(const nlohmann::json& j, const char* array, std::string* problem) {
    auto buffers = j.find(array);
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
        const std::string where = std::string(array) + "[" + std::to_string(i) + "].uri";
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
    // Relative file (checkFileUris has refused textual escapes): confined after resolving
    // symlinks too, and only a regular file (else left to tinygltf's confined callbacks to refuse).
    const fs::path p = root / uri;
    if (!resolvesInside(p.string(), root.string())) return false;
    return readFile(p, max_bytes, out);
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
        // A missing field counts as 0; present, it must be an integer in 0..2^53 (a float such as
        // 1e300 would overflow the size_t conversions below: undefined behaviour).
        bool integral = true;
        auto num = [&](const json& o, const char* key) {
            if (!o.is_object() || !o.contains(key)) return 0.0;
            if (!o[key].is_number_unsigned() || o[key].get<uint64_t>() > (uint64_t(1) << 53)) integral = false;
            return integral ? o[key].get<double>() : 0.0;
        };
        const double len = num(view, "byteLength"), off = num(view, "byteOffset"), blen = num(buffer, "byteLength");
        if (!integral) {
            *problem = "bufferViews[" + std::to_string(bv) + "] or buffers[" + std::to_string(buf) +
                       "]: byteOffset and byteLength must be integers from 0 to 2^53";
            return false;
        }
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
#if defined(APPARENT_NO_DRACO)
    // Step: a build without Draco (the WebAssembly module) refuses what it cannot decode.
    (void)file, (void)binary, (void)root, (void)max_bytes;
    return forEachDracoPrimitive(j, [&](const json&, const json&, const std::string& prim_where) {
        *problem = prim_where + ".extensions.KHR_draco_mesh_compression: Draco-compressed meshes are not read by this "
                                "build (the WebAssembly module); use the plain or meshopt file";
        return false;
    });
#else
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
                *problem = where + ".attributes." + it.key() + ": Draco attribute id " + jsonForMessage(it.value()) + " is not in the payload";
                return false;
            }
            if (a->num_components() < 1 || a->num_components() > 4) {
                *problem = where + ".attributes." + it.key() + ": " + std::to_string(a->num_components()) + " components (glTF allows 1 to 4)";
                return false;
            }
        }
        return true;
    });
#endif
}

// tinygltf 2.7 hands an image's bufferView to the image loader without checking that it lies inside
// its buffer (tiny_gltf.h, "Load image from the buffer view"): every image's view is checked here
// against its buffer's actual bytes first.
bool checkImageViews(const nlohmann::json& j, const std::vector<unsigned char>& file, bool binary, const fs::path& root,
                     size_t max_bytes, std::string* problem) {
    auto images = j.find("images");
    if (images == j.end() || !images->is_array()) return true;
    auto arraySize = [&](const char* key) {
        auto it = j.find(key);
        return it != j.end() && it->is_array() ? it->size() : size_t(0);
    };
    const size_t n_views = arraySize("bufferViews"), n_buffers = arraySize("buffers");
    for (size_t i = 0; i < images->size(); ++i) {
        const nlohmann::json& image = (*images)[i];
        if (!image.is_object() || !image.contains("bufferView")) continue;
        const std::string where = "images[" + std::to_string(i) + "].bufferView";
        const nlohmann::json& bv = image["bufferView"];
        if (!bv.is_number_unsigned() || bv.get<uint64_t>() >= n_views) {
            *problem = where + ": " + jsonForMessage(bv) + " out of range (" + std::to_string(n_views) + " bufferViews)";
            return false;
        }
        const nlohmann::json& view = j["bufferViews"][bv.get<size_t>()];
        const std::string vwhere = "bufferViews[" + std::to_string(bv.get<size_t>()) + "]";
        if (!view.is_object() || !view.contains("buffer") || !view["buffer"].is_number_unsigned() ||
            view["buffer"].get<uint64_t>() >= n_buffers) {
            *problem = vwhere + ".buffer: missing or out of range (" + std::to_string(n_buffers) + " buffers)";
            return false;
        }
        auto field = [&](const char* key, uint64_t* value) {
            *value = 0;
            if (!view.contains(key)) return true;
            if (!view[key].is_number_unsigned() || view[key].get<uint64_t>() > (uint64_t(1) << 53)) return false;
            *value = view[key].get<uint64_t>();
            return true;
        };
        uint64_t off = 0, len = 0;
        if (!field("byteOffset", &off) || !field("byteLength", &len)) {
            *problem = vwhere + ": byteOffset and byteLength must be integers from 0 to 2^53";
            return false;
        }
        const size_t buffer = view["buffer"].get<size_t>();
        std::vector<unsigned char> bytes;
        if (!bufferBytes(j, buffer, file, binary, root, max_bytes, &bytes)) {
            *problem = where + ": buffers[" + std::to_string(buffer) + "] cannot be read";
            return false;
        }
        // tinygltf keeps a buffer's first byteLength bytes: the smaller of the two counts.
        const nlohmann::json& declared = j["buffers"][buffer];
        if (declared.is_object() && declared.contains("byteLength") && declared["byteLength"].is_number_unsigned())
            bytes.resize(std::min<uint64_t>(bytes.size(), declared["byteLength"].get<uint64_t>()));
        if (off > bytes.size() || len > bytes.size() - off) {
            *problem = where + ": " + vwhere + " (byteOffset " + std::to_string(off) + ", byteLength " + std::to_string(len) +
                       ") reaches past buffers[" + std::to_string(buffer) + "] (" + std::to_string(bytes.size()) + " bytes)";
            return false;
        }
    }
    return true;
}

// Checks and parses the bytes of glTF file `path` (resolved: `canonical`) into `doc`, file access
// confined to its folder; `read` receives the external files tinygltf read.
Status parseDocument(const std::string& path, const std::vector<unsigned char>& bytes, const fs::path& canonical,
                     const MeshLimits& limits, GltfDocument* doc, std::vector<FileStamp>* read) {
    tinygltf::Model* model = &doc->model;
    const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    std::string json_text, problem;
    if (!extractJson(path, bytes, binary, &json_text, &problem)) return Status::failure(path + ": " + problem);
    // Before any recursive parse (nlohmann's dump, tinygltf's parser): a bounded nesting depth.
    if (Status s = checkJsonDepth(path, json_text); !s.ok) return s;
    nlohmann::json j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return Status::failure(path + ": invalid JSON");
    if (!j.is_object()) return Status::failure(path + ": the glTF JSON is not an object");
    // glTF 1.0 (asset.version "1.x", or meshes as a dictionary): tinygltf would read no meshes
    // from it and the file would seem empty.
    {
        const auto asset = j.find("asset");
        const nlohmann::json version = asset != j.end() && asset->is_object() ? asset->value("version", nlohmann::json()) : nlohmann::json();
        const bool v1 = (version.is_string() && version.get<std::string>().rfind("1", 0) == 0) ||
                        (j.contains("meshes") && j["meshes"].is_object());
        if (v1)
            return Status::failure(path + ": asset.version: glTF 1.0 is not supported; convert with "
                                          "'npx gltf-pipeline -i IN -o OUT.glb' (it upgrades 1.0 to 2.0) or re-export as glTF 2.0");
    }
    if (!checkFileUris(j, "buffers", &problem) || !checkFileUris(j, "images", &problem) || !checkDracoReferences(j, &problem) ||
        !checkDracoPayloads(j, bytes, binary, canonical.parent_path(), limits.max_file_bytes, &problem) ||
        !checkImageViews(j, bytes, binary, canonical.parent_path(), limits.max_file_bytes, &problem))
        return Status::failure(path + ": " + problem);

    // Step: parse with tinygltf, file access confined to the glTF file's folder.
    Confinement conf{canonical.parent_path(), limits.max_file_bytes, {}, {}, {}};
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({&confinedExists, &confinedExpand, &confinedRead, &refuseWrite, &conf});
    loader.SetImageLoader(&keepImageBytes, nullptr);
    std::string err, warn;
    const std::string base_dir = conf.root.string();
    const bool ok = binary ? loader.LoadBinaryFromMemory(model, &err, &warn, bytes.data(), unsigned(bytes.size()), base_dir)
                           : loader.LoadASCIIFromString(model, &err, &warn, json_text.c_str(), unsigned(json_text.size()), base_dir);
    if (!conf.violation.empty())
        return Status::failure(path + ": " + (referencedBy(j, "images", conf.violation) ? "images" : "buffers") + ": URI '" +
                               conf.violation + "' is outside the glTF file's folder (refused)");
    if (!ok) return Status::failure(path + ": tinygltf: " + (err.empty() ? std::string("could not load the file") : firstLine(err)));
    if (!warn.empty()) doc->warnings.push_back("tinygltf: " + firstLine(warn));
    // Step: keep the extras as written (see GltfDocument).
    auto extrasOf = [&](const char* array, size_t count, std::vector<json>* out) {
        out->assign(count, nullptr);
        auto it = j.find(array);
        if (it == j.end() || !it->is_array()) return;
        for (size_t i = 0; i < count && i < it->size(); ++i)
            if ((*it)[i].is_object() && (*it)[i].contains("extras")) (*out)[i] = (*it)[i]["extras"];
    };
    extrasOf("nodes", model->nodes.size(), &doc->node_extras);
    extrasOf("scenes", model->scenes.size(), &doc->scene_extras);
    for (const char* array : {"materials", "textures", "samplers", "images"}) {
        auto it = j.find(array);
        doc->looks[array] = it != j.end() && it->is_array() ? *it : json::array();
    }
    *read = std::move(conf.read);
    return Status::success();
}

// Step: the cache of parsed documents, keyed by resolved path.
struct CacheEntry {
    std::shared_ptr<const GltfDocument> doc;
    std::vector<FileStamp> files;  // the glTF file first, then its external buffers
    size_t bytes = 0;              // sum of the files' sizes
    uint64_t last_use = 0;
};

struct Cache {
    std::mutex mutex;
    std::map<std::string, CacheEntry> entries;
    size_t bytes = 0;
    uint64_t clock = 0;
    size_t parses = 0;
};

Cache& cache() {
    static Cache c;
    return c;
}

// True while every file of the entry still has the bytes it had, within the size limit.
bool stillValid(const CacheEntry& e, const std::vector<unsigned char>& main_bytes, size_t max_bytes) {
    if (e.files.empty() || e.files[0].size != main_bytes.size() || e.files[0].hash != hashBytes(main_bytes)) return false;
    std::vector<unsigned char> bytes;
    for (size_t i = 1; i < e.files.size(); ++i) {
        if (!readFile(e.files[i].path, max_bytes, &bytes)) return false;
        if (bytes.size() != e.files[i].size || hashBytes(bytes) != e.files[i].hash) return false;
    }
    return true;
}

void dropEntry(Cache& c, std::map<std::string, CacheEntry>::iterator it) {
    c.bytes -= it->second.bytes;
    c.entries.erase(it);
}

}  // namespace

Status openGltf(const std::string& path, const MeshLimits& limits, std::shared_ptr<const GltfDocument>* out) {
    out->reset();
    // Step: read the file ourselves (size-limited); its bytes key the cache entry.
    std::string text;
    if (Status s = readRegularFile(path, limits.max_file_bytes, &text); !s.ok) return s;
    std::vector<unsigned char> bytes(text.begin(), text.end());
    text = {};
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(path, ec), ec);
    if (ec) return Status::failure(path + ": cannot resolve the path: " + ec.message());

    Cache& c = cache();
    std::lock_guard<std::mutex> lock(c.mutex);
    // Step: a cached document whose files are unchanged.
    if (auto it = c.entries.find(canonical.string()); it != c.entries.end()) {
        if (stillValid(it->second, bytes, limits.max_file_bytes)) {
            it->second.last_use = ++c.clock;
            *out = it->second.doc;
            return Status::success();
        }
        dropEntry(c, it);
    }

    // Step: parse, and keep the result if it fits.
    ++c.parses;
    auto doc = std::make_shared<GltfDocument>();
    std::vector<FileStamp> buffers;
    if (Status s = parseDocument(path, bytes, canonical, limits, doc.get(), &buffers); !s.ok) return s;
    CacheEntry entry;
    entry.doc = doc;
    entry.files.push_back({canonical.string(), bytes.size(), hashBytes(bytes)});
    entry.files.insert(entry.files.end(), buffers.begin(), buffers.end());
    for (const FileStamp& f : entry.files) entry.bytes += f.size;
    entry.last_use = ++c.clock;
    *out = doc;
    if (entry.bytes > kMaxCachedBytes) return Status::success();
    while (c.bytes + entry.bytes > kMaxCachedBytes && !c.entries.empty()) {
        auto oldest = c.entries.begin();
        for (auto it = c.entries.begin(); it != c.entries.end(); ++it)
            if (it->second.last_use < oldest->second.last_use) oldest = it;
        dropEntry(c, oldest);
    }
    c.bytes += entry.bytes;
    c.entries.emplace(canonical.string(), std::move(entry));
    return Status::success();
}

size_t gltfParseCount() {
    std::lock_guard<std::mutex> lock(cache().mutex);
    return cache().parses;
}

void clearGltfCache() {
    Cache& c = cache();
    std::lock_guard<std::mutex> lock(c.mutex);
    c.entries.clear();
    c.bytes = 0;
}

}  // namespace apparent
