#include "pipeline/input/obj_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "pipeline/input/input_file.h"
#include "pipeline/input/look_files.h"
#include "pipeline/input/mtl_reader.h"
#include "pipeline/input/polygon_input.h"
#include "pipeline/input/text_scan.h"

namespace apparent {

namespace {

// A coordinate: the whole token a finite number within float range (the exports are float32).
bool parseCoordinate(std::string_view token, double* out) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    double v = 0;
    const auto r = std::from_chars(token.data(), token.data() + token.size(), v);
    if (r.ec != std::errc() || r.ptr != token.data() + token.size() || !std::isfinite(v) || std::fabs(v) > 3.0e38)
        return false;
    *out = v;
    return true;
}

// A face corner's position index: the integer before the first '/'.
bool parseIndex(std::string_view token, long* out) {
    std::string_view head = token.substr(0, token.find('/'));
    if (head.size() > 1 && head[0] == '+' && head[1] != '-') head.remove_prefix(1);
    const auto r = std::from_chars(head.data(), head.data() + head.size(), *out);
    return !head.empty() && r.ec == std::errc() && r.ptr == head.data() + head.size() && *out != 0;
}

// A face corner's texture coordinate index: the integer between the first and the second '/'
// (0: none, as in "i" and "i//n"; false: not an integer).
bool parseTexIndex(std::string_view token, long* out) {
    *out = 0;
    const size_t slash = token.find('/');
    if (slash == std::string_view::npos) return true;
    std::string_view t = token.substr(slash + 1);
    t = t.substr(0, t.find('/'));
    if (t.empty()) return true;
    if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.remove_prefix(1);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), *out);
    return r.ec == std::errc() && r.ptr == t.data() + t.size() && *out != 0;
}

// What the scanner gathers for the look, beside the mesh.
struct ObjLookParts {
    std::vector<double> uv;                          // vt: u, v (file order)
    std::vector<std::array<uint32_t, 3>> corner_uv;  // per scanned triangle (kNoTexcoord: none); empty: no corner has one
    std::vector<int> usemtl;                         // per scanned triangle: index into `names` (-1: none); empty: no usemtl
    std::vector<std::string> names;                  // usemtl names in first-use order
    std::vector<std::pair<std::string, size_t>> libraries;  // mtllib file names as written, and their line
    size_t mtllib_lines = 0;
    std::string bad_uv;  // the first corner whose vt index is malformed or out of range
};

