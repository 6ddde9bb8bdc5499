// OBJ reading by our own scanner: good meshes load, polygons and degenerate faces are counted,
// malformed files fail with the line number, and no truncated prefix of a file crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pipeline/input/mesh_check.h"
#include "pipeline/input/obj_reader.h"

using namespace apparent;

namespace {
std::string fixture(const std::string& name) { return std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/" + name; }
}  // namespace

TEST(ObjReader, ReadsTheFlangeAndTheTetrahedron) {
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readObj(std::string(APPARENT_SOURCE_DIR) + "/data/meshes/flange.obj", {}, &m, &w).ok);
    EXPECT_EQ(m.positions.size(), 6u);
    EXPECT_EQ(m.triangles.size(), 4u);
    EXPECT_TRUE(w.lines().empty());
    const Topology flange = analyzeTopology(m.positions, m.triangles);
    EXPECT_TRUE(flange.manifold);
    EXPECT_EQ(flange.boundary_loops, 1u);  // the two plates form one open strip
    ASSERT_TRUE(readObj(fixture("tetra.obj"), {}, &m, &w).ok);
    const Topology tetra = analyzeTopology(m.positions, m.triangles);
    EXPECT_TRUE(tetra.closed);
    EXPECT_EQ(tetra.genus, 0);
}

TEST(ObjReader, PolygonsAreTriangulatedAndCounted) {
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readObj(fixture("quad.obj"), {}, &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(w.polygons_triangulated, 1u);
    ASSERT_EQ(w.lines().size(), 1u);
    EXPECT_EQ(w.lines()[0], "1 polygons triangulated");
}

// What an OBJ gives that is not kept is said: its materials (usemtl) and texture coordinates (vt).
TEST(ObjReader, MaterialsAndTextureCoordinatesNotKeptAreNamed) {
    const std::string path = (std::filesystem::temp_directory_path() / "apparent_obj_usemtl.obj").string();
    std::ofstream(path) << "mtllib box.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n"
                           "usemtl red\nf 1/1 2/2 3/3\nusemtl blue\nf 1/1 3/3 4/2\nusemtl red\nf 1 4 2\n";
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readObj(path, {}, &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 3u);
    const std::vector<std::string> lines = w.lines();
    auto has = [&](const std::string& text) {
        return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
    };
    EXPECT_TRUE(has("1 mtllib lines ignored"));
    EXPECT_TRUE(has("2 usemtl materials not kept"));
    EXPECT_TRUE(has("3 vt texture coordinates not kept"));
    std::filesystem::remove(path);
}

TEST(ObjReader, DegenerateTrianglesAreDroppedAndCounted) {
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readObj(fixture("degenerate.obj"), {}, &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(w.degenerate_dropped, 2u);
}

TEST(ObjReader, MalformedFilesNameTheLine) {
    const std::pair<const char*, const char*> cases[] = {
        {"bad_index.obj", "bad_index.obj:5: f: vertex index 9 is out of range (valid 1..3"},
        {"bad_number.obj", "bad_number.obj:2: v: expected 3 finite numbers"},
        {"no_faces.obj", "no usable faces"},
        {"two_vertex_face.obj", "two_vertex_face.obj:3: f: a face needs at least 3 vertices, got 2"},
        {"does_not_exist.obj", "cannot open mesh file"},
    };
    for (const auto& [file, expected] : cases) {
        mesh4d::RestMesh m;
        MeshWarnings w;
        const Status st = readObj(fixture(file), {}, &m, &w);
        EXPECT_FALSE(st.ok) << file;
        EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    }
}

TEST(ObjReader, LimitsAreEnforced) {
    mesh4d::RestMesh m;
    MeshWarnings w;
    MeshLimits small;
    small.max_vertices = 3;
    const Status st = readObj(fixture("tetra.obj"), small, &m, &w);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("more than 3 vertices (raise with --max-vertices)"), std::string::npos) << st.message;
}

// Every truncated prefix of a valid file either loads or fails with a message; none crashes.
TEST(ObjReader, TruncatedPrefixesNeverCrash) {
    std::ifstream in(fixture("tetra.obj"), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    const auto dir = std::filesystem::temp_directory_path() / ("apparent_trunc_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "prefix.obj").string();
    for (size_t n = 0; n <= text.size(); ++n) {
        std::ofstream(path, std::ios::binary) << text.substr(0, n);
        mesh4d::RestMesh m;
        MeshWarnings w;
        const Status st = readObj(path, {}, &m, &w);
        if (!st.ok) EXPECT_FALSE(st.message.empty()) << n;
        else EXPECT_FALSE(m.triangles.empty()) << n;
    }
    std::filesystem::remove_all(dir);
}
