// OBJ reading by our own scanner: good meshes load, polygons and degenerate faces are counted,
// malformed files fail with the line number, and no truncated prefix of a file crashes. The look:
// .mtl fields and their glTF materials, usemtl groups, vt with the vertex split, textures.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/input/input_file.h"
#include "pipeline/input/mesh_check.h"
#include "pipeline/input/mtl_reader.h"
#include "pipeline/input/obj_reader.h"
#include "temp_dir.h"

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
    const std::string path = (testio::tempPath() / "apparent_obj_usemtl.obj").string();
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
    const auto dir = testio::tempPath() / ("apparent_trunc_" + std::to_string(::getpid()));
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

// ---- The look: .mtl libraries, usemtl groups, vt ----

namespace {

// A fresh folder with files written into it, removed at the end.
struct LookFolder {
    std::filesystem::path dir;
    explicit LookFolder(const std::string& name)
        : dir(testio::tempPath() / ("apparent_objlook_" + name + "_" + std::to_string(::getpid()))) {
        std::filesystem::remove_all(dir);
        std::filesystem::create_directories(dir);
    }
    ~LookFolder() { std::filesystem::remove_all(dir); }
    std::string write(const std::string& name, const std::string& text) const {
        std::filesystem::create_directories((dir / name).parent_path());
        std::ofstream(dir / name, std::ios::binary) << text;
        return (dir / name).string();
    }
};

bool hasLine(const MeshWarnings& w, const std::string& text) {
    const std::vector<std::string> lines = w.lines();
    return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
}

const std::string kPng("\x89PNG\r\n\x1a\n0000", 12);  // the signature is all the reader looks at

}  // namespace

TEST(MtlReader, FieldsAndTheStatedMapping) {
    std::vector<MtlMaterial> m;
    std::vector<std::string> w;
    ASSERT_TRUE(parseMtl("a.mtl",
                         "# c\nKa 1 1 1\nnewmtl one two\nKd 0.25 0.5 1\nTr 0.25\nKe 2 1 0\nNs 100\nillum 2\n"
                         "map_Kd -s 2 2 1 tex\\wood.png\nnewmtl pbr\nKd 0.5\nPr 0.3\nNs 0\nPm 0.75\nd 1\n"
                         "newmtl one two\nKd 0 0 0\n",
                         &m, &w)
                    .ok);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m[0].name, "one two");  // the rest of the line
    EXPECT_EQ(m[0].diffuse, (std::array<double, 3>{0.25, 0.5, 1}));  // the first definition kept
    EXPECT_EQ(m[0].alpha, 0.75);                                     // 1 - Tr
    EXPECT_EQ(m[0].emissive, (std::array<double, 3>{2, 1, 0}));
    EXPECT_DOUBLE_EQ(m[0].roughness, 1 - 10.0 / 30);  // 1 - sqrt(Ns) / 30
    EXPECT_EQ(m[0].metallic, 0);
    EXPECT_EQ(m[0].diffuse_map, "tex/wood.png");
    EXPECT_EQ(m[1].diffuse, (std::array<double, 3>{0.5, 0.5, 0.5}));  // one number: grey
    EXPECT_EQ(m[1].roughness, 0.3);                                    // Pr wins over a later Ns
    EXPECT_EQ(m[1].metallic, 0.75);
    EXPECT_EQ(m[1].alpha, 1);
    ASSERT_EQ(w.size(), 3u);
    EXPECT_EQ(w[0], "a.mtl: keywords not read (no glTF counterpart here): Ka, illum");
    EXPECT_NE(w[1].find("map_Kd options ignored (line 9)"), std::string::npos) << w[1];
    EXPECT_NE(w[2].find("'one two' (line 16) defined again"), std::string::npos) << w[2];
    // An empty name (Blender's "no material") is a name; bytes that are not UTF-8 read as U+FFFD.
    w.clear();
    ASSERT_TRUE(parseMtl("c.mtl", "newmtl \nKd 0.5\nnewmtl Terraind\xe6k\n", &m, &w).ok);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m[0].name, "");
    EXPECT_EQ(m[1].name, "Terraind\xef\xbf\xbdk");
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("c.mtl: material names that are not UTF-8 (first at line 3)"), std::string::npos) << w[0];
    // A large Ns is clamped at 900 (roughness 0); no Ns and no Pr: roughness 1.
    ASSERT_TRUE(parseMtl("b.mtl", "newmtl a\nNs 5000\nnewmtl b\n", &m, &w).ok);
    EXPECT_EQ(m[0].roughness, 0);
    EXPECT_EQ(m[1].roughness, 1);
}