// Reads `text` line by line into `scan` and `parts`, checking everything as it goes.
Status scanObj(const std::string& path, const std::string& text, const MeshLimits& limits, ScannedMesh* scan,
               ObjLookParts* parts, MeshWarnings* warnings) {
    size_t line_no = 0, faces = 0;
    int current = -1;         // the usemtl in force (index into parts->names)
    bool corners_uv = false;  // a corner had a texture coordinate: parts->corner_uv is kept from then on
    std::map<std::string, int> name_index;
    std::vector<uint32_t> idx, sorted, tex;
    // UTF-16 (a byte-order mark, or NUL bytes among the first characters, as Windows tools write
    // it): every line would read as garbage and the file as "no vertices".
    const size_t prefix = std::min<size_t>(text.size(), 64);
    if ((text.size() >= 2 && (((unsigned char)text[0] == 0xFF && (unsigned char)text[1] == 0xFE) ||
                              ((unsigned char)text[0] == 0xFE && (unsigned char)text[1] == 0xFF))) ||
        text.find('\0') < prefix)
        return Status::failure(path + ": UTF-16 text; save as UTF-8 (OBJ is read as ASCII / UTF-8)");
    size_t face_no = 0;        // 'f' lines so far
    std::string first_repeat;  // "face 3 repeats vertex 7 (line 12)": the first face dropped for it
    const char* const begin = text.data();
    const char* const end = begin + text.size();
    auto& positions = scan->mesh.positions;
    auto& triangles = scan->mesh.triangles;
    for (const char* at = begin; at < end;) {
        const char* eol = static_cast<const char*>(std::memchr(at, '\n', size_t(end - at)));
        if (!eol) eol = end;
        const char* p = at;
        const char* const line_begin = at;
        at = eol + 1;
        ++line_no;
        auto fail = [&](const std::string& problem) {
            return Status::failure(path + ":" + std::to_string(line_no) + ": " + problem);
        };
        auto line = [&] {
            std::string l(line_begin, size_t(eol - line_begin));
            if (!l.empty() && l.back() == '\r') l.pop_back();
            return l;
        };
        const std::string_view key = nextToken(&p, eol);
        if (key.empty() || key[0] == '#') continue;
        if (key == "v") {
            mesh4d::Vec3 q;
            double* xyz[3] = {&q.x, &q.y, &q.z};
            for (double* c : xyz)
                if (!parseCoordinate(nextToken(&p, eol), c))
                    return fail("v: expected 3 finite numbers within float range (|x| <= 3e38), got '" + line() + "'");
            if (positions.size() >= limits.max_vertices)
                return fail("v: more than " + std::to_string(limits.max_vertices) + " vertices (raise with --max-vertices)");
            positions.push_back(q);
        } else if (key == "f") {
            idx.clear();
            tex.clear();
            const long n = long(positions.size());
            for (std::string_view tok = nextToken(&p, eol); !tok.empty(); tok = nextToken(&p, eol)) {
                long i = 0;
                if (!parseIndex(tok, &i)) return fail("f: bad vertex index '" + std::string(tok) + "'");
                const long resolved = i > 0 ? i : n + 1 + i;
                if (resolved < 1 || resolved > n)
                    return fail("f: vertex index " + std::to_string(i) + " is out of range (valid 1.." + std::to_string(n) +
                                " so far, or -1..-" + std::to_string(n) + ")");
                idx.push_back(uint32_t(resolved - 1));
                // The texture coordinate: checked against the vt lines so far, an error only if kept.
                long t = 0;
                const long nt = long(parts->uv.size() / 2);
                const bool good = parseTexIndex(tok, &t);
                const long rt = t > 0 ? t : nt + 1 + t;
                if (good && t != 0 && rt >= 1 && rt <= nt) tex.push_back(uint32_t(rt - 1));
                else tex.push_back(kNoTexcoord);
                if ((!good || (t != 0 && (rt < 1 || rt > nt))) && parts->bad_uv.empty())
                    parts->bad_uv = path + ":" + std::to_string(line_no) + ": f: texture coordinate index in '" +
                                    std::string(tok) + "' is " + (good ? "out of range (" + std::to_string(nt) + " vt so far)" : "malformed");
            }
            ++face_no;
            if (idx.size() < 3) return fail("f: a face needs at least 3 vertices, got " + std::to_string(idx.size()));
            sorted.assign(idx.begin(), idx.end());
            std::sort(sorted.begin(), sorted.end());
            if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
                ++scan->repeated_index;  // dropped (as OpenMesh does) and counted as degenerate
                if (first_repeat.empty()) {
                    // The first corner whose vertex an earlier corner of the face already used.
                    uint32_t repeated = 0;
                    for (size_t a = 1; a < idx.size() && !repeated; ++a)
                        for (size_t b = 0; b < a; ++b)
                            if (idx[a] == idx[b]) { repeated = idx[a] + 1; break; }
                    first_repeat = "face " + std::to_string(face_no) + " repeats vertex " + std::to_string(repeated) +
                                   " (line " + std::to_string(line_no) + ")";
                }
                continue;
            }
            if (++faces > limits.max_faces)
                return fail("f: more than " + std::to_string(limits.max_faces) + " faces (raise with --max-faces)");
            if (idx.size() > 3) scan->polygons.emplace_back(uint32_t(triangles.size()), uint32_t(idx.size()));
            const bool any_uv = std::any_of(tex.begin(), tex.end(), [](uint32_t t) { return t != kNoTexcoord; });
            if (any_uv && !corners_uv) {
                corners_uv = true;
                parts->corner_uv.assign(triangles.size(), {kNoTexcoord, kNoTexcoord, kNoTexcoord});
            }
            for (size_t k = 1; k + 1 < idx.size(); ++k) {
                triangles.push_back({idx[0], idx[k], idx[k + 1]});
                if (current >= 0 || !parts->usemtl.empty()) parts->usemtl.push_back(current);
                if (corners_uv) parts->corner_uv.push_back({tex[0], tex[k], tex[k + 1]});
            }
        } else if (key == "mtllib") {
            // Step: library names (OBJ separates them by blanks).
            ++parts->mtllib_lines;
            for (std::string_view tok = nextToken(&p, eol); !tok.empty(); tok = nextToken(&p, eol))
                if (parts->libraries.size() < 64) parts->libraries.emplace_back(std::string(tok.substr(0, 4096)), line_no);
        } else if (key == "usemtl") {
            // The rest of the line is the name (.mtl names may hold blanks: newmtl reads them so too).
            while (p < eol && isBlank(*p)) ++p;
            const char* e = eol;
            while (e > p && isBlank(e[-1])) --e;
            const std::string name = utf8Replaced(std::string(p, std::min<size_t>(size_t(e - p), 256)));
            auto [it, fresh] = name_index.try_emplace(name, int(parts->names.size()));
            if (fresh) parts->names.push_back(name);
            current = it->second;
            if (parts->usemtl.empty()) parts->usemtl.assign(triangles.size(), -1);  // kept from the first usemtl on
        } else if (key == "vt") {
            // u [v [w]]: v defaults to 0, w is not used.
            double uv[2] = {0, 0};
            std::string_view tok = nextToken(&p, eol);
            for (int c = 0; c < 2 && (c == 0 || !tok.empty()); ++c, tok = nextToken(&p, eol))
                if (!parseCoordinate(tok, &uv[c]))
                    return fail("vt: expected 1 to 3 finite numbers within float range (|x| <= 3e38), got '" + line() + "'");
            if (parts->uv.size() / 2 >= limits.max_vertices)
                return fail("vt: more than " + std::to_string(limits.max_vertices) + " texture coordinates (raise with --max-vertices)");
            parts->uv.insert(parts->uv.end(), {uv[0], uv[1]});
        }
    }
    if (positions.empty()) return Status::failure(path + ": no vertices ('v' lines)");
    if (faces == 0)
        return Status::failure(path + ": no usable faces ('f' lines)" +
                               (first_repeat.empty() ? std::string()
                                                     : ": " + first_repeat +
                                                           (scan->repeated_index > 1
                                                                ? " (and " + std::to_string(scan->repeated_index - 1) +
                                                                      " more faces repeat a vertex)"
                                                                : std::string())));
    if (!first_repeat.empty()) warnings->other.push_back(first_repeat + ": dropped (a face may use a vertex once)");
    return Status::success();
}

