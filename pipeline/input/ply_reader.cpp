#include "pipeline/input/ply_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <sstream>
#include <string_view>

#include "pipeline/input/input_file.h"
#include "pipeline/input/look_files.h"
#include "pipeline/input/mtl_reader.h"
#include "pipeline/input/polygon_input.h"

namespace apparent {

namespace {


enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };
enum class ScalarType { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

// The names of PLY 1.0 and the sized names most writers use (both are accepted).
bool parseType(const std::string& s, ScalarType* t) {
    static const std::pair<const char*, ScalarType> names[] = {
        {"char", ScalarType::Int8},     {"int8", ScalarType::Int8},       {"uchar", ScalarType::Uint8},
        {"uint8", ScalarType::Uint8},   {"short", ScalarType::Int16},     {"int16", ScalarType::Int16},
        {"ushort", ScalarType::Uint16}, {"uint16", ScalarType::Uint16},   {"int", ScalarType::Int32},
        {"int32", ScalarType::Int32},   {"uint", ScalarType::Uint32},     {"uint32", ScalarType::Uint32},
        {"float", ScalarType::Float32}, {"float32", ScalarType::Float32}, {"double", ScalarType::Float64},
        {"float64", ScalarType::Float64}};
    for (const auto& [name, type] : names)
        if (s == name) {
            *t = type;
            return true;
        }
    return false;
}

size_t typeSize(ScalarType t) {
    switch (t) {
        case ScalarType::Int8: case ScalarType::Uint8: return 1;
        case ScalarType::Int16: case ScalarType::Uint16: return 2;
        case ScalarType::Int32: case ScalarType::Uint32: case ScalarType::Float32: return 4;
        case ScalarType::Float64: return 8;
    }
    return 1;
}

bool isIntegral(ScalarType t) { return t != ScalarType::Float32 && t != ScalarType::Float64; }

// Range of an integral type, to refuse ascii values that would wrap in their declared type.
void integralRange(ScalarType t, double* lo, double* hi) {
    switch (t) {
        case ScalarType::Int8: *lo = -128; *hi = 127; return;
        case ScalarType::Uint8: *lo = 0; *hi = 255; return;
        case ScalarType::Int16: *lo = -32768; *hi = 32767; return;
        case ScalarType::Uint16: *lo = 0; *hi = 65535; return;
        case ScalarType::Int32: *lo = -2147483648.0; *hi = 2147483647.0; return;
        default: *lo = 0; *hi = 4294967295.0; return;
    }
}

struct PlyProperty {
    std::string name;
    ScalarType type = ScalarType::Float32;  // the item type for a list
    bool list = false;
    ScalarType count_type = ScalarType::Uint8;
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> props;
};

struct PlyHeader {
    PlyFormat format = PlyFormat::Ascii;
    std::vector<PlyElement> elements;
    size_t body_offset = 0;
    std::vector<std::pair<std::string, size_t>> texture_files;  // `comment TextureFile NAME`: NAME and its line
};

std::vector<std::string> splitWords(const std::string& line) {
    std::istringstream ls(line);
    std::vector<std::string> words;
    std::string w;
    while (ls >> w) words.push_back(w);
    return words;
}

// Parses the header lines up to `end_header`.
bool parseHeader(const std::string& bytes, PlyHeader* h, std::string* problem) {
    size_t pos = 0, line_no = 0;
    bool has_format = false;
    for (;;) {
        const void* nl = pos < bytes.size() ? std::memchr(bytes.data() + pos, '\n', bytes.size() - pos) : nullptr;
        if (!nl) {
            *problem = line_no == 0 ? "header: not a PLY file (no 'ply' line)" : "header: no 'end_header' line";
            return false;
        }
        const size_t next = size_t(static_cast<const char*>(nl) - bytes.data()) + 1;
        std::string line(bytes.data() + pos, next - 1 - pos);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        pos = next;
        ++line_no;
        const std::string where = "header line " + std::to_string(line_no);
        if (line_no == 1) {
            if (line != "ply") {
                *problem = "header: not a PLY file (the first line is not 'ply')";
                return false;
            }
            continue;
        }
        const std::vector<std::string> w = splitWords(line);
        if (w.empty()) continue;
        if (w[0] == "comment" && w.size() >= 3 && w[1] == "TextureFile") {
            // The name is the rest of the line (it may hold blanks).
            const size_t at = line.find("TextureFile") + std::strlen("TextureFile");
            const size_t first = line.find_first_not_of(" \t", at), last = line.find_last_not_of(" \t");
            h->texture_files.emplace_back(line.substr(first, last + 1 - first), line_no);
            continue;
        }
        if (w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "end_header") {
            if (!has_format) {
                *problem = "header: no 'format' line";
                return false;
            }
            h->body_offset = pos;
            return true;
        }
        if (w[0] == "format") {
            if (has_format || w.size() != 3 || w[2] != "1.0") {
                *problem = where + ": format: expected one 'format ascii|binary_little_endian|binary_big_endian 1.0'";
                return false;
            }
            if (w[1] == "ascii") h->format = PlyFormat::Ascii;
            else if (w[1] == "binary_little_endian") h->format = PlyFormat::BinaryLittle;
            else if (w[1] == "binary_big_endian") h->format = PlyFormat::BinaryBig;
            else {
                *problem = where + ": format: unknown format '" + w[1] + "' (ascii, binary_little_endian, binary_big_endian)";
                return false;
            }
            has_format = true;
        } else if (w[0] == "element") {
            char* end = nullptr;
            errno = 0;
            const unsigned long long n = w.size() == 3 && !w[2].empty() && std::isdigit((unsigned char)w[2][0])
                                             ? std::strtoull(w[2].c_str(), &end, 10)
                                             : 0;
            if (w.size() != 3 || !end || *end != '\0' || errno == ERANGE) {
                *problem = where + ": element: expected 'element NAME COUNT' with a non-negative integer COUNT";
                return false;
            }
            for (const PlyElement& e : h->elements)
                if (e.name == w[1]) {
                    *problem = where + ": element " + w[1] + ": defined twice";
                    return false;
                }
            h->elements.push_back({w[1], uint64_t(n), {}});
        } else if (w[0] == "property") {
            if (h->elements.empty()) {
                *problem = where + ": property: before any 'element' line";
                return false;
            }
            PlyProperty p;
            bool ok;
            if (w.size() >= 2 && w[1] == "list") {
                ok = w.size() == 5 && parseType(w[2], &p.count_type) && isIntegral(p.count_type) && parseType(w[3], &p.type);
                p.list = true;
                if (ok) p.name = w[4];
            } else {
                ok = w.size() == 3 && parseType(w[1], &p.type);
                if (ok) p.name = w[2];
            }
            if (!ok) {
                *problem = where + ": property: expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME' "
                                   "(integer COUNT_TYPE; types char uchar short ushort int uint float double or int8 ... float64)";
                return false;
            }
            for (const PlyProperty& q : h->elements.back().props)
                if (q.name == p.name) {
                    *problem = where + ": property " + p.name + ": defined twice in element " + h->elements.back().name;
                    return false;
                }
            h->elements.back().props.push_back(p);
        } else {
            *problem = where + ": unknown keyword '" + w[0] + "'";
            return false;
        }
    }
}

// Reads the values of the body, ascii or binary, one at a time.
class BodyCursor {
public:
    BodyCursor(const std::string& bytes, size_t offset, PlyFormat format)
        : p_(bytes.data() + offset), end_(bytes.data() + bytes.size()), format_(format) {}

