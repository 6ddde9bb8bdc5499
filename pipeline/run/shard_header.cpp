#include "pipeline/run/shard_header.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <initializer_list>

#include <unistd.h>

#include "pipeline/input/json_limits.h"
#include "pipeline/input/scene.h"
#include "pipeline/input/scene_fields.h"

namespace apparent {

const std::string kShardMagic = "apparent shard 4\n";

void putShardU64(std::string* out, uint64_t v) {
    for (int i = 0; i < 8; ++i) out->push_back(char((v >> (8 * i)) & 0xff));  // little-endian
}

namespace {

void putU64(std::string* out, uint64_t v) { putShardU64(out, v); }
void putDouble(std::string* out, double v) {
    uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    putU64(out, bits);
}
void putString(std::string* out, const std::string& s) {
    putU64(out, s.size());
    *out += s;
}

// A name written into the .glb and its summary: valid UTF-8, no control characters.
std::string nameProblem(const std::string& name) {
    if (!isValidUtf8(name)) return "not valid UTF-8 ('" + printable(name, 60) + "')";
    for (unsigned char c : name)
        if (c < 0x20 || c == 0x7f) return "holds a control character ('" + printable(name, 60) + "')";
    return "";
}

bool finite(std::initializer_list<double> values) {
    for (double v : values)
        if (!std::isfinite(v)) return false;
    return true;
}

void getLooks(ShardReader* in, SequenceInfo* info, std::string* problem);

// The header's fields back, each checked as the scene's and the command line's are (a shard is
// input like any other); the first problem as "field: problem" in `problem`, read or not.
void getSequence(ShardReader* in, SequenceInfo* info, GlbOptions* o, std::string* problem) {
    auto fail = [problem](const std::string& field, const std::string& what) {
        if (problem->empty()) *problem = field + ": " + what;
    };
    constexpr uint64_t kText = 1 << 20;  // names and paths: far below
    info->model = in->bytes(kText);
    Model model;
    if (in->ok && !parseModel(info->model, &model))
        fail("model", "'" + printable(info->model, 60) + "' is not one of instant, finite, relativistic, contracted");
    info->tolerance = in->real();
    if (in->ok && !(std::isfinite(info->tolerance) && info->tolerance >= 0))
        fail("tolerance", formatNumber(info->tolerance) + " is not a finite number >= 0");
    info->fps = in->real();
    if (in->ok && !(std::isfinite(info->fps) && info->fps > 0))
        fail("fps", formatNumber(info->fps) + " is not a finite number > 0");
    info->scene_path = in->bytes(kText);
    if (in->ok && !isValidUtf8(info->scene_path))
        fail("scene path", "not valid UTF-8 ('" + printable(info->scene_path, 60) + "')");
    // Each object takes at least 96 bytes (a name length, 4 colours, 5 material factors, a mirror
    // index and name length).
    const uint64_t n = in->u64();
    if (in->ok && (n < 1 || n > in->left() / 96)) fail("objects", std::to_string(n) + " objects, more than the file holds");
    for (uint64_t i = 0; in->ok && problem->empty() && i < n; ++i) {
        const std::string at = "objects[" + std::to_string(i) + "]";
        ExportObject e;
        e.name = in->bytes(kText);
        if (in->ok && !nameProblem(e.name).empty()) fail(at + ".name", nameProblem(e.name));
        for (double& c : e.base_color) c = in->real();
        for (double c : e.base_color)
            if (in->ok && !(c >= 0 && c <= 1)) fail(at + ".base_color", formatNumber(c) + " is outside [0, 1]");
        e.metallic = in->real();
        e.roughness = in->real();
        for (double& c : e.emissive) c = in->real();
        for (double c : {e.metallic, e.roughness, e.emissive[0], e.emissive[1], e.emissive[2]})
            if (in->ok && !(c >= 0 && c <= 1)) fail(at + ".material", formatNumber(c) + " is outside [0, 1]");
        const uint64_t mirror = in->u64();
        if (in->ok && !(int64_t(mirror) >= -1 && int64_t(mirror) < int64_t(n)))
            fail(at + ".mirror_index", std::to_string(int64_t(mirror)) + " is outside -1 .. " + std::to_string(n - 1));
        e.mirror_index = int(int64_t(mirror));
        e.mirror = in->bytes(kText);
        if (in->ok && !nameProblem(e.mirror).empty()) fail(at + ".mirror", nameProblem(e.mirror));
        info->objects.push_back(e);
    }
    ExportCamera& c = info->camera;
    for (mesh4d::Vec3* v : {&c.position, &c.look_at, &c.up}) {
        v->x = in->real();
        v->y = in->real();
        v->z = in->real();
    }
    c.fov_deg = in->real();
    if (c.fov_deg < 0) {  // an orthographic camera, written as minus its width
        c.width = -c.fov_deg;
        c.fov_deg = 60;
        if (in->ok && !(std::isfinite(c.width))) fail("camera.width", formatNumber(c.width) + " is not finite");
    }
    const mesh4d::Vec3 dir = c.look_at - c.position;
    if (in->ok && !finite({c.position.x, c.position.y, c.position.z, c.look_at.x, c.look_at.y, c.look_at.z, c.up.x,
                           c.up.y, c.up.z}))
        fail("camera", "a position, look_at or up coordinate is not finite");
    else if (in->ok && !(mesh4d::norm(mesh4d::cross(dir, c.up)) > 0))
        fail("camera", "look_at must differ from position, and up must be non-zero and not along the view");
    if (in->ok && !(c.fov_deg > 0 && c.fov_deg < 180)) fail("camera.fov_deg", formatNumber(c.fov_deg) + " is outside (0, 180)");
    // Flags 0 or 1; bits in the ranges the command line takes (cli.cpp).
    const char* names[8] = {"draco", "draco position bits", "draco normal bits", "meshopt", "meshopt bits",
                            "doppler attribute", "proper_time attribute", "shade doppler"};
    const int64_t lo[8] = {0, 1, 1, 0, 0, 0, 0, 0}, hi[8] = {1, 30, 30, 1, 16, 1, 1, 1};
    int flags[8] = {};
    for (int i = 0; i < 8; ++i) {
        const int64_t f = int64_t(in->u64());
        if (in->ok && !(f >= lo[i] && f <= hi[i]))
            fail(names[i], std::to_string(f) + " is outside " + std::to_string(lo[i]) + " .. " + std::to_string(hi[i]));
        flags[i] = int(f);
    }
    if (in->ok && flags[4] == 1) fail("meshopt bits", "1 is outside 2 .. 16 (or 0)");
    if (in->ok && flags[0] && flags[3]) fail("draco", "and meshopt both on");
    o->draco = flags[0] != 0;
    o->position_bits = flags[1];
    o->normal_bits = flags[2];
    o->meshopt = flags[3] != 0;
    o->meshopt_bits = flags[4];
    o->doppler = flags[5] != 0;
    o->proper_time = flags[6] != 0;
    o->shade_doppler = flags[7] != 0;
    // The light: a point flag, position, direction, ambient, key direction and weight.
    ExportLight& l = info->light;
    const uint64_t point = in->u64();
    if (in->ok && point > 1) fail("light.point", std::to_string(point) + " is outside 0 .. 1");
    l.point = point == 1;
    for (mesh4d::Vec3* v : {&l.position, &l.direction}) {
        v->x = in->real();
        v->y = in->real();
        v->z = in->real();
    }
    l.ambient = in->real();
    l.key_direction.x = in->real();
    l.key_direction.y = in->real();
    l.key_direction.z = in->real();
    l.key_weight = in->real();
    if (in->ok && !finite({l.position.x, l.position.y, l.position.z, l.direction.x, l.direction.y, l.direction.z,
                           l.key_direction.x, l.key_direction.y, l.key_direction.z}))
        fail("light", "a position or direction coordinate is not finite");
    if (in->ok && !(l.ambient >= 0 && l.ambient <= 1)) fail("light.ambient", formatNumber(l.ambient) + " is outside [0, 1]");
    if (in->ok && !(l.key_weight >= 0 && l.key_weight <= 1))
        fail("light.key_weight", formatNumber(l.key_weight) + " is outside [0, 1]");
    if (in->ok && problem->empty()) getLooks(in, info, problem);
}

// The objects' looks (exporters/surface_look.h) as the .glb needs them: per distinct look its
// materials, textures and samplers (JSON text), images and extensions and whether it has
// TEXCOORD_1, then per object the index of its look + 1 (0: none). The per-vertex arrays stay
// with the frames.
void putLooks(std::string* out, const SequenceInfo& info) {
    std::vector<const SurfaceLook*> looks;
    for (const ExportObject& e : info.objects)
        if (e.look && std::find(looks.begin(), looks.end(), e.look.get()) == looks.end()) looks.push_back(e.look.get());
    putU64(out, looks.size());
    for (const SurfaceLook* l : looks) {
        for (const auto* list : {&l->materials, &l->textures, &l->samplers, &l->extensions}) {
            putU64(out, list->size());
            for (const std::string& s : *list) putString(out, s);
        }
        putU64(out, l->images.size());
        for (const LookImage& im : l->images) {
            putString(out, im.mime_type);
            putString(out, im.name);
            putString(out, std::string(im.bytes.begin(), im.bytes.end()));
        }
        putU64(out, l->has_texcoord1 ? 1 : 0);
    }
    for (const ExportObject& e : info.objects)
        putU64(out, e.look ? uint64_t(std::find(looks.begin(), looks.end(), e.look.get()) - looks.begin()) + 1 : 0);
}

// A JSON object of at most `limit` bytes, its nesting bounded (json_limits.h), or null.
nlohmann::json parseObject(const std::string& text) {
    if (!checkJsonDepth("", text).ok) return nlohmann::json();
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    return j.is_object() ? j : nlohmann::json();
}

// Every textureInfo ("...Texture": {"index": i, "texCoord": s}) below `j` refers to one of
// `textures` and to a texture coordinate set below `sets`.
bool textureInfosWithin(const nlohmann::json& j, size_t textures, long long sets) {
    for (const auto& [key, value] : j.items()) {
        if (!value.is_object()) continue;
        if (key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0 && value.contains("index")) {
            const nlohmann::json& i = value["index"];
            if (!i.is_number_integer() || i.get<long long>() < 0 || uint64_t(i.get<long long>()) >= textures) return false;
            const nlohmann::json s = value.value("texCoord", nlohmann::json(0));
            if (!s.is_number_integer() || s.get<long long>() < 0 || s.get<long long>() >= sets) return false;
        } else if (!textureInfosWithin(value, textures, sets)) {
            return false;
        }
    }
    return true;
}

void getLooks(ShardReader* in, SequenceInfo* info, std::string* problem) {
    auto fail = [problem](const std::string& field, const std::string& what) {
        if (problem->empty()) *problem = field + ": " + what;
    };
    constexpr uint64_t kText = 1 << 20;
    const uint64_t n = in->u64();
    if (in->ok && n > info->objects.size()) fail("looks", std::to_string(n) + " looks for " + std::to_string(info->objects.size()) + " objects");
    std::vector<std::shared_ptr<const SurfaceLook>> looks;
    for (uint64_t k = 0; in->ok && problem->empty() && k < n; ++k) {
        const std::string at = "looks[" + std::to_string(k) + "]";
        auto look = std::make_shared<SurfaceLook>();
        std::vector<std::string>* lists[4] = {&look->materials, &look->textures, &look->samplers, &look->extensions};
        const char* names[4] = {"materials", "textures", "samplers", "extensions"};
        for (int i = 0; i < 4 && in->ok && problem->empty(); ++i) {
            const uint64_t count = in->u64();
            if (in->ok && count > in->left() / 8) fail(at + "." + names[i], "more than the file holds");
            for (uint64_t c = 0; in->ok && problem->empty() && c < count; ++c) lists[i]->push_back(in->bytes(kText));
        }
        const uint64_t images = in->u64();
        if (in->ok && images > in->left() / 24) fail(at + ".images", "more than the file holds");
        for (uint64_t c = 0; in->ok && problem->empty() && c < images; ++c) {
            LookImage im;
            im.mime_type = in->bytes(kText);
            im.name = in->bytes(kText);
            const std::string bytes = in->bytes(in->left());
            im.bytes.assign(bytes.begin(), bytes.end());
            if (in->ok && im.mime_type != "image/png" && im.mime_type != "image/jpeg")
                fail(at + ".images[" + std::to_string(c) + "].mimeType", "'" + printable(im.mime_type, 60) + "' is not image/png or image/jpeg");
            if (in->ok && !nameProblem(im.name).empty()) fail(at + ".images[" + std::to_string(c) + "].name", nameProblem(im.name));
            look->images.push_back(std::move(im));
        }
        const uint64_t texcoord1 = in->u64();
        if (in->ok && texcoord1 > 1) fail(at + ".texcoord1", std::to_string(texcoord1) + " is not 0 or 1");
        look->has_texcoord1 = texcoord1 == 1;
        // Step: the JSON the .glb takes as it is: objects, references within the lists.
        for (size_t m = 0; in->ok && problem->empty() && m < look->materials.size(); ++m) {
            const nlohmann::json j = parseObject(look->materials[m]);
            if (j.is_null() || !textureInfosWithin(j, look->textures.size(), look->has_texcoord1 ? 2 : 1))
                fail(at + ".materials[" + std::to_string(m) + "]",
                     "not a JSON object whose textures and texture coordinate sets are among the look's");
            else look->materials[m] = j.dump();
        }
        for (size_t t = 0; in->ok && problem->empty() && t < look->textures.size(); ++t) {
            const nlohmann::json j = parseObject(look->textures[t]);
            auto within = [&](const char* key, size_t count, bool required) {
                if (!j.contains(key)) return !required;
                const nlohmann::json& v = j[key];
                return v.is_number_integer() && v.get<long long>() >= 0 && uint64_t(v.get<long long>()) < count;
            };
            if (j.is_null() || !within("source", look->images.size(), true) || !within("sampler", look->samplers.size(), false))
                fail(at + ".textures[" + std::to_string(t) + "]", "not a JSON object whose source and sampler are among the look's");
            else look->textures[t] = j.dump();
        }
        for (size_t s = 0; in->ok && problem->empty() && s < look->samplers.size(); ++s) {
            const nlohmann::json j = parseObject(look->samplers[s]);
            if (j.is_null()) fail(at + ".samplers[" + std::to_string(s) + "]", "not a JSON object");
            else look->samplers[s] = j.dump();
        }
        for (const std::string& e : look->extensions)
            if (in->ok && e != "KHR_texture_transform" && e.rfind("KHR_materials_", 0) != 0)
                fail(at + ".extensions", "'" + printable(e, 60) + "' is not an extension a look carries");
        looks.push_back(std::move(look));
    }
    for (size_t i = 0; in->ok && problem->empty() && i < info->objects.size(); ++i) {
        const uint64_t ref = in->u64();
        if (in->ok && ref > looks.size()) fail("objects[" + std::to_string(i) + "].look", std::to_string(ref) + " is outside 0 .. " + std::to_string(looks.size()));
        else if (ref > 0) info->objects[i].look = looks[ref - 1];
    }
}

}  // namespace

void putShardSequence(std::string* out, const SequenceInfo& info, const GlbOptions& o) {
    putString(out, info.model);
    putDouble(out, info.tolerance);
    putDouble(out, info.fps);
    putString(out, info.scene_path);
    putU64(out, info.objects.size());
    for (const ExportObject& e : info.objects) {
        putString(out, e.name);
        for (double c : e.base_color) putDouble(out, c);
        for (double c : {e.metallic, e.roughness, e.emissive[0], e.emissive[1], e.emissive[2]}) putDouble(out, c);
        putU64(out, uint64_t(int64_t(e.mirror_index)));
        putString(out, e.mirror);
    }
    for (const mesh4d::Vec3& v : {info.camera.position, info.camera.look_at, info.camera.up})
        for (double c : {v.x, v.y, v.z}) putDouble(out, c);
    // An orthographic camera as minus its width, in the field of the field of view (which is > 0).
    putDouble(out, info.camera.orthographic() ? -info.camera.width : info.camera.fov_deg);
    for (int v : {int(o.draco), o.position_bits, o.normal_bits, int(o.meshopt), o.meshopt_bits, int(o.doppler),
                  int(o.proper_time), int(o.shade_doppler)})
        putU64(out, uint64_t(int64_t(v)));
    const ExportLight& l = info.light;
    putU64(out, l.point ? 1 : 0);
    for (const mesh4d::Vec3& v : {l.position, l.direction})
        for (double c : {v.x, v.y, v.z}) putDouble(out, c);
    putDouble(out, l.ambient);
    for (double c : {l.key_direction.x, l.key_direction.y, l.key_direction.z}) putDouble(out, c);
    putDouble(out, l.key_weight);
    putLooks(out, info);
}

uint64_t ShardReader::u64() {
    unsigned char b[8] = {};
    if (ok) ok = read(b, 8);
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= uint64_t(b[i]) << (8 * i);
    return ok ? v : 0;
}

double ShardReader::real() {
    const uint64_t bits = u64();
    double v = 0;
    std::memcpy(&v, &bits, 8);
    return v;
}

std::string ShardReader::bytes(uint64_t limit) {
    const uint64_t n = u64();
    if (ok && (n > limit || n > left_)) {
        ok = false;
        overlong = true;
    }
    // Step: in chunks of 16 MiB, so that a file that shrinks meanwhile costs no more than it holds.
    std::string s;
    constexpr uint64_t kChunk = uint64_t(1) << 24;
    while (ok && s.size() < n) {
        const size_t at = s.size(), step = size_t(std::min(kChunk, n - at));
        s.resize(at + step);
        ok = read(&s[at], step);
    }
    return ok ? s : std::string();
}

std::string ShardReader::exact(size_t n) {
    std::string s(n, '\0');
    if (ok) ok = n <= left_ && read(&s[0], n);
    return s;
}

bool ShardReader::read(void* to, size_t n) {
    if (n > left_) return false;
    char* p = static_cast<char*>(to);
    while (n > 0) {
        const ssize_t r = ::read(fd_, p, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return false;
        p += r;
        n -= size_t(r);
        left_ -= uint64_t(r);
    }
    return true;
}

Status readShardHeader(ShardReader* in, const std::string& path, ShardHeader* h) {
    ShardReader& r = *in;
    if (r.exact(kShardMagic.size()) != kShardMagic || !r.ok)
        return Status::failure(path + ": not a shard file of this version of apparent");
    h->fingerprint = r.u64();
    const uint64_t part = r.u64(), parts = r.u64();
    const uint64_t first = r.u64(), last_excl = r.u64();
    std::string problem;
    getSequence(&r, &h->info, &h->options, &problem);
    if (!r.ok)
        return Status::failure(path + ": shard header is malformed" +
                               (r.overlong ? std::string(" (a length beyond the file's end)") : std::string()));
    if (!problem.empty()) return Status::failure(path + ": shard header: " + problem);
    if (parts < 1 || parts > uint64_t(kMaxShards) || part >= parts)
        return Status::failure(path + ": shard header: part " + std::to_string(part) + " of " + std::to_string(parts) +
                               " is not a shard I/N with 0 <= I < N <= " + std::to_string(kMaxShards));
    // Frames: far below 2^62 (a scene's frame count is bounded far lower).
    if (first > uint64_t(1) << 62 || last_excl > uint64_t(1) << 62 || last_excl <= first)
        return Status::failure(path + ": shard header: frames " + std::to_string(first) + ":" +
                               std::to_string(last_excl) + " is not a range of frames");
    h->first = (long long)first;
    h->last_excl = (long long)last_excl;
    h->split = FrameSplit{int(part), int(parts)};
    putShardSequence(&h->sequence, h->info, h->options);
    return Status::success();
}

}  // namespace apparent