// The look of a scanned OBJ (obj_reader.h): its libraries read, its materials in first-use order,
// their textures, and its texture coordinates with the vertices split where a position has two.
// Null when no face's usemtl names a material the libraries define.
Status buildObjLook(const std::string& path, const MeshLimits& limits, ObjLookParts& parts, ScannedMesh* scan,
                    MeshWarnings* warnings, std::shared_ptr<SurfaceLook>* out) {
    out->reset();
    const size_t vt_count = parts.uv.size() / 2;
    auto notKept = [&] {
        if (vt_count) warnings->other.push_back(std::to_string(vt_count) + " vt texture coordinates not kept (no material uses them)");
    };
    if (parts.names.empty()) {
        if (parts.mtllib_lines)
            warnings->other.push_back(std::to_string(parts.mtllib_lines) + " mtllib lines not read (no face has a usemtl)");
        notKept();
        return Status::success();
    }
    // Step: the libraries, each read once; a name's first definition wins.
    const LookFolders folders(path, limits);
    struct Found {
        MtlMaterial material;
        std::string library;
    };
    std::map<std::string, Found> defined;
    std::set<std::string> seen;
    for (const auto& [name, line] : parts.libraries) {
        const std::string file = besideFile(path, name);
        if (!seen.insert(file).second) continue;
        std::string text;
        bool read = false;
        const std::string where = "line " + std::to_string(line) + ": mtllib";
        if (Status s = readConfined(where, "material library", file, folders, limits, warnings, &text, &read); !s.ok)
            return s;
        if (!read) continue;
        std::vector<MtlMaterial> materials;
        if (Status s = parseMtl(file, text, &materials, &warnings->other); !s.ok) return s;
        for (MtlMaterial& m : materials) {
            const std::string material_name = m.name;
            defined.try_emplace(material_name, Found{std::move(m), file});
        }
    }
    if (parts.libraries.empty()) warnings->other.push_back("usemtl without an mtllib line: no material library to read");
    // Step: the names no library defines: their faces keep the default look.
    std::vector<const Found*> by_name(parts.names.size(), nullptr);
    std::string missing;
    size_t missing_count = 0;
    for (size_t n = 0; n < parts.names.size(); ++n) {
        auto it = defined.find(parts.names[n]);
        if (it != defined.end()) by_name[n] = &it->second;
        else if (++missing_count <= 5) missing += (missing.empty() ? "'" : ", '") + parts.names[n] + "'";
    }
    if (std::all_of(by_name.begin(), by_name.end(), [](const Found* f) { return !f; })) {
        warnings->other.push_back(std::to_string(parts.names.size()) +
                                  " usemtl materials not kept (no library defines them): the object has one colour");
        notKept();
        return Status::success();
    }
    if (missing_count)
        warnings->other.push_back(std::to_string(missing_count) + " usemtl materials not in the libraries (" + missing +
                                  (missing_count > 5 ? ", ..." : "") + "): their faces get a white material");
    auto look = std::make_shared<SurfaceLook>();
    // Step: the materials in first-use order (-1: faces without one), each texture's image read once.
    std::map<int, uint32_t> out_index;
    std::map<std::string, int> texture_of_file;
    auto texture = [&](const Found& f, int* index) -> Status {
        *index = -1;
        if (f.material.diffuse_map.empty()) return Status::success();
        const std::string file = besideFile(f.library, f.material.diffuse_map);
        if (auto it = texture_of_file.find(file); it != texture_of_file.end()) {
            *index = it->second;
            return Status::success();
        }
        texture_of_file[file] = -1;
        std::string bytes;
        bool read = false;
        const std::string where = f.library + ": material '" + f.material.name + "' (line " + std::to_string(f.material.line) + "): map_Kd";
        if (Status s = readConfined(where, "texture", file, folders, limits, warnings, &bytes, &read); !s.ok || !read) return s;
        const std::string type = sniffImage(bytes);
        if (type.empty()) {
            warnings->other.push_back(where + ": " + file + " is not PNG or JPEG (the texture is dropped)");
            return Status::success();
        }
        if (look->samplers.empty()) look->samplers.push_back(R"({"wrapS":10497,"wrapT":10497})");  // REPEAT
        look->images.push_back({type, utf8Replaced(std::filesystem::path(file).filename().string()), std::vector<unsigned char>(bytes.begin(), bytes.end())});
        *index = texture_of_file[file] = int(look->textures.size());
        look->textures.push_back(R"({"sampler":0,"source":)" + std::to_string(look->images.size() - 1) + "}");
        return Status::success();
    };
    std::vector<uint32_t> material_of(scan->mesh.triangles.size());
    for (size_t t = 0; t < material_of.size(); ++t) {
        const int n = parts.usemtl[t];
        const int key = n >= 0 && by_name[size_t(n)] ? n : -1;
        auto [it, fresh] = out_index.try_emplace(key, uint32_t(look->materials.size()));
        if (fresh) {
            if (key < 0) {
                look->materials.push_back(mtlMaterialJson(MtlMaterial{}, -1, &look->extensions));  // no fields, no name
            } else {
                int tex = -1;
                if (Status s = texture(*by_name[size_t(key)], &tex); !s.ok) return s;
                look->materials.push_back(mtlMaterialJson(by_name[size_t(key)]->material, tex, &look->extensions));
            }
        }
        material_of[t] = it->second;
    }
    look->triangle_material = std::move(material_of);
    // Step: the texture coordinates, a position given a vertex per distinct vt it has (glTF's v axis
    // points down: TEXCOORD_0 = (u, 1 - v)); corners without one get (0, 0).
    if (!parts.bad_uv.empty()) {
        if (vt_count) return Status::failure(parts.bad_uv);
        warnings->other.push_back("face corners name texture coordinates but the file has no vt lines: none kept");
    }
    if (!parts.corner_uv.empty()) {
        std::vector<uint32_t> copied_from;
        if (Status st = splitAtTextureSeams(path, limits, parts.uv, &parts.corner_uv, scan, &look->texcoord, &copied_from); !st.ok)
            return st;
        if (!copied_from.empty())
            warnings->other.push_back(std::to_string(copied_from.size()) +
                                      " vertices copied at texture seams (a position with more than one vt)");
    } else if (vt_count) {
        warnings->other.push_back(std::to_string(vt_count) + " vt texture coordinates not kept (no face corner uses one)");
    }
    *out = std::move(look);
    return Status::success();
}

}  // namespace