TEST(MtlReader, MaterialJsonIsTheStatedGltf) {
    MtlMaterial m;
    m.name = "glow";
    m.diffuse = {0.25, 0.5, 1};
    m.alpha = 0.5;
    m.emissive = {4, 2, 0};
    m.roughness = 0.25;
    m.metallic = 0.125;
    std::vector<std::string> ext;
    const nlohmann::json j = nlohmann::json::parse(mtlMaterialJson(m, 3, &ext));
    const nlohmann::json want = nlohmann::json::parse(
        R"({"name":"glow","doubleSided":true,"alphaMode":"BLEND","emissiveFactor":[1,0.5,0],
            "extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":4}},
            "pbrMetallicRoughness":{"baseColorFactor":[0.25,0.5,1,0.5],"metallicFactor":0.125,"roughnessFactor":0.25,
                                    "baseColorTexture":{"index":3}}})");
    EXPECT_EQ(j, want) << j.dump();
    EXPECT_EQ(ext, std::vector<std::string>{"KHR_materials_emissive_strength"});
    // Opaque, no emission, no texture: none of those keys.
    m.alpha = 1;
    m.emissive = {0, 0, 0};
    const nlohmann::json plain = nlohmann::json::parse(mtlMaterialJson(m, -1, &ext));
    EXPECT_FALSE(plain.contains("alphaMode") || plain.contains("emissiveFactor") || plain.contains("extensions") ||
                 plain["pbrMetallicRoughness"].contains("baseColorTexture"))
        << plain.dump();
}

TEST(MtlReader, BadNumbersNameFileLineAndField) {
    const std::pair<const char*, const char*> cases[] = {
        {"newmtl a\nKd 0.5 x 0.5\n", "m.mtl:2: Kd: expected 1 or 3 numbers in [0, 1], got '0.5 x 0.5'"},
        {"newmtl a\n\nKd 0.5 1.5 0.5\n", "m.mtl:3: Kd: expected 1 or 3 numbers in [0, 1], got '0.5 1.5 0.5'"},
        {"newmtl a\nKd 0.5 0.5\n", "m.mtl:2: Kd: expected 1 or 3 numbers in [0, 1], got '0.5 0.5'"},
        {"newmtl a\nd 2\n", "m.mtl:2: d: expected 1 number in [0, 1], got '2'"},
        {"newmtl a\nTr nan\n", "m.mtl:2: Tr: expected 1 number in [0, 1], got 'nan'"},
        {"newmtl a\nKe -1 0 0\n", "m.mtl:2: Ke: expected 1 or 3 numbers >= 0, got '-1 0 0'"},
        {"newmtl a\nNs inf\n", "m.mtl:2: Ns: expected 1 number >= 0, got 'inf'"},
        {"newmtl a\nPr 0.1 0.2\n", "m.mtl:2: Pr: expected 1 number in [0, 1], got '0.1 0.2'"},
        {"Kd 1 1 1\n", "m.mtl:1: Kd: comes before any newmtl"},
        {"newmtl a\nmap_Kd\n", "m.mtl:2: map_Kd: names no file"},
    };
    for (const auto& [text, expected] : cases) {
        std::vector<MtlMaterial> m;
        std::vector<std::string> w;
        const Status st = parseMtl("m.mtl", text, &m, &w);
        EXPECT_FALSE(st.ok) << text;
        EXPECT_EQ(st.message, expected);
    }
}

