// A glTF object's look: materials, textures, samplers and images renumbered (gltf_look.h).
#include "pipeline/input/gltf_look.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <set>

namespace apparent {

namespace {

using json = nlohmann::json;

bool keptMaterialExtension(const std::string& name) { return name.rfind("KHR_materials_", 0) == 0; }

// "image/png" or "image/jpeg" from the file's bytes (its declared type may be absent or wrong).
std::string sniffImage(const std::vector<unsigned char>& b) {
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (b.size() >= 8 && std::memcmp(b.data(), png, 8) == 0) return "image/png";
    if (b.size() >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff) return "image/jpeg";
    return "";
}

class LookBuilder {
public:
    LookBuilder(const std::string& path, const GltfDocument& doc, MeshWarnings* warnings, SurfaceLook* look)
        : path_(path), doc_(doc), warnings_(warnings), look_(look) {}

    std::string error;

    // Output index of glTF material `m` (-1: glTF's default material).
    int material(int m) {
        auto [it, fresh] = materials_.try_emplace(m, int(look_->materials.size()));
        if (!fresh) return it->second;
        look_->materials.emplace_back();
        json mat = json::object();
        const json& all = doc_.looks["materials"];
        if (m >= 0 && size_t(m) < all.size() && all[size_t(m)].is_object()) {
            mat = all[size_t(m)];
            textureInfos(&mat, "materials[" + std::to_string(m) + "]");
            extensions(&mat, "materials[" + std::to_string(m) + "]", keptMaterialExtension);
        } else if (m >= 0) {
            fail("meshes: material " + std::to_string(m) + " out of range (" + std::to_string(all.size()) + " materials)");
        }
        look_->materials[size_t(it->second)] = mat.dump();
        return it->second;
    }

private:
    void fail(const std::string& problem) {
        if (error.empty()) error = path_ + ": " + problem;
    }
    void warn(const std::string& what) {
        if (warned_.insert(what).second) warnings_->other.push_back(what);
    }

    // Keeps the extensions `keep` accepts, drops the others with a warning.
    template <class Keep>
    void extensions(json* object, const std::string& where, const Keep& keep) {
        auto it = object->find("extensions");
        if (it == object->end() || !it->is_object()) return;
        json kept = json::object();
        for (const auto& [name, value] : it->items()) {
            if (keep(name)) {
                kept[name] = value;
                if (std::find(look_->extensions.begin(), look_->extensions.end(), name) == look_->extensions.end())
                    look_->extensions.push_back(name);
            } else {
                warn(where + ".extensions." + name + ": not carried to the outputs (dropped)");
            }
        }
        if (kept.empty()) object->erase("extensions");
        else (*object)["extensions"] = kept;
    }

    // Every textureInfo ("...Texture": {"index": i, ...}) below `object`, renumbered; references
    // that cannot be kept are removed.
    void textureInfos(json* object, const std::string& where) {
        std::vector<std::string> drop;
        for (auto& [key, value] : object->items()) {
            if (!value.is_object()) continue;
            const std::string at = where + "." + key;
            const bool info = key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0 && value.contains("index");
            if (!info) {
                if (key != "extensions" && key != "extras") textureInfos(&value, at);
                else if (key == "extensions")
                    for (auto& [name, ext] : value.items())
                        if (ext.is_object()) textureInfos(&ext, at + "." + name);
                continue;
            }
            const json& index = value["index"];
            const json& set = value.value("texCoord", json(0));
            if (!index.is_number_integer() || index.get<long long>() < 0 ||
                size_t(index.get<long long>()) >= doc_.looks["textures"].size()) {
                fail(at + ".index: out of range (" + std::to_string(doc_.looks["textures"].size()) + " textures)");
                continue;
            }
            const long long s = set.is_number_integer() ? set.get<long long>() : -1;
            if (s != 0 && !(s == 1 && look_->has_texcoord1)) {
                warn(at + ": uses texture coordinate set " + set.dump() +
                     (s == 1 ? ", which its meshes do not have" : "; TEXCOORD_0 and TEXCOORD_1 are carried") + " (dropped)");
                drop.push_back(key);
                continue;
            }
            const int t = texture(int(index.get<long long>()));
            if (t < 0) {
                drop.push_back(key);
                continue;
            }
            value["index"] = t;
            extensions(&value, at, [](const std::string& n) { return n == "KHR_texture_transform"; });
        }
        for (const std::string& k : drop) object->erase(k);
    }

