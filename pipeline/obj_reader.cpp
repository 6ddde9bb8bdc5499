#include "pipeline/obj_reader.h"

#include <cerrno>
#include <cmath>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "pipeline/input_file.h"
#include "pipeline/mesh_check.h"
#include "pipeline/openmesh_input.h"

namespace apparent {

namespace {

typedef InputTriMesh ObjMesh;

// The scan's counts (openmesh_input.h), and the faces OpenMesh should keep.
struct ScanResult : ScannedCounts {
    size_t faces = 0;
};

bool parseFinite(const std::string& token, double* out) {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    // OpenMesh reads OBJ coordinates as float: larger magnitudes would be dropped by it silently.
    if (end == token.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v) || std::fabs(v) > 3.0e38) return false;
    *out = v;
    return true;
}

// Scans the OBJ text for what OpenMesh would drop without a word. Material libraries are never
// read (nothing uses materials): each `mtllib` line is turned into a comment in `text`, so
// OpenMesh cannot open the file it names (a device, a FIFO, a file outside every folder).
Status scanObj(const std::string& path, std::string& text, const MeshLimits& limits, ScanResult* scan,
               MeshWarnings* warnings) {
    size_t mtllibs = 0;
    std::string line;
    size_t line_no = 0;
    auto fail = [&](const std::string& problem) {
        return Status::failure(path + ":" + std::to_string(line_no) + ": " + problem);
    };
    // UTF-16 (a byte-order mark, or NUL bytes among the first characters, as Windows tools write
    // it): every line would read as garbage and the file as "no vertices".
    const size_t prefix = std::min<size_t>(text.size(), 64);
    if ((text.size() >= 2 && (((unsigned char)text[0] == 0xFF && (unsigned char)text[1] == 0xFE) ||
                              ((unsigned char)text[0] == 0xFE && (unsigned char)text[1] == 0xFF))) ||
        text.find('\0') < prefix)
        return Status::failure(path + ": UTF-16 text; save as UTF-8 (OBJ is read as ASCII / UTF-8)");
    size_t face_no = 0;          // 'f' lines so far
    std::string first_repeat;    // "face 3 repeats vertex 7 (line 12)": the first face dropped for it
    for (size_t at = 0; at < text.size();) {
        size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        const size_t line_start = at;
        line.assign(text, at, end - at);
        at = end + 1;
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string key;
        if (!(ls >> key) || key[0] == '#') continue;
        if (key == "mtllib") {
            text[line_start + line.find_first_not_of(" \t")] = '#';
            ++mtllibs;
            continue;
        }
        if (key == "v") {
            std::string tok;
            double xyz[3];
            for (int i = 0; i < 3; ++i) {
                if (!(ls >> tok) || !parseFinite(tok, &xyz[i]))
                    return fail("v: expected 3 finite numbers within float range (|x| <= 3e38), got '" + line + "'");
            }
            if (++scan->vertices > limits.max_vertices)
                return fail("v: more than " + std::to_string(limits.max_vertices) + " vertices (raise with --max-vertices)");
        } else if (key == "f") {
            std::vector<long> idx;
            std::string tok;
            while (ls >> tok) {
                // "i", "i/t", "i//n", "i/t/n": the position index comes first; negatives count back.
                const std::string head = tok.substr(0, tok.find('/'));
                char* end = nullptr;
                errno = 0;
                const long i = std::strtol(head.c_str(), &end, 10);
                if (head.empty() || *end != '\0' || errno == ERANGE || i == 0)
                    return fail("f: bad vertex index '" + tok + "'");
                const long resolved = i > 0 ? i : long(scan->vertices) + 1 + i;
                if (resolved < 1 || resolved > long(scan->vertices))
                    return fail("f: vertex index " + std::to_string(i) + " is out of range (valid 1.." +
                                std::to_string(scan->vertices) + " so far, or -1..-" + std::to_string(scan->vertices) + ")");
                idx.push_back(resolved);
            }
            ++face_no;
            if (idx.size() < 3) return fail("f: a face needs at least 3 vertices, got " + std::to_string(idx.size()));
            if (std::set<long>(idx.begin(), idx.end()).size() != idx.size()) {
                ++scan->repeated_index;  // OpenMesh drops it; we count it as degenerate
                if (first_repeat.empty()) {
                    std::set<long> seen;
                    long repeated = 0;
                    for (long i : idx)
                        if (!seen.insert(i).second && !repeated) repeated = i;
                    first_repeat = "face " + std::to_string(face_no) + " repeats vertex " + std::to_string(repeated) +
                                   " (line " + std::to_string(line_no) + ")";
                }
                continue;
            }
            ++scan->faces;
            scan->triangles += idx.size() - 2;
            if (idx.size() > 3) ++scan->polygons;
            if (scan->faces > limits.max_faces)
                return fail("f: more than " + std::to_string(limits.max_faces) + " faces (raise with --max-faces)");
        }
    }
    if (mtllibs)
        warnings->other.push_back(std::to_string(mtllibs) +
                                  " mtllib lines ignored (material libraries are not read)");
    if (scan->vertices == 0) return Status::failure(path + ": no vertices ('v' lines)");
    if (scan->faces == 0)
        return Status::failure(path + ": no usable faces ('f' lines)" +
                               (first_repeat.empty() ? std::string()
                                                      : ": " + first_repeat +
                                                            (scan->repeated_index > 1
                                                                 ? " (and " + std::to_string(scan->repeated_index - 1) + " more faces repeat a vertex)"
                                                                 : std::string())));
    if (!first_repeat.empty())
        warnings->other.push_back(first_repeat + ": dropped (a face may use a vertex once)");
    return Status::success();
}

}  // namespace

Status readObj(const std::string& path, const MeshLimits& limits, mesh4d::RestMesh* mesh, MeshWarnings* warnings) {
    // Step: scan for what the library would drop silently.
    std::string text;
    if (Status s = readRegularFile(path, limits.max_file_bytes, &text, "mesh file"); !s.ok) return s;
    ScanResult scan;
    if (Status s = scanObj(path, text, limits, &scan, warnings); !s.ok) return s;

    // Step: read with OpenMesh; its own log lines become our counts.
    omerr().disable();
    omlog().disable();
    ObjMesh om;
    OpenMesh::IO::Options opt;
    MemoryBuffer buffer(text);
    std::istream in(&buffer);
    if (!OpenMesh::IO::read_mesh(om, in, ".obj", opt)) return Status::failure(path + ": OpenMesh could not read the OBJ file");

    return takeOpenMeshResult(om, scan, path, mesh, warnings);
}

}  // namespace apparent
