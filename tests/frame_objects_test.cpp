// Objects apart in the PLY and OBJ frames (exporters/ply.h, exporters/obj.h):
// a two-object scene rendered to both, against each object rendered alone from the same scene
// (an independent oracle: objects are cut independently, so object i's vertices in the pair's
// files are the lone render's, in order); every face within one object; the header comments name
// the objects, the model, the scene and the camera time frameTime gives, read back exactly; and
// the width of the PLY's `object` index from the sequence's object count.
#include <gtest/gtest.h>

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "exporters/obj.h"
#include "exporters/ply.h"
#include "file_bytes.h"
#include "pipeline/input/scene.h"
#include "run_command.h"

using namespace apparent;
using testcli::apparentRun;
namespace fs = std::filesystem;

namespace {

// A binary little-endian PLY read by the header's own description (any vertex properties).
struct PlyFile {
    std::vector<std::string> comments;              // the text after "comment "
    std::vector<std::pair<std::string, std::string>> vertex_props;  // (type, name)
    std::vector<std::array<double, 3>> positions;
    std::vector<long long> object;                  // the `object` column
    std::vector<std::array<int32_t, 3>> faces;
};

size_t plyTypeSize(const std::string& type) {
    if (type == "uchar" || type == "char") return 1;
    if (type == "ushort" || type == "short") return 2;
    if (type == "int" || type == "uint" || type == "float") return 4;
    if (type == "double") return 8;
    ADD_FAILURE() << "unexpected PLY type " << type;
    return 0;
}

PlyFile readPly(const fs::path& p) {
    PlyFile f;
    const std::string bytes = testio::readBytes(p);
    const size_t end = bytes.find("end_header\n");
    EXPECT_NE(end, std::string::npos) << p;
    std::istringstream header(bytes.substr(0, end));
    std::string line, element;
    size_t vertices = 0, faces = 0;
    while (std::getline(header, line)) {
        if (line.rfind("comment ", 0) == 0) f.comments.push_back(line.substr(8));
        std::istringstream words(line);
        std::string w0, w1, w2;
        words >> w0 >> w1 >> w2;
        if (w0 == "element") {
            element = w1;
            (element == "vertex" ? vertices : faces) = std::stoul(w2);
        } else if (w0 == "property" && element == "vertex") {
            f.vertex_props.emplace_back(w1, w2);
        }
    }
    size_t stride = 0;
    for (const auto& [type, name] : f.vertex_props) stride += plyTypeSize(type);
    const char* data = bytes.data() + end + 11;
    EXPECT_EQ(bytes.size(), end + 11 + stride * vertices + 13 * faces) << p;
    for (size_t v = 0; v < vertices; ++v) {
        const char* row = data + stride * v;
        std::array<double, 3> q{};
        for (const auto& [type, name] : f.vertex_props) {
            // Little-endian values on this (x86-64) test machine.
            if (name == "x" || name == "y" || name == "z") std::memcpy(&q[size_t(name[0] - 'x')], row, 8);
            if (name == "object") {
                if (type == "uchar") f.object.push_back((unsigned char)row[0]);
                if (type == "ushort") {
                    uint16_t u = 0;
                    std::memcpy(&u, row, 2);
                    f.object.push_back(u);
                }
                if (type == "int") {
                    int32_t i = 0;
                    std::memcpy(&i, row, 4);
                    f.object.push_back(i);
                }
            }
            row += plyTypeSize(type);
        }
        f.positions.push_back(q);
    }
    for (size_t k = 0; k < faces; ++k) {
        const char* row = data + stride * vertices + 13 * k;
        EXPECT_EQ(row[0], char(3));
        std::array<int32_t, 3> t{};
        std::memcpy(t.data(), row + 1, 12);
        f.faces.push_back(t);
    }
    return f;
}

// An OBJ frame: its comments (after "# "), its `o` groups in order with each group's vertices and
// faces (1-based indices into the whole file, as written).
struct ObjGroup {
    std::string name;
    std::vector<std::array<double, 3>> positions;
    size_t first_vertex = 0;  // 1-based index of the group's first vertex
    std::vector<std::array<long long, 3>> faces;
};
struct ObjFile {
    std::vector<std::string> comments;
    std::vector<ObjGroup> groups;
    size_t vertices_outside_groups = 0;
};

ObjFile readObj(const fs::path& p) {
    ObjFile f;
    std::ifstream in(p);
    std::string line;
    size_t vertex = 0;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string key;
        words >> key;
        if (line.rfind("# ", 0) == 0) {
            f.comments.push_back(line.substr(2));
        } else if (key == "o") {
            f.groups.push_back({line.substr(2), {}, vertex + 1, {}});
        } else if (key == "v") {
            ++vertex;
            std::array<double, 3> q{};
            EXPECT_TRUE(testio::objVertex(line, &q)) << line;
            if (f.groups.empty())
                ++f.vertices_outside_groups;
            else
                f.groups.back().positions.push_back(q);
        } else if (key == "f") {
            std::array<long long, 3> t{};
            words >> t[0] >> t[1] >> t[2];
            EXPECT_FALSE(f.groups.empty()) << "a face before any o line";
            if (!f.groups.empty()) f.groups.back().faces.push_back(t);
        }
    }
    return f;
}