    // Output index of glTF texture `t`, or -1 when it cannot be kept.
    int texture(int t) {
        if (auto it = textures_.find(t); it != textures_.end()) return it->second;
        int& out = textures_[t] = -1;
        const std::string at = "textures[" + std::to_string(t) + "]";
        json tex = doc_.looks["textures"][size_t(t)];
        if (!tex.is_object()) return out;
        extensions(&tex, at, [](const std::string&) { return false; });
        const json source = tex.value("source", json());
        if (!source.is_number_integer()) {
            warn(at + ": no PNG or JPEG source (dropped)");
            return out;
        }
        const long long s = source.get<long long>();
        if (s < 0 || size_t(s) >= doc_.model.images.size()) {
            fail(at + ".source: out of range (" + std::to_string(doc_.model.images.size()) + " images)");
            return out;
        }
        const int image = this->image(int(s));
        if (image < 0) return out;
        tex["source"] = image;
        if (tex.contains("sampler")) {
            const json& sampler = tex["sampler"];
            const size_t n = doc_.looks["samplers"].size();
            if (!sampler.is_number_integer() || sampler.get<long long>() < 0 || size_t(sampler.get<long long>()) >= n) {
                fail(at + ".sampler: out of range (" + std::to_string(n) + " samplers)");
                return out;
            }
            tex["sampler"] = this->sampler(int(sampler.get<long long>()));
        }
        out = int(look_->textures.size());
        look_->textures.push_back(tex.dump());
        return out;
    }

    int sampler(int s) {
        auto [it, fresh] = samplers_.try_emplace(s, int(look_->samplers.size()));
        if (fresh) {
            json kept = json::object();
            const json& in = doc_.looks["samplers"][size_t(s)];
            for (const char* k : {"magFilter", "minFilter", "wrapS", "wrapT", "name"})
                if (in.is_object() && in.contains(k)) kept[k] = in[k];
            look_->samplers.push_back(kept.dump());
        }
        return it->second;
    }

    int image(int i) {
        if (auto it = images_.find(i); it != images_.end()) return it->second;
        int& out = images_[i] = -1;
        const tinygltf::Image& image = doc_.model.images[size_t(i)];
        const std::string type = sniffImage(image.image);
        if (type.empty()) {
            warn("images[" + std::to_string(i) + "]: " + (image.image.empty() ? "could not be read" : "not PNG or JPEG") +
                 " (its textures are dropped)");
            return out;
        }
        out = int(look_->images.size());
        look_->images.push_back({type, image.name, image.image});
        return out;
    }

    const std::string& path_;
    const GltfDocument& doc_;
    MeshWarnings* warnings_;
    SurfaceLook* look_;
    std::map<int, int> materials_, textures_, samplers_, images_;
    std::set<std::string> warned_;
};

}  // namespace

Status buildGltfLook(const std::string& path, const GltfDocument& doc, GltfLookParts parts, size_t vertices,
                     MeshWarnings* warnings, std::shared_ptr<const SurfaceLook>* out) {
    out->reset();
    const bool any_material = std::any_of(parts.triangle_material.begin(), parts.triangle_material.end(),
                                          [](int m) { return m >= 0; });
    if (!any_material && parts.texcoord.empty() && parts.texcoord1.empty() && parts.color.empty())
        return Status::success();
    auto look = std::make_shared<SurfaceLook>();
    // Step: the attributes over every vertex (later primitives without them: (0, 0) and white).
    for (std::vector<double>* uv : {&parts.texcoord, &parts.texcoord1})
        if (!uv->empty()) uv->resize(2 * vertices, 0.0);
    if (!parts.color.empty()) parts.color.resize(4 * vertices, 1.0);
    look->texcoord = std::move(parts.texcoord);
    look->texcoord1 = std::move(parts.texcoord1);
    look->has_texcoord1 = !look->texcoord1.empty();
    look->color = std::move(parts.color);
    // Step: the materials in first-use order, with what they reach.
    LookBuilder builder(path, doc, warnings, look.get());
    look->triangle_material.reserve(parts.triangle_material.size());
    for (int m : parts.triangle_material) look->triangle_material.push_back(uint32_t(builder.material(m)));
    if (!builder.error.empty()) return Status::failure(builder.error);
    *out = std::move(look);
    return Status::success();
}

}  // namespace apparent
