// A .mtl library read into glTF materials (mtl_reader.h).
#include "pipeline/input/mtl_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>

#include <nlohmann/json.hpp>

#include "pipeline/input/text_scan.h"

namespace apparent {

namespace {

// The rest of the line, blanks trimmed at both ends.
std::string_view restOfLine(const char* p, const char* end) {
    while (p < end && isBlank(*p)) ++p;
    while (end > p && isBlank(end[-1])) --end;
    return std::string_view(p, size_t(end - p));
}

bool parseNumber(std::string_view token, double* out) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    double v = 0;
    const auto r = std::from_chars(token.data(), token.data() + token.size(), v);
    if (token.empty() || r.ec != std::errc() || r.ptr != token.data() + token.size() || !std::isfinite(v)) return false;
    *out = v;
    return true;
}

}  // namespace

Status parseMtl(const std::string& path, const std::string& text, std::vector<MtlMaterial>* materials,
                std::vector<std::string>* warnings) {
    materials->clear();
    std::set<std::string> unknown, names;
    std::string map_options, twice, not_utf8;
    bool skipping = false;  // inside a second definition of a name (the first is kept)
    size_t line_no = 0;
    const char* const end = text.data() + text.size();
    for (const char* at = text.data(); at < end;) {
        const char* eol = static_cast<const char*>(std::memchr(at, '\n', size_t(end - at)));
        if (!eol) eol = end;
        const char* p = at;
        at = eol + 1;
        ++line_no;
        const std::string_view key = nextToken(&p, eol);
        if (key.empty() || key[0] == '#') continue;
        auto fail = [&](const std::string& problem) {
            return Status::failure(path + ":" + std::to_string(line_no) + ": " + std::string(key) + ": " + problem);
        };
        if (key == "newmtl") {
            // The rest of the line (Blender writes "newmtl " and "usemtl " for no material: a name too).
            const std::string written(restOfLine(p, eol).substr(0, 256));
            const std::string name = utf8Replaced(written);
            if (name != written && not_utf8.empty()) not_utf8 = "line " + std::to_string(line_no);
            skipping = !names.insert(name).second;
            if (skipping) {
                if (twice.empty()) twice = "'" + name + "' (line " + std::to_string(line_no) + ")";
                continue;
            }
            materials->push_back({});
            materials->back().name = name;
            materials->back().line = line_no;
            continue;
        }
        if (skipping) continue;
        if (materials->empty()) {
            if (key == "Kd" || key == "d" || key == "Tr" || key == "Ke" || key == "Pr" || key == "Pm" || key == "Ns" ||
                key == "map_Kd")
                return fail("comes before any newmtl");
            unknown.insert(std::string(key.substr(0, 64)));
            continue;
        }
        MtlMaterial& m = materials->back();
        // Step: numbers, each checked against its range.
        std::vector<double> values;
        const char* const args = p;
        auto numbers = [&](size_t min_count, size_t max_count, const double lo, const double hi, const char* range) -> Status {
            values.clear();
            bool good = true;
            for (std::string_view tok = nextToken(&p, eol); !tok.empty() && good; tok = nextToken(&p, eol)) {
                double v = 0;
                good = parseNumber(tok, &v) && v >= lo && v <= hi;
                values.push_back(v);
            }
            if (!good || (values.size() != min_count && values.size() != max_count))
                return fail("expected " + std::to_string(min_count) +
                            (max_count > min_count ? " or " + std::to_string(max_count) : std::string()) +
                            (max_count > 1 ? " numbers " : " number ") + range + ", got '" +
                            std::string(restOfLine(args, eol).substr(0, 200)) + "'");
            return Status::success();
        };
        // One number is grey: r = g = b.
        auto colour = [&](std::array<double, 3>* rgb) { *rgb = {values[0], values[values.size() / 2], values.back()}; };
        const double kHuge = 3.0e38;
        if (key == "Kd") {
            if (Status s = numbers(1, 3, 0, 1, "in [0, 1]"); !s.ok) return s;
            colour(&m.diffuse);
        } else if (key == "Ke") {
            if (Status s = numbers(1, 3, 0, kHuge, ">= 0"); !s.ok) return s;
            colour(&m.emissive);
        } else if (key == "d" || key == "Tr") {
            // "d -halo a" (a halo's fall-off) has no glTF counterpart: its factor is read as the alpha.
            const char* q = p;
            if (nextToken(&q, eol) == "-halo") p = q;
            if (Status s = numbers(1, 1, 0, 1, "in [0, 1]"); !s.ok) return s;
            m.alpha = key == "d" ? values[0] : 1 - values[0];
        } else if (key == "Pr" || key == "Pm") {
            if (Status s = numbers(1, 1, 0, 1, "in [0, 1]"); !s.ok) return s;
            (key == "Pr" ? m.roughness : m.metallic) = values[0];
            if (key == "Pr") m.roughness_given = true;
        } else if (key == "Ns") {
            if (Status s = numbers(1, 1, 0, kHuge, ">= 0"); !s.ok) return s;
            if (!m.roughness_given) m.roughness = 1 - std::sqrt(std::min(values[0], 900.0)) / 30;
        } else if (key == "map_Kd") {
            // Step: options ("-s 1 1 1 ...") are not read; the file is the last token.
            std::string_view last, tok;
            bool options = false;
            for (tok = nextToken(&p, eol); !tok.empty(); tok = nextToken(&p, eol)) {
                if (tok[0] == '-') options = true;
                last = tok;
            }
            if (last.empty()) return fail("names no file");
            if (options && map_options.empty()) map_options = "line " + std::to_string(line_no);
            m.diffuse_map = std::string(last.substr(0, 4096));
            std::replace(m.diffuse_map.begin(), m.diffuse_map.end(), '\\', '/');
        } else {
            unknown.insert(std::string(key.substr(0, 64)));
        }
    }
    // Step: what was not read, said once each.
    if (!unknown.empty()) {
        std::string list;
        size_t shown = 0;
        for (const std::string& k : unknown) {
            if (shown++ == 20) {
                list += ", ... (" + std::to_string(unknown.size() - 20) + " more)";
                break;
            }
            list += (list.empty() ? "" : ", ") + k;
        }
        warnings->push_back(path + ": keywords not read (no glTF counterpart here): " + list);
    }
    if (!map_options.empty())
        warnings->push_back(path + ": map_Kd options ignored (" + map_options + "): the texture is used as it is, repeated");
    if (!not_utf8.empty())
        warnings->push_back(path + ": material names that are not UTF-8 (first at " + not_utf8 +
                            "): their bad bytes read as U+FFFD (usemtl names are read so too)");
    if (!twice.empty()) warnings->push_back(path + ": material " + twice + " defined again: the first definition is kept");
    return Status::success();
}