Status readObj(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
               std::shared_ptr<const SurfaceLook>* look_out) {
    if (look_out) look_out->reset();
    std::string text;
    if (Status s = readRegularFile(path, limits.max_file_bytes, &text, "mesh file"); !s.ok) return s;
    ScannedMesh scan;
    ObjLookParts parts;
    if (Status s = scanObj(path, text, limits, &scan, &parts, warnings); !s.ok) return s;
    std::string().swap(text);  // the text is no longer needed: give its memory back before the mesh grows
    std::shared_ptr<SurfaceLook> look;
    if (look_out) {
        if (Status s = buildObjLook(path, limits, parts, &scan, warnings, &look); !s.ok) {
            // A library's or an image's own message ("m.mtl:2: Kd: ..."), after the mesh it serves.
            if (s.message.rfind(path, 0) != 0) s.message = path + ": " + s.message;
            return s;
        }
    } else {
        if (parts.mtllib_lines)
            warnings->other.push_back(std::to_string(parts.mtllib_lines) + " mtllib lines ignored (material libraries are not read)");
        if (!parts.names.empty())
            warnings->other.push_back(std::to_string(parts.names.size()) + " usemtl materials not kept: the object has one colour");
        if (!parts.uv.empty()) warnings->other.push_back(std::to_string(parts.uv.size() / 2) + " vt texture coordinates not kept");
    }
    if (!look) return finishScannedMesh(std::move(scan), path, mesh, warnings);
    // Step: the mesh made as for any OBJ, the look following its triangles and the vertices
    // OpenMesh copies (a copy takes its original's attributes: found by its triangle's corners).
    std::vector<int> origin;
    std::vector<uint32_t> vertex_origin;
    if (Status s = finishScannedMeshTraced(std::move(scan), path, mesh, warnings, &origin, &vertex_origin); !s.ok) return s;
    std::vector<uint32_t> triangle_material(mesh->triangles.size());
    for (size_t t = 0; t < triangle_material.size(); ++t) triangle_material[t] = look->triangle_material[size_t(origin[t])];
    look->triangle_material = std::move(triangle_material);
    if (!look->texcoord.empty()) {
        std::vector<double> texcoord(2 * mesh->positions.size());
        for (size_t v = 0; v < mesh->positions.size(); ++v)
            if (vertex_origin[v] != kNoOrigin)
                for (int k = 0; k < 2; ++k) texcoord[2 * v + size_t(k)] = look->texcoord[2 * size_t(vertex_origin[v]) + size_t(k)];
        look->texcoord = std::move(texcoord);
    }
    *look_out = std::move(look);
    return Status::success();
}

}  // namespace apparent