    size_t remaining() const { return size_t(end_ - p_); }

    // Reads one value of type t into *v. Returns false with a problem when the file ends or the value is malformed.
    bool read(ScalarType t, double* v, std::string* problem) {
        if (format_ == PlyFormat::Ascii) return readAscii(t, v, problem);
        const size_t n = typeSize(t);
        if (remaining() < n) {
            *problem = "the file ends early";
            return false;
        }
        unsigned char b[8];
        std::memcpy(b, p_, n);
        p_ += n;
        const bool little_host = [] {
            const uint16_t one = 1;
            unsigned char c;
            std::memcpy(&c, &one, 1);
            return c == 1;
        }();
        if ((format_ == PlyFormat::BinaryLittle) != little_host)
            for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
        switch (t) {
            case ScalarType::Int8: { int8_t x; std::memcpy(&x, b, 1); *v = x; break; }
            case ScalarType::Uint8: { uint8_t x; std::memcpy(&x, b, 1); *v = x; break; }
            case ScalarType::Int16: { int16_t x; std::memcpy(&x, b, 2); *v = x; break; }
            case ScalarType::Uint16: { uint16_t x; std::memcpy(&x, b, 2); *v = x; break; }
            case ScalarType::Int32: { int32_t x; std::memcpy(&x, b, 4); *v = x; break; }
            case ScalarType::Uint32: { uint32_t x; std::memcpy(&x, b, 4); *v = x; break; }
            case ScalarType::Float32: { float x; std::memcpy(&x, b, 4); *v = x; break; }
            case ScalarType::Float64: { double x; std::memcpy(&x, b, 8); *v = x; break; }
        }
        return true;
    }

private:
    bool readAscii(ScalarType t, double* v, std::string* problem) {
        while (p_ < end_ && std::isspace((unsigned char)*p_)) ++p_;
        const char* start = p_;
        while (p_ < end_ && !std::isspace((unsigned char)*p_)) ++p_;
        if (p_ == start) {
            *problem = "the file ends early";
            return false;
        }
        std::string_view token(start, size_t(p_ - start));
        if (token.size() > 64) {
            *problem = "value too long";
            return false;
        }
        const std::string_view shown = token;
        if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
        const char* const token_end = token.data() + token.size();
        if (isIntegral(t)) {
            long long x = 0;
            const auto r = std::from_chars(token.data(), token_end, x);
            double lo, hi;
            integralRange(t, &lo, &hi);
            if (r.ec != std::errc() || r.ptr != token_end || double(x) < lo || double(x) > hi) {
                *problem = "'" + std::string(shown) + "' is not an integer in [" + std::to_string((long long)lo) + ", " +
                           std::to_string((long long)hi) + "]";
                return false;
            }
            *v = double(x);
        } else {
            double x = 0;
            const auto r = std::from_chars(token.data(), token_end, x);
            if (r.ec != std::errc() || r.ptr != token_end || !std::isfinite(x) ||
                (t == ScalarType::Float32 && std::fabs(x) > 3.4e38)) {
                *problem = "'" + std::string(shown) + "' is not a finite number";
                return false;
            }
            *v = x;
        }
        return true;
    }
    const char* p_;
    const char* end_;
    PlyFormat format_;
};

// The sRGB-encoded value s in [0, 1] made linear (ply_reader.h, IEC 61966-2-1).
double srgbToLinear(double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); }

// A value as a message shows it.
std::string shown(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

// What a vertex property is read for.
enum Role { kOther = -1, kX, kY, kZ, kRed, kGreen, kBlue, kAlpha, kU, kV };

// The look's parts as the vertices give them (ply_reader.h), per file vertex.
struct PlyLookParts {
    std::vector<double> color;     // linear R, G, B, A; empty: the file has no colours
    std::vector<double> texcoord;  // glTF's (u, 1 - v); empty: the file has no texture coordinates
    // The faces' `texcoord` lists: each corner's (u, v) as written, and per scanned triangle its
    // corners' indices into them; empty: the faces have none.
    std::vector<double> corner_values;
    std::vector<std::array<uint32_t, 3>> corner_uv;
    std::vector<uint32_t> texnumber;  // per scanned triangle, the face's `texnumber`; empty: the faces have none
    std::vector<std::pair<std::string, size_t>> texture_files;  // from the header
};

// The first spelling whose properties are all scalar properties of `e`: their indices, else empty.
std::vector<size_t> findScalars(const PlyElement& e, std::initializer_list<std::vector<const char*>> spellings) {
    for (const std::vector<const char*>& names : spellings) {
        std::vector<size_t> found;
        for (const char* name : names)
            for (size_t i = 0; i < e.props.size(); ++i)
                if (!e.props[i].list && e.props[i].name == name) found.push_back(i);
        if (found.size() == names.size()) return found;
    }
    return {};
}

// "element vertex: properties nx, ny, nz ignored (...)" for the properties of `e` not read (`read`
// false), or nothing when every property is read.
void warnIgnored(const PlyElement& e, const std::vector<bool>& read, std::vector<std::string>* warnings) {
    std::string names;
    size_t count = 0;
    bool normals = false;
    for (size_t i = 0; i < e.props.size(); ++i) {
        if (read[i]) continue;
        names += (count++ ? ", " : "") + e.props[i].name;
        normals = normals || e.props[i].name == "nx" || e.props[i].name == "ny" || e.props[i].name == "nz";
    }
    if (count == 0) return;
    warnings->push_back("element " + e.name + ": " + (count > 1 ? "properties " : "property ") + names + " ignored" +
                        (normals ? " (normals are the apparent surface's own)" : ""));
}

// Checks the header and every value of the body, keeping the vertices, faces and the look's parts.
Status scanPly(const std::string& path, const std::string& bytes, const MeshLimits& limits, ScannedMesh* scan,
               PlyLookParts* parts) {
    PlyHeader h;
    std::string problem;
    if (!parseHeader(bytes, &h, &problem)) return Status::failure(path + ": " + problem);
    auto fail = [&](const std::string& field, const std::string& what) { return Status::failure(path + ": " + field + ": " + what); };

    // Step: the elements we need, with the properties the mesh needs.
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    for (const PlyElement& e : h.elements) {
        if (e.name == "vertex") vertex = &e;
        if (e.name == "face") face = &e;
    }
    if (!vertex) return fail("header", "no 'element vertex'");
    if (!face) return fail("header", "no 'element face' (a point cloud has no surface)");
    for (const char* axis : {"x", "y", "z"}) {
        bool found = false;
        for (const PlyProperty& p : vertex->props) found = found || (p.name == axis && !p.list);
        if (!found) return fail("element vertex", std::string("no scalar property '") + axis + "'");
    }
    int index_prop = -1;
    for (size_t i = 0; i < face->props.size(); ++i)
        if (face->props[i].list && (face->props[i].name == "vertex_indices" || face->props[i].name == "vertex_index")) {
            if (!isIntegral(face->props[i].type)) return fail("element face", face->props[i].name + ": indices must be of an integer type");
            index_prop = int(i);
        }
    if (index_prop < 0) return fail("element face", "no list property 'vertex_indices' (or 'vertex_index')");
    // Step: the faces' look: MeshLab's per-corner `texcoord` list and per-face `texnumber`.
    int corner_prop = -1, texnumber_prop = -1;
    for (size_t i = 0; i < face->props.size(); ++i) {
        const PlyProperty& p = face->props[i];
        if (p.list && p.name == "texcoord") {
            if (isIntegral(p.type)) return fail("element face", "texcoord: values must be of type float or double");
            corner_prop = int(i);
        }
        if (!p.list && p.name == "texnumber") texnumber_prop = int(i);
    }
    // Step: what each vertex property is read for: position, colour (one spelling), texture coordinates (one spelling).
    std::vector<int> vertex_role(vertex->props.size(), kOther);
    for (size_t pi = 0; pi < vertex->props.size(); ++pi)
        for (int a = 0; a < 3; ++a)
            if (!vertex->props[pi].list && vertex->props[pi].name == "xyz"[a] + std::string()) vertex_role[pi] = kX + a;
    const std::vector<size_t> rgb = findScalars(*vertex, {{"red", "green", "blue"}, {"diffuse_red", "diffuse_green", "diffuse_blue"}});
    if (!rgb.empty()) {
        for (int c = 0; c < 3; ++c) vertex_role[rgb[size_t(c)]] = kRed + c;
        const bool diffuse = vertex->props[rgb[0]].name == "diffuse_red";
        const std::vector<size_t> alpha = diffuse ? findScalars(*vertex, {{"diffuse_alpha"}, {"alpha"}}) : findScalars(*vertex, {{"alpha"}});
        if (!alpha.empty()) vertex_role[alpha[0]] = kAlpha;
    }
    const std::vector<size_t> uv = findScalars(*vertex, {{"texture_u", "texture_v"}, {"s", "t"}, {"u", "v"}});
    if (!uv.empty()) vertex_role[uv[0]] = kU, vertex_role[uv[1]] = kV;
    // Step: one warning per element for the properties not read; an apparent frame's objects' indices (exporters/ply.h) apart.
    std::vector<bool> vertex_read(vertex->props.size()), face_read(face->props.size());
    for (size_t pi = 0; pi < vertex->props.size(); ++pi) {
        vertex_read[pi] = vertex_role[pi] != kOther || (vertex->props[pi].name == "object" && !vertex->props[pi].list);
        if (vertex->props[pi].name == "object" && !vertex->props[pi].list)
            scan->warnings.push_back("element vertex: property 'object' ignored (the objects' indices of an apparent "
                                     "frame): the file is one object here");
    }
    face_read[size_t(index_prop)] = true;
    if (corner_prop >= 0) face_read[size_t(corner_prop)] = true;
    if (texnumber_prop >= 0) face_read[size_t(texnumber_prop)] = true;
    warnIgnored(*vertex, vertex_read, &scan->warnings);
    warnIgnored(*face, face_read, &scan->warnings);
    std::string others;
    for (const PlyElement& e : h.elements)
        if (&e != vertex && &e != face) others += (others.empty() ? "" : ", ") + e.name;
    if (!others.empty())
        scan->warnings.push_back(std::string(others.find(',') == std::string::npos ? "element " : "elements ") + others +
                                 " ignored (vertex and face are read)");
    parts->texture_files = h.texture_files;

    // Step: counts against the limits and against the file size, before anything is allocated.
    if (vertex->count > limits.max_vertices)
        return fail("element vertex", std::to_string(vertex->count) + " vertices, more than the limit of " +
                                          std::to_string(limits.max_vertices) + " (raise with --max-vertices)");
    if (face->count > limits.max_faces)
        return fail("element face", std::to_string(face->count) + " faces, more than the limit of " +
                                        std::to_string(limits.max_faces) + " (raise with --max-faces)");
    const size_t body = bytes.size() - h.body_offset;
    uint64_t needed = 0;
    for (const PlyElement& e : h.elements) {
        // The smallest row: binary, every scalar plus every list's count; ascii, one digit and one separator each.
        uint64_t row = 0;
        for (const PlyProperty& p : e.props)
            row += h.format == PlyFormat::Ascii ? 2 : typeSize(p.list ? p.count_type : p.type);
        if (row == 0 && e.count > 0) return fail("element " + e.name, "has rows but no properties");
        if (row > 0 && e.count > (body - std::min<uint64_t>(needed, body)) / row)
            return fail("element " + e.name, std::to_string(e.count) + " rows need at least " +
                                                 std::to_string(row) + " bytes each, more than the file holds (" +
                                                 std::to_string(body) + " bytes after the header)");
        needed += e.count * row;
    }
    // Step: every value of the body, in file order, the vertices and faces kept as read.
    auto& positions = scan->mesh.positions;
    auto& triangles = scan->mesh.triangles;
    positions.resize(size_t(vertex->count));  // bounded by the file size above
    if (!rgb.empty()) parts->color.assign(4 * size_t(vertex->count), 1.0);  // alpha 1 unless given
    if (!uv.empty()) parts->texcoord.assign(2 * size_t(vertex->count), 0.0);
    BodyCursor cur(bytes, h.body_offset, h.format);
    std::vector<uint32_t> face_indices, sorted;
    std::vector<double> face_uv;  // the face row's texcoord list
    // A face's texnumber names one of the TextureFile comments (0 alone when there is at most one).
    const double texture_count = double(std::max<size_t>(h.texture_files.size(), 1));
    for (const PlyElement& e : h.elements) {
        const bool is_vertex = &e == vertex, is_face = &e == face;
        for (uint64_t row = 0; row < e.count; ++row) {
            double texnumber = 0;
            face_uv.clear();
            for (size_t pi = 0; pi < e.props.size(); ++pi) {
                const PlyProperty& p = e.props[pi];
                // Built only for a message: "face[3].vertex_indices".
                auto field = [&] { return e.name + "[" + std::to_string(row) + "]." + p.name; };
                double v = 0;
                if (!cur.read(p.list ? p.count_type : p.type, &v, &problem)) return fail(field(), problem);
                if (!p.list) {
                    if (is_face && int(pi) == texnumber_prop) {
                        if (!(v >= 0 && v < texture_count && v == std::floor(v)))
                            return fail(field(), shown(v) + " names no texture (" + std::to_string(h.texture_files.size()) +
                                                     " TextureFile comments; 0 to " + shown(texture_count - 1) + ")");
                        texnumber = v;
                        continue;
                    }
                    const int role = is_vertex ? vertex_role[pi] : kOther;
                    if (role == kOther) continue;
                    if (role <= kZ || role >= kU) {
                        if (!(std::isfinite(v) && std::fabs(v) <= 3.0e38))
                            return fail(field(), "not a finite number within float range (|x| <= 3e38)");
                        mesh4d::Vec3& q = positions[size_t(row)];
                        if (role == kX) q.x = v;
                        else if (role == kY) q.y = v;
                        else if (role == kZ) q.z = v;
                        else parts->texcoord[2 * size_t(row) + size_t(role - kU)] = role == kU ? v : 1 - v;
                        continue;
                    }
                    // A colour: an integer over its type's largest value, a float as it is; within [0, 1].
                    double top = 1, lo = 0;
                    if (isIntegral(p.type)) integralRange(p.type, &lo, &top);
                    if (!(std::isfinite(v) && v >= 0 && v <= top))
                        return fail(field(), shown(v) + " is not a colour value in [0, " + shown(top) + "]");
                    const double s = v / top;
                    parts->color[4 * size_t(row) + size_t(role - kRed)] = role == kAlpha ? s : srgbToLinear(s);
                    continue;
                }
                // A list: its count, then its items (each item takes at least one byte).
                if (v < 0 || v > double(cur.remaining()))
                    return fail(field(), "list count " + std::to_string((long long)v) +
                                             " is negative or longer than the rest of the file");
                const size_t n = size_t(v);
                const bool indices = is_face && int(pi) == index_prop, corners = is_face && int(pi) == corner_prop;
                if (indices) face_indices.clear();
                for (size_t k = 0; k < n; ++k) {
                    double item = 0;
                    if (!cur.read(p.type, &item, &problem)) return fail(field() + "[" + std::to_string(k) + "]", problem);
                    if (corners) {
                        if (!(std::isfinite(item) && std::fabs(item) <= 3.0e38))
                            return fail(field() + "[" + std::to_string(k) + "]", "not a finite number within float range (|x| <= 3e38)");
                        face_uv.push_back(item);
                    }
                    if (!indices) continue;
                    if (!(item >= 0 && item < double(vertex->count)))
                        return fail(field() + "[" + std::to_string(k) + "]", "index " + std::to_string((long long)item) +
                                                                           " is out of range (" + std::to_string(vertex->count) + " vertices)");
                    face_indices.push_back(uint32_t(item));
                }
                if (indices && n < 3) return fail(field(), "a face needs at least 3 vertices, got " + std::to_string(n));
            }
            if (!is_face) continue;
            // Step: the face itself, as OpenMesh would take it, once its row is read (texcoord may come before the indices).
            const size_t n = face_indices.size();
            auto indices_field = [&] { return "face[" + std::to_string(row) + "]." + face->props[size_t(index_prop)].name; };
            if (corner_prop >= 0 && face_uv.size() != 2 * n)
                return fail("face[" + std::to_string(row) + "].texcoord",
                            std::to_string(face_uv.size()) + " values for a face of " + std::to_string(n) +
                                " vertices (a u v pair per vertex: " + std::to_string(2 * n) + ")");
            sorted.assign(face_indices.begin(), face_indices.end());
            std::sort(sorted.begin(), sorted.end());
            if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
                ++scan->repeated_index;
                continue;
            }
            if (triangles.size() + n - 2 > limits.max_faces)
                return fail(indices_field(), "more than " + std::to_string(limits.max_faces) + " triangles (raise with --max-faces)");
            if (n > 3) scan->polygons.emplace_back(uint32_t(triangles.size()), uint32_t(n));
            const uint32_t first_uv = uint32_t(parts->corner_values.size() / 2);
            parts->corner_values.insert(parts->corner_values.end(), face_uv.begin(), face_uv.end());
            for (size_t k = 1; k + 1 < n; ++k) {
                triangles.push_back({face_indices[0], face_indices[k], face_indices[k + 1]});
                if (corner_prop >= 0) parts->corner_uv.push_back({first_uv, first_uv + uint32_t(k), first_uv + uint32_t(k + 1)});
                if (texnumber_prop >= 0) parts->texnumber.push_back(uint32_t(texnumber));
            }
        }
    }
    if (vertex->count == 0) return fail("element vertex", "no vertices");
    if (triangles.empty()) return fail("element face", "no usable faces");
    return Status::success();
}

// The look of a scanned PLY (ply_reader.h): its colours and texture coordinates (the vertices split
// at the seams of per-corner ones), its materials, and the TextureFile images that can be read.
// Null when the file has neither colours nor texture coordinates.
Status buildPlyLook(const std::string& path, const MeshLimits& limits, PlyLookParts& parts, ScannedMesh* scan,
                    MeshWarnings* warnings, std::shared_ptr<SurfaceLook>* out) {
    out->reset();
    auto where = [&](size_t k) { return "header line " + std::to_string(parts.texture_files[k].second) + ": comment TextureFile"; };
    const bool corners = !parts.corner_uv.empty();
    if (corners && !parts.texcoord.empty()) {
        warnings->other.push_back("element vertex: per-vertex texture coordinates ignored (the faces' per-corner texcoord lists are read)");
        parts.texcoord.clear();
    }
    if (parts.texcoord.empty() && !corners) {
        if (!parts.texture_files.empty())
            warnings->other.push_back(where(0) + " " + parts.texture_files[0].first +
                                      " ignored (no texture coordinates: texture_u texture_v, s t or u v per vertex, "
                                      "or a texcoord list per face)");
        if (parts.color.empty()) return Status::success();
    }
    auto look = std::make_shared<SurfaceLook>();
    look->color = std::move(parts.color);
    look->texcoord = std::move(parts.texcoord);
    // Step: per-corner coordinates made per vertex as an OBJ's vt are; the colours follow the copies.
    if (corners) {
        std::vector<uint32_t> copied_from;
        if (Status s = splitAtTextureSeams(path, limits, parts.corner_values, &parts.corner_uv, scan, &look->texcoord, &copied_from); !s.ok)
            return s;
        std::vector<double>().swap(parts.corner_values);  // per vertex now: their memory back before the mesh is made
        std::vector<std::array<uint32_t, 3>>().swap(parts.corner_uv);
        if (!look->color.empty())
            for (uint32_t v : copied_from)
                for (size_t k = 0; k < 4; ++k) look->color.push_back(look->color[4 * size_t(v) + k]);
        if (!copied_from.empty())
            warnings->other.push_back(std::to_string(copied_from.size()) +
                                      " vertices copied at texture seams (a vertex with more than one texcoord)");
    }
    // Step: the textures, each read as an OBJ's map_Kd is: with a face texnumber one material per
    // TextureFile, else the first one alone (one material per PLY).
    const bool several = parts.texture_files.size() > 1 && !parts.texnumber.empty();
    auto readTexture = [&](size_t k, int* texture) -> Status {
        *texture = -1;
        const std::string file = besideFile(path, parts.texture_files[k].first);
        std::string bytes;
        bool read = false;
        if (Status s = readConfined(where(k), "texture", file, LookFolders(path, limits), limits, warnings, &bytes, &read); !s.ok)
            return s;
        const std::string type = read ? sniffImage(bytes) : "";
        if (read && type.empty()) warnings->other.push_back(where(k) + ": " + file + " is not PNG or JPEG (the texture is dropped)");
        if (type.empty()) return Status::success();
        if (look->samplers.empty()) look->samplers.push_back(R"({"wrapS":10497,"wrapT":10497})");  // REPEAT
        look->images.push_back({type, utf8Replaced(std::filesystem::path(file).filename().string()),
                                std::vector<unsigned char>(bytes.begin(), bytes.end())});
        *texture = int(look->textures.size());
        look->textures.push_back(R"({"sampler":0,"source":)" + std::to_string(look->images.size() - 1) + "}");
        return Status::success();
    };
    if (!look->texcoord.empty() && several) {
        for (size_t k = 0; k < parts.texture_files.size(); ++k) {
            int texture = -1;
            if (Status s = readTexture(k, &texture); !s.ok) return s;
            look->materials.push_back(mtlMaterialJson(MtlMaterial{}, texture, &look->extensions));
        }
        look->triangle_material = std::move(parts.texnumber);
    } else {
        int texture = -1;
        if (!look->texcoord.empty() && !parts.texture_files.empty()) {
            if (parts.texture_files.size() > 1)
                warnings->other.push_back(std::to_string(parts.texture_files.size() - 1) + " more TextureFile comments after " +
                                          where(0) + " ignored (one texture per PLY is read without a face texnumber)");
            if (Status s = readTexture(0, &texture); !s.ok) return s;
        }
        look->materials.push_back(mtlMaterialJson(MtlMaterial{}, texture, &look->extensions));  // triangle_material: readPly
    }
    *out = std::move(look);
    return Status::success();
}

}  // namespace