// usemtl groups become per-triangle materials in first-use order; faces without one, or whose name
// the library lacks, get a white material without a name.
TEST(ObjReader, UsemtlGroupsBecomeTriangleMaterials) {
    LookFolder f("groups");
    f.write("lib/m.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\nPm 1\nnewmtl unused\n");
    const std::string obj = f.write("m.obj",
                                    "mtllib lib/m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n"
                                    "f 1 2 5\nusemtl blue\nf 1 2 3\nusemtl red\nf 1 3 4\nusemtl nowhere\nf 2 6 5\n"
                                    "usemtl blue\nf 2 3 6\n");
    mesh4d::RestMesh m;
    MeshWarnings w;
    std::shared_ptr<const SurfaceLook> look;
    ASSERT_TRUE(readObj(obj, {}, &m, &w, &look).ok);
    ASSERT_TRUE(look);
    ASSERT_EQ(m.triangles.size(), 5u);
    EXPECT_EQ(look->triangle_material, (std::vector<uint32_t>{0, 1, 2, 0, 1}));
    ASSERT_EQ(look->materials.size(), 3u);
    EXPECT_EQ(nlohmann::json::parse(look->materials[0]),
              nlohmann::json::parse(R"({"doubleSided":true,"pbrMetallicRoughness":{"baseColorFactor":[1,1,1,1],
                                       "metallicFactor":0,"roughnessFactor":1}})"));
    const auto blue = nlohmann::json::parse(look->materials[1]);
    EXPECT_EQ(blue["name"], "blue");
    EXPECT_EQ(blue["pbrMetallicRoughness"]["baseColorFactor"], nlohmann::json::parse("[0,0,1,1]"));
    EXPECT_EQ(blue["pbrMetallicRoughness"]["metallicFactor"], 1.0);
    EXPECT_EQ(nlohmann::json::parse(look->materials[2])["name"], "red");
    EXPECT_TRUE(look->texcoord.empty() && look->images.empty());
    EXPECT_TRUE(hasLine(w, "1 usemtl materials not in the libraries ('nowhere')")) << ::testing::PrintToString(w.lines());
    // Without asking for the look: counted, not read.
    MeshWarnings w2;
    ASSERT_TRUE(readObj(obj, {}, &m, &w2).ok);
    EXPECT_TRUE(hasLine(w2, "1 mtllib lines ignored"));
    EXPECT_TRUE(hasLine(w2, "3 usemtl materials not kept"));
}

TEST(ObjReader, NoDefinedMaterialMeansNoLook) {
    LookFolder f("none");
    const std::string obj =
        f.write("m.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl red\nf 1/1 2/1 3/1\n");
    mesh4d::RestMesh m;
    MeshWarnings w;
    std::shared_ptr<const SurfaceLook> look;
    ASSERT_TRUE(readObj(obj, {}, &m, &w, &look).ok);
    EXPECT_FALSE(look);
    EXPECT_TRUE(hasLine(w, "line 1: mtllib: material library " + (f.dir / "missing.mtl").string() + " not found"));
    EXPECT_TRUE(hasLine(w, "1 usemtl materials not kept (no library defines them): the object has one colour"));
    EXPECT_TRUE(hasLine(w, "1 vt texture coordinates not kept"));
}