std::string utf8Replaced(const std::string& text) {
    using json = nlohmann::json;
    return json::parse(json(text).dump(-1, ' ', false, json::error_handler_t::replace)).get<std::string>();
}

std::string mtlMaterialJson(const MtlMaterial& m, int texture, std::vector<std::string>* extensions) {
    using json = nlohmann::json;
    json pbr = {{"baseColorFactor", {m.diffuse[0], m.diffuse[1], m.diffuse[2], m.alpha}},
                {"metallicFactor", m.metallic},
                {"roughnessFactor", m.roughness}};
    if (texture >= 0) pbr["baseColorTexture"] = {{"index", texture}};
    json mat = {{"doubleSided", true}, {"pbrMetallicRoughness", pbr}};
    if (!m.name.empty()) mat["name"] = m.name;
    // Step: emission; glTF's factor stops at 1, the rest is KHR_materials_emissive_strength.
    const double strongest = std::max({m.emissive[0], m.emissive[1], m.emissive[2]});
    if (strongest > 0) {
        const double s = std::max(strongest, 1.0);
        mat["emissiveFactor"] = {m.emissive[0] / s, m.emissive[1] / s, m.emissive[2] / s};
        if (s > 1) {
            mat["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", s}}}};
            const std::string ext = "KHR_materials_emissive_strength";
            if (std::find(extensions->begin(), extensions->end(), ext) == extensions->end()) extensions->push_back(ext);
        }
    }
    if (m.alpha < 1) mat["alphaMode"] = "BLEND";
    return mat.dump();
}

}  // namespace apparent