// The value after "KEY: " among `comments`, or "" when there is none.
std::string commentValue(const std::vector<std::string>& comments, const std::string& key) {
    for (const std::string& c : comments)
        if (c.rfind(key + ": ", 0) == 0) return c.substr(key.size() + 2);
    return "";
}

double exactNumber(const std::string& text) {
    double v = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    EXPECT_TRUE(r.ec == std::errc() && r.ptr == text.data() + text.size()) << "'" << text << "'";
    return v;
}

// Two tetrahedra, one moving at 0.6c, the other at rest; `which` keeps both (-1) or one alone.
// The first's name has a space and a tab (an OBJ `o` name is one word).
void writeScene(const fs::path& dir, int which) {
    fs::create_directories(dir);
    std::ofstream(dir / "tetra.obj") << "v 0.5 0.25 0\nv -0.5 0 0.125\nv 0 -0.75 0.5\nv 0.25 0.5 -0.5\n"
                                        "f 1 2 4\nf 1 3 2\nf 1 4 3\nf 2 3 4\n";
    const std::string objects[2] = {
        R"({"name": "left block\tone", "mesh": "tetra.obj", "position": [-2, 0, -10], "velocity": [0.6, 0, 0]})",
        R"({"name": "right", "mesh": "tetra.obj", "position": [2, 0.5, -10]})"};
    std::string list = which < 0 ? objects[0] + ", " + objects[1] : objects[which];
    std::ofstream(dir / "scene.json") << R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
        "frames": {"start": 0.1, "end": 1, "fps": 3}, "model": "relativistic",
        "objects": [)" + list + "]}";
}

}  // namespace