Status readPly(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings,
               std::shared_ptr<const SurfaceLook>* look_out) {
    if (look_out) look_out->reset();
    // Step: read the whole file (size-limited) and scan it: the bytes are read once.
    std::string text;
    if (Status s = readRegularFile(path, limits.max_file_bytes, &text, "mesh file"); !s.ok) return s;
    ScannedMesh scan;
    PlyLookParts parts;
    if (Status s = scanPly(path, text, limits, &scan, &parts); !s.ok) return s;
    std::string().swap(text);
    std::shared_ptr<SurfaceLook> look;
    if (look_out) {
        if (Status s = buildPlyLook(path, limits, parts, &scan, warnings, &look); !s.ok) {
            // The image's own message, after the mesh it serves.
            if (s.message.rfind(path, 0) != 0) s.message = path + ": " + s.message;
            return s;
        }
    } else if (!parts.color.empty() || !parts.texcoord.empty() || !parts.corner_uv.empty()) {
        warnings->other.push_back("vertex colours and texture coordinates not kept");
    }
    if (!look) return finishScannedMesh(std::move(scan), path, mesh, warnings);
    // Step: the mesh made as for any PLY, the attributes following the vertices OpenMesh copies and
    // the materials the triangles it keeps.
    std::vector<int> origin;
    std::vector<uint32_t> vertex_origin;
    if (Status s = finishScannedMeshTraced(std::move(scan), path, mesh, warnings, &origin, &vertex_origin); !s.ok) return s;
    auto follow = [&](std::vector<double>* values, size_t per_vertex) {
        if (values->empty()) return;
        std::vector<double> out(per_vertex * mesh->positions.size());
        for (size_t v = 0; v < mesh->positions.size(); ++v)
            if (vertex_origin[v] != kNoOrigin)
                for (size_t k = 0; k < per_vertex; ++k) out[per_vertex * v + k] = (*values)[per_vertex * vertex_origin[v] + k];
        *values = std::move(out);
    };
    follow(&look->color, 4);
    follow(&look->texcoord, 2);
    if (look->materials.size() == 1) {
        look->triangle_material.assign(mesh->triangles.size(), 0);
    } else {
        std::vector<uint32_t> triangle_material(mesh->triangles.size());
        for (size_t t = 0; t < triangle_material.size(); ++t) triangle_material[t] = look->triangle_material[size_t(origin[t])];
        look->triangle_material = std::move(triangle_material);
    }
    *look_out = std::move(look);
    return Status::success();
}

}  // namespace apparent
