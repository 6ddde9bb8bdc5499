#include "exporters/gltf_json.h"

#include <charconv>
#include <cmath>

#include <nlohmann/json.hpp>

namespace apparent::gltfjson {

namespace {

constexpr int kFloat = 5126, kDouble = 5130;

}  // namespace

void Text::value(uint64_t v) {
    separate();
    char buf[24];
    out.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

void Text::value(int64_t v) {
    separate();
    char buf[24];
    out.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

void Text::value(double v) {
    separate();
    if (!std::isfinite(v)) {
        out += "null";
        return;
    }
    // nlohmann's own number text (what its dump() writes for a double).
    char buf[64];
    out.append(buf, nlohmann::detail::to_chars(buf, buf + sizeof buf, v));
}

void Text::string(std::string_view s) {
    static const char hex[] = "0123456789abcdef";
    bool plain = true;
    for (const char c : s)
        if (static_cast<unsigned char>(c) >= 0x80) plain = false;
    if (!plain) {
        // Not ASCII: nlohmann's dump itself (it checks the UTF-8, as the files' writer always did).
        out += nlohmann::json(std::string(s)).dump();
        return;
    }
    out += '"';
    for (const char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) {
                    out += "\\u00";
                    out += hex[static_cast<unsigned char>(c) >> 4];
                    out += hex[c & 0xf];
                } else {
                    out += c;
                }
        }
    }
    out += '"';
}

const char* attributeName(int a) {
    static const char* const names[kAttributes] = {"COLOR_0",  "NORMAL",         "POSITION",     "TEXCOORD_0", "TEXCOORD_1",
                                                   "_DOPPLER", "_EMISSION_TIME", "_PROPER_TIME"};
    return names[a];
}

namespace {

void attributes(Text* t, const std::array<int, kAttributes>& a) {
    t->open('{');
    for (int i = 0; i < kAttributes; ++i)
        if (a[size_t(i)] >= 0) {
            t->key(attributeName(i));
            t->value(a[size_t(i)]);
        }
    t->close('}');
}

void bounds(Text* t, const char* key, const Accessor& a, const double* v) {
    t->key(key);
    t->open('[');
    for (int i = 0; i < a.bounds; ++i) {
        if (a.component == kFloat || a.component == kDouble)
            t->value(v[i]);
        else
            t->value(static_cast<int>(v[i]));  // integer components: integer bounds
    }
    t->close(']');
}

void numbers(Text* t, const char* key, const double* v, int n) {
    t->key(key);
    t->open('[');
    for (int i = 0; i < n; ++i) t->value(v[i]);
    t->close(']');
}

}  // namespace

void write(Text* t, const Accessor& a) {
    t->open('{');
    if (a.view >= 0) {
        t->key("bufferView");
        t->value(a.view);
    }
    if (a.offset != 0) {
        t->key("byteOffset");
        t->value(a.offset);
    }
    t->key("componentType");
    t->value(a.component);
    t->key("count");
    t->value(a.count);
    if (a.bounds > 0) {
        bounds(t, "max", a, a.max);
        bounds(t, "min", a, a.min);
    }
    if (a.normalized) {
        t->key("normalized");
        t->value(true);
    }
    t->key("type");
    t->value(a.vec3 ? "VEC3" : a.vec2 ? "VEC2" : "SCALAR");
    t->close('}');
}

void write(Text* t, const BufferView& v) {
    t->open('{');
    t->key("buffer");
    t->value(v.buffer);
    t->key("byteLength");
    t->value(v.length);
    if (v.offset > 0) {
        t->key("byteOffset");
        t->value(v.offset);
    }
    if (v.stride >= 4) {
        t->key("byteStride");
        t->value(v.stride);
    }
    if (v.meshopt) {
        const BufferView::Meshopt& m = v.ext;
        t->key("extensions");
        t->open('{');
        t->key("EXT_meshopt_compression");
        t->open('{');
        t->key("buffer");
        t->value(0);
        t->key("byteLength");
        t->value(m.length);
        t->key("byteOffset");
        t->value(m.offset);
        t->key("byteStride");
        t->value(m.stride);
        t->key("count");
        t->value(m.count);
        if (m.octahedral) {
            t->key("filter");
            t->value("OCTAHEDRAL");
        }
        t->key("mode");
        t->value(m.indices ? "TRIANGLES" : "ATTRIBUTES");
        t->close('}');
        t->close('}');
    }
    if (v.target == 34962 || v.target == 34963) {
        t->key("target");
        t->value(v.target);
    }
    t->close('}');
}

void write(Text* t, const Mesh& m) {
    t->open('{');
    if (!m.name.empty()) {
        t->key("name");
        t->value(m.name);
    }
    t->key("primitives");
    t->open('[');
    for (const Primitive& p : m.primitives) {
        t->open('{');
        t->key("attributes");
        attributes(t, p.attributes);
        if (p.draco_view >= 0) {
            t->key("extensions");
            t->open('{');
            t->key("KHR_draco_mesh_compression");
            t->open('{');
            t->key("attributes");
            t->open('{');
            for (int i = 0; i < kAttributes; ++i)
                if (p.draco_ids[size_t(i)] >= 0) {
                    t->key(attributeName(i));
                    t->value(int64_t(p.draco_ids[size_t(i)]));
                }
            t->close('}');
            t->key("bufferView");
            t->value(p.draco_view);
            t->close('}');
            t->close('}');
        }
        if (p.indices >= 0) {
            t->key("indices");
            t->value(p.indices);
        }
        if (p.material >= 0) {
            t->key("material");
            t->value(p.material);
        }
        t->key("mode");
        t->value(4);  // TRIANGLES
        if (!p.targets.empty()) {
            t->key("targets");
            t->open('[');
            for (const auto& target : p.targets) attributes(t, target);
            t->close(']');
        }
        t->close('}');
    }
    t->close(']');
    t->close('}');
}

void write(Text* t, const Node& n) {
    t->open('{');
    if (n.camera >= 0) {
        t->key("camera");
        t->value(n.camera);
    }
    if (!n.children.empty()) {
        t->key("children");
        t->open('[');
        for (const int c : n.children) t->value(c);
        t->close(']');
    }
    if (n.has_mirror) {
        t->key("extras");
        t->open('{');
        t->key("mirror");
        t->value(n.mirror);
        t->close('}');
    }
    if (n.mesh >= 0) {
        t->key("mesh");
        t->value(n.mesh);
    }
    if (!n.name.empty()) {
        t->key("name");
        t->value(n.name);
    }
    if (n.has_rotation) numbers(t, "rotation", n.rotation, 4);
    if (n.has_scale) numbers(t, "scale", n.scale, 3);
    if (n.has_translation) numbers(t, "translation", n.translation, 3);
    if (!n.weights.empty()) {
        t->key("weights");
        t->open('[');
        for (const int w : n.weights) t->value(w);
        t->close(']');
    }
    t->close('}');
}

void moveTextureIndices(nlohmann::json* j, int offset) {
    for (auto& [key, value] : j->items()) {
        if (!value.is_object()) continue;
        if (key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0 && value.contains("index"))
            value["index"] = value["index"].get<int>() + offset;
        else
            moveTextureIndices(&value, offset);
    }
}

}  // namespace apparent::gltfjson