TEST(FrameObjects, TwoObjectsApartInPlyAndObj) {
    testcli::TempDir tmp;
    const fs::path pair = tmp / "pair", alone[2] = {tmp / "first", tmp / "second"};
    writeScene(pair, -1);
    writeScene(alone[0], 0);
    writeScene(alone[1], 1);
    for (const fs::path& d : {pair, alone[0], alone[1]}) {
        const auto r = apparentRun({"render", (d / "scene.json").string(), "--out", (d / "out").string(), "--format",
                                    "ply,obj", "--quiet"});
        ASSERT_EQ(r.code, 0) << r.err;
    }
    // The scene's frames (0.1 + k/3 while < 1): the camera times the headers must carry.
    FrameSpec frames;
    frames.start = 0.1;
    frames.end = 1;
    frames.fps = 3;
    const std::string names[2] = {"left_block_one", "right"};
    for (long long k = 0; k < 3; ++k) {
        const std::string file = "out/relativistic/" + frameName(k);
        SCOPED_TRACE(file);
        const PlyFile ply = readPly(pair / (file + ".ply"));
        const ObjFile obj = readObj(pair / (file + ".obj"));

        // Step: the comments, both files alike.
        for (const std::vector<std::string>* comments : {&ply.comments, &obj.comments}) {
            EXPECT_EQ(commentValue(*comments, "model"), "relativistic");
            EXPECT_EQ(commentValue(*comments, "scene"), (pair / "scene.json").string());
            EXPECT_EQ(exactNumber(commentValue(*comments, "camera_time")), frameTime(frames, k));
            size_t listed = 0;
            for (const std::string& c : *comments)
                if (c.rfind("object ", 0) == 0) {
                    ASSERT_LT(listed, 2u) << c;
                    EXPECT_EQ(c, "object " + std::to_string(listed) + " " + names[listed]);
                    ++listed;
                }
            EXPECT_EQ(listed, 2u);
        }

        // Step: the PLY's object column, a uchar (2 objects), against each object alone.
        ASSERT_EQ(ply.vertex_props.back(), (std::pair<std::string, std::string>{"uchar", "object"}));
        ASSERT_EQ(ply.object.size(), ply.positions.size());
        size_t at = 0, faces_seen = 0;
        for (int o = 0; o < 2; ++o) {
            const PlyFile lone = readPly(alone[o] / (file + ".ply"));
            ASSERT_FALSE(lone.positions.empty());
            size_t count = 0;
            for (long long i : ply.object) count += i == o;
            EXPECT_EQ(count, lone.positions.size()) << "object " << o;
            // The pair's vertices of object o: contiguous, the lone render's in order.
            for (size_t i = 0; i < lone.positions.size(); ++i) {
                ASSERT_LT(at + i, ply.positions.size());
                EXPECT_EQ(ply.object[at + i], o);
                EXPECT_EQ(ply.positions[at + i], lone.positions[i]) << "object " << o << " vertex " << i;
            }
            // Its faces: the lone render's, offset by the vertices before, every corner in object o.
            for (size_t f = 0; f < lone.faces.size(); ++f) {
                ASSERT_LT(faces_seen + f, ply.faces.size());
                for (int c = 0; c < 3; ++c) {
                    const int32_t v = ply.faces[faces_seen + f][size_t(c)];
                    EXPECT_EQ(v, lone.faces[f][size_t(c)] + int32_t(at));
                    EXPECT_EQ(ply.object[size_t(v)], o) << "face " << faces_seen + f;
                }
            }
            at += lone.positions.size();
            faces_seen += lone.faces.size();
        }
        EXPECT_EQ(at, ply.positions.size());
        EXPECT_EQ(faces_seen, ply.faces.size());

        // Step: the OBJ's groups, one per object in scene order, each the lone render's vertices.
        EXPECT_EQ(obj.vertices_outside_groups, 0u);
        ASSERT_EQ(obj.groups.size(), 2u);
        for (int o = 0; o < 2; ++o) {
            const ObjGroup& g = obj.groups[size_t(o)];
            EXPECT_EQ(g.name, names[o]);
            const ObjFile lone = readObj(alone[o] / (file + ".obj"));
            ASSERT_EQ(lone.groups.size(), 1u);
            EXPECT_EQ(lone.groups[0].name, names[o]);
            EXPECT_EQ(g.positions, lone.groups[0].positions);
            ASSERT_EQ(g.faces.size(), lone.groups[0].faces.size());
            for (size_t f = 0; f < g.faces.size(); ++f)
                for (int c = 0; c < 3; ++c) {
                    const long long v = g.faces[f][size_t(c)];
                    EXPECT_EQ(v, lone.groups[0].faces[f][size_t(c)] + (long long)(g.first_vertex - 1));
                    EXPECT_TRUE(v >= (long long)g.first_vertex && v < (long long)(g.first_vertex + g.positions.size()))
                        << "group " << g.name << " face " << f << " uses vertex " << v;
                }
        }
    }
}

