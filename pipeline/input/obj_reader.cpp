#include "pipeline/input/obj_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>

#include "pipeline/input/input_file.h"
#include "pipeline/input/polygon_input.h"

namespace apparent {

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// The next whitespace-separated token of [*p, end), advancing *p past it; empty at the line's end.
std::string_view nextToken(const char** p, const char* end) {
    const char* s = *p;
    while (s < end && isBlank(*s)) ++s;
    const char* e = s;
    while (e < end && !isBlank(*e)) ++e;
    *p = e;
    return std::string_view(s, size_t(e - s));
}

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

// Reads `text` line by line into `scan`, checking everything as it goes.
Status scanObj(const std::string& path, const std::string& text, const MeshLimits& limits, ScannedMesh* scan,
               MeshWarnings* warnings) {
    size_t mtllibs = 0, line_no = 0, faces = 0, texcoords = 0;
    std::set<std::string> materials;  // usemtl names
    std::vector<uint32_t> idx, sorted;
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
            const long n = long(positions.size());
            for (std::string_view tok = nextToken(&p, eol); !tok.empty(); tok = nextToken(&p, eol)) {
                long i = 0;
                if (!parseIndex(tok, &i)) return fail("f: bad vertex index '" + std::string(tok) + "'");
                const long resolved = i > 0 ? i : n + 1 + i;
                if (resolved < 1 || resolved > n)
                    return fail("f: vertex index " + std::to_string(i) + " is out of range (valid 1.." + std::to_string(n) +
                                " so far, or -1..-" + std::to_string(n) + ")");
                idx.push_back(uint32_t(resolved - 1));
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
            for (size_t k = 1; k + 1 < idx.size(); ++k) triangles.push_back({idx[0], idx[k], idx[k + 1]});
        } else if (key == "mtllib") {
            ++mtllibs;
        } else if (key == "usemtl") {
            const std::string_view name = nextToken(&p, eol);
            materials.insert(std::string(name.substr(0, std::min<size_t>(name.size(), 256))));
        } else if (key == "vt") {
            ++texcoords;
        }
    }
    if (mtllibs)
        warnings->other.push_back(std::to_string(mtllibs) + " mtllib lines ignored (material libraries are not read)");
    if (!materials.empty())
        warnings->other.push_back(std::to_string(materials.size()) +
                                  " usemtl materials not kept: the object has one colour (give it a colour or material "
                                  "in the scene, or convert the file to glTF, whose materials are kept)");
    if (texcoords)
        warnings->other.push_back(std::to_string(texcoords) + " vt texture coordinates not kept (glTF's TEXCOORD_0 are)");
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

}  // namespace

Status readObj(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings) {
    std::string text;
    if (Status s = readRegularFile(path, limits.max_file_bytes, &text, "mesh file"); !s.ok) return s;
    ScannedMesh scan;
    if (Status s = scanObj(path, text, limits, &scan, warnings); !s.ok) return s;
    std::string().swap(text);  // the text is no longer needed: give its memory back before the mesh grows
    return finishScannedMesh(std::move(scan), path, mesh, warnings);
}

}  // namespace apparent