// A position used with two different texture coordinates becomes two vertices at exactly the same
// place; each vertex's TEXCOORD_0 is (u, 1 - v) of its vt; equal (u, v) written twice do not split.
TEST(ObjReader, VerticesSplitWhereTheirTextureCoordinatesDiffer) {
    LookFolder f("split");
    f.write("m.mtl", "newmtl a\n");
    // Two triangles sharing the edge 2-3: vertex 2 has the same vt value (indices 2 and 5) in both,
    // vertex 3 two different ones; vertex 4 has none (0, 0).
    const std::string obj = f.write("m.obj",
                                    "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                    "vt 0.1 0.2\nvt 0.3 0.4\nvt 0.5 0.6\nvt 0.7 0.8\nvt 0.3 0.4\n"
                                    "f 1/1 2/2 3/3\nf 2/5 4 3/-2\n");
    mesh4d::RestMesh m;
    MeshWarnings w;
    std::shared_ptr<const SurfaceLook> look;
    ASSERT_TRUE(readObj(obj, {}, &m, &w, &look).ok);
    ASSERT_TRUE(look);
    ASSERT_EQ(m.positions.size(), 5u);
    ASSERT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(m.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(m.triangles[1], (std::array<uint32_t, 3>{1, 3, 4}));
    EXPECT_EQ(m.positions[4].x, m.positions[2].x);
    EXPECT_EQ(m.positions[4].y, m.positions[2].y);
    EXPECT_EQ(m.positions[4].z, m.positions[2].z);
    const std::vector<double> want = {0.1, 1 - 0.2, 0.3, 1 - 0.4, 0.5, 1 - 0.6, 0, 0, 0.7, 1 - 0.8};
    EXPECT_EQ(look->texcoord, want);
    EXPECT_EQ(look->triangle_material, (std::vector<uint32_t>{0, 0}));
    EXPECT_TRUE(hasLine(w, "1 vertices copied at texture seams"));
    // A closed mesh split at seams is open by index (as a glTF file with seams is); welded it is closed.
    const Topology split = analyzeTopology(m.positions, m.triangles);
    EXPECT_FALSE(split.closed);
}

// Vertices OpenMesh copies (a non-manifold vertex) keep their original's texture coordinate, and the
// materials follow the triangles past a dropped degenerate one.
TEST(ObjReader, LookFollowsOpenMeshCopiesAndDroppedTriangles) {
    LookFolder f("copies");
    f.write("m.mtl", "newmtl a\nnewmtl b\n");
    // Two triangles touching only at vertex 1 (a bow tie: OpenMesh copies a vertex), then a zero-area one.
    const std::string obj = f.write("m.obj",
                                    "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 2 0 0\n"
                                    "vt 0.25 0.5\nvt 1 0\nvt 0 1\n"
                                    "usemtl a\nf 1/1 2/2 3/3\nf 1/1 2/2 6/3\nusemtl b\nf 1/1 4/2 5/3\nf 1/1 5/3 4/2\n");
    mesh4d::RestMesh m;
    MeshWarnings w;
    std::shared_ptr<const SurfaceLook> look;
    ASSERT_TRUE(readObj(obj, {}, &m, &w, &look).ok);
    ASSERT_TRUE(look);
    EXPECT_EQ(w.degenerate_dropped, 1u);  // 1 2 6 lies on the x axis
    EXPECT_GT(m.positions.size(), 6u) << "OpenMesh copied no vertex: the test does not test the copies";
    ASSERT_EQ(m.triangles.size(), 3u);
    EXPECT_EQ(look->triangle_material, (std::vector<uint32_t>{0, 1, 1}));
    ASSERT_EQ(look->texcoord.size(), 2 * m.positions.size());
    // Every corner at the origin, copied or not, has vt 1: (0.25, 1 - 0.5).
    size_t at_origin = 0;
    for (const auto& t : m.triangles)
        for (uint32_t v : t)
            if (m.positions[v].x == 0 && m.positions[v].y == 0) {
                ++at_origin;
                EXPECT_EQ(look->texcoord[2 * v], 0.25);
                EXPECT_EQ(look->texcoord[2 * v + 1], 0.5);
            }
    EXPECT_EQ(at_origin, 3u);
}

TEST(ObjReader, LookErrorsNameTheLine) {
    LookFolder f("errors");
    f.write("m.mtl", "newmtl a\nKd 2 0 0\n");
    f.write("ok.mtl", "newmtl a\n");
    const std::pair<std::string, std::string> cases[] = {
        {"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n", "m.obj: " + (f.dir / "m.mtl").string() + ":2: Kd: expected 1 or 3 numbers"},
        {"mtllib .\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n", "m.obj: " + (f.dir / ".").string() + ": is a folder, not a regular file (refused)"},
        {"mtllib ok.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/1 2/2 3/1\n",
         "m.obj:7: f: texture coordinate index in '2/2' is out of range (1 vt so far)"},
        {"mtllib ok.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/x 2/1 3/1\n",
         "m.obj:7: f: texture coordinate index in '1/x' is malformed"},
        {"v 0 0 0\nvt 0 nan\n", "m.obj:2: vt: expected 1 to 3 finite numbers"},
    };
    for (const auto& [text, expected] : cases) {
        const std::string obj = f.write("m.obj", text);
        mesh4d::RestMesh m;
        MeshWarnings w;
        std::shared_ptr<const SurfaceLook> look;
        const Status st = readObj(obj, {}, &m, &w, &look);
        EXPECT_FALSE(st.ok) << text;
        EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
        EXPECT_EQ(st.message.rfind(obj, 0), 0u) << st.message;  // starts with the OBJ's path
        EXPECT_EQ(st.message.find('\n'), std::string::npos) << st.message;
    }
    // Without a look the texture indices are not read: the same bad index loads.
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readObj(f.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/7 2/7 3/7\n"), {}, &m, &w).ok);
}

// map_Kd: a PNG or JPEG is kept once (its bytes as they are) behind one REPEAT sampler; another
// format is dropped with a warning.
TEST(ObjReader, DiffuseMapsBecomeTextures) {
    LookFolder f("maps");
    f.write("tex/a.png", kPng);
    f.write("tex/b.jpg", std::string("\xff\xd8\xff\xe0", 4));
    f.write("tex/c.bmp", "BM....");
    f.write("mat/m.mtl",
            "newmtl a\nmap_Kd ../tex/a.png\nnewmtl a2\nmap_Kd ..\\tex\\a.png\nnewmtl b\nmap_Kd ../tex/b.jpg\n"
            "newmtl c\nmap_Kd ../tex/c.bmp\n");
    const std::string obj = f.write("m.obj",
                                    "mtllib mat/m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                    "usemtl a\nf 1 2 3\nusemtl b\nf 2 4 3\nusemtl c\nf 1 3 4\nusemtl a2\nf 1 4 2\n");
    mesh4d::RestMesh m;
    MeshWarnings w;
    std::shared_ptr<const SurfaceLook> look;
    ASSERT_TRUE(readObj(obj, {}, &m, &w, &look).ok);
    ASSERT_TRUE(look);
    ASSERT_EQ(look->images.size(), 2u);
    EXPECT_EQ(look->images[0].mime_type, "image/png");
    EXPECT_EQ(std::string(look->images[0].bytes.begin(), look->images[0].bytes.end()), kPng);
    EXPECT_EQ(look->images[1].mime_type, "image/jpeg");
    EXPECT_EQ(look->textures, (std::vector<std::string>{R"({"sampler":0,"source":0})", R"({"sampler":0,"source":1})"}));
    EXPECT_EQ(look->samplers, (std::vector<std::string>{R"({"wrapS":10497,"wrapT":10497})"}));
    auto texture = [&](size_t i) {
        const auto j = nlohmann::json::parse(look->materials[i])["pbrMetallicRoughness"];
        return j.contains("baseColorTexture") ? j["baseColorTexture"]["index"].get<int>() : -1;
    };
    EXPECT_EQ(texture(0), 0);
    EXPECT_EQ(texture(1), 1);
    EXPECT_EQ(texture(2), -1);
    EXPECT_EQ(texture(3), 0);  // the same file again
    EXPECT_TRUE(hasLine(w, "c.bmp is not PNG or JPEG (the texture is dropped)"));
}

// A library may lie where a mesh may: in the scene's folder (MeshLimits::scene_path) beside the OBJ's
// own; outside them it is not opened (one warning) unless allow_outside.
TEST(ObjReader, LibrariesAreReadFromTheFoldersAMeshMayUse) {
    LookFolder f("folders");
    f.write("materials/m.mtl", "newmtl a\nKd 0 1 0\n");
    const std::string obj =
        f.write("meshes/m.obj", "mtllib ../materials/m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    const std::string library = (f.dir / "meshes/../materials/m.mtl").string();
    mesh4d::RestMesh m;
    std::shared_ptr<const SurfaceLook> look;
    MeshLimits limits;
    if (!resolvesInside(library, std::filesystem::current_path().string())) {  // else the working folder allows it
        MeshWarnings w;
        ASSERT_TRUE(readObj(obj, limits, &m, &w, &look).ok);
        EXPECT_FALSE(look);
        EXPECT_TRUE(hasLine(w, "line 1: mtllib: material library " + library +
                                   " is outside the folders a mesh may be read from: not opened (allow with --allow-outside)"))
            << ::testing::PrintToString(w.lines());
    }
    for (const bool allow : {false, true}) {
        limits.scene_path = allow ? std::string() : (f.dir / "scene.json").string();
        limits.allow_outside = allow;
        MeshWarnings w;
        ASSERT_TRUE(readObj(obj, limits, &m, &w, &look).ok);
        ASSERT_TRUE(look) << allow;
        EXPECT_EQ(nlohmann::json::parse(look->materials[0])["pbrMetallicRoughness"]["baseColorFactor"],
                  nlohmann::json::parse("[0,1,0,1]"));
    }
}