// The `object` property's type follows the sequence's object count (uchar up to 256 objects,
// ushort up to 65536, else int), also in a frame where only the last object has anything; the
// value read back is that object's index.
TEST(FrameObjects, ObjectIndexWidthFollowsTheSequence) {
    struct Case {
        size_t objects;
        const char* type;
    };
    testcli::TempDir tmp;
    fs::create_directories(tmp / "");
    for (const Case c : {Case{256, "uchar"}, Case{257, "ushort"}, Case{65536, "ushort"}, Case{65537, "int"}}) {
        SequenceInfo info;
        ExportFrame frame;
        frame.t_c = 0.25;
        info.objects.resize(c.objects);
        frame.objects.resize(c.objects);
        mesh4d::ApparentMesh& last = frame.objects.back();
        last.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        last.emission_times = {0, 0, 0};
        last.triangles = {{0, 1, 2}};
        const fs::path path = tmp / (std::to_string(c.objects) + ".ply");
        std::string error;
        ASSERT_TRUE(writePly(path.string(), frame, info, &error)) << error;
        const PlyFile ply = readPly(path);
        ASSERT_EQ(ply.vertex_props.back(), (std::pair<std::string, std::string>{c.type, "object"}));
        ASSERT_EQ(ply.object.size(), 3u);
        for (long long o : ply.object) EXPECT_EQ(o, (long long)(c.objects - 1)) << c.objects;
        // Unnamed objects are named by their index.
        EXPECT_EQ(ply.comments.back(), "object " + std::to_string(c.objects - 1) + " object_" + std::to_string(c.objects - 1));
    }
}

// Frames across processes without shared spills (exporters/frame_files.h): a rank's sink, begun
// with beginEncoding, encodes the bytes its writer would write, and the writing sink commits them
// (addEncoded): the same file, comments and object indices included, as one process's add().
TEST(FrameObjects, EncodedFramesAreTheOneProcessBytes) {
    testcli::TempDir tmp;
    SequenceInfo info;
    info.model = "finite";
    info.scene_path = "scenes/two.json";
    info.objects.resize(2);
    info.objects[0].name = "a b";
    info.objects[1].name = "c";
    info.objects[1].base_color = {0.5, 0.5, 0.5, 1};
    ExportFrame frame;
    frame.index = 7;
    frame.t_c = 0.1 + 7.0 / 3;
    for (int o = 0; o < 2; ++o) {
        mesh4d::ApparentMesh m;
        m.positions = {{double(o), 0, 0}, {double(o) + 1, 0, 0}, {double(o), 1, 0}};
        m.emission_times = {0, -1, -2};
        m.triangles = {{0, 1, 2}};
        frame.objects.push_back(m);
    }
    for (const bool ply : {true, false}) {
        const fs::path one = tmp / (ply ? "one_ply" : "one_obj"), writer = tmp / (ply ? "w_ply" : "w_obj");
        auto direct = ply ? plySink(one.string()) : objSink(one.string());
        auto rank = ply ? plySink(writer.string()) : objSink(writer.string());
        auto rank0 = ply ? plySink(writer.string()) : objSink(writer.string());
        std::string error;
        std::vector<std::string> completed;
        ASSERT_TRUE(direct->begin(info, &error)) << error;
        ASSERT_TRUE(direct->add(frame, direct->prepare(frame).get(), &completed, &error)) << error;
        ASSERT_TRUE(rank->beginEncoding(info, &error)) << error;
        ASSERT_TRUE(rank0->begin(info, &error)) << error;
        const EncodedOutput e = rank->encode(frame, rank->prepare(frame).get());
        ASSERT_TRUE(rank0->addEncoded(frame.index, e, &completed, &error)) << error;
        ASSERT_EQ(completed.size(), 2u);
        const std::string name = frameName(7) + (ply ? ".ply" : ".obj");
        const std::string bytes = testio::readBytes(one / name);
        EXPECT_TRUE(bytes == testio::readBytes(writer / name)) << name;
        // The comments came with the sequence: the rank's bytes name the objects and the scene.
        EXPECT_NE(bytes.find(std::string(ply ? "comment " : "# ") + "object 0 a_b\n"), std::string::npos) << name;
        EXPECT_NE(bytes.find(std::string(ply ? "comment " : "# ") + "scene: scenes/two.json\n"), std::string::npos);
    }
}
