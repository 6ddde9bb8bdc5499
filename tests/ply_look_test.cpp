// A PLY's look (pipeline/input/ply_reader.h): vertex colours of every integer and float type made
// linear against the sRGB closed form computed by hand here, alpha as it is, texture coordinates of
// each spelling as glTF's (u, 1 - v), the TextureFile image read under the look's file rules,
// values out of range refused naming the row and property, one warning per element for the
// properties not read; then a coloured PLY rendered at rest gives COLOR_0 equal to its linear
// colours vertex for vertex. Per-corner `texcoord` lists: a cube whose corners' coordinates are a
// closed form, split into the hand-counted vertices, errors, `texnumber` materials, and the cube
// rendered at rest gives TEXCOORD_0 equal to the closed form corner for corner.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <sys/stat.h>

#include <tiny_gltf.h>

#include "pipeline/input/mesh_input.h"
#include "pipeline/input/ply_reader.h"
#include "file_bytes.h"
#include "run_command.h"
#include "temp_dir.h"
#include "glb_accessors.h"

using namespace apparent;
namespace fs = std::filesystem;

namespace {

// A folder of its own for one test's files.
struct PlyFolder {
    fs::path dir;
    explicit PlyFolder(const std::string& name) : dir(testio::tempPath() / ("ply_look_" + name)) {
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(dir / name, std::ios::binary) << text;
        return (dir / name).string();
    }
};

// Renders f's scene.json (the instant model, frame 0) and reads its .glb back into `model`.
void renderAtRest(const PlyFolder& f, tinygltf::Model* model) {
    const testcli::CommandResult run = testcli::apparentRun(
        {"render", (f.dir / "scene.json").string(), "--out", (f.dir / "out").string(), "--frames", "0:1", "--quiet"});
    ASSERT_EQ(run.code, 0) << run.err;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    ASSERT_TRUE(loader.LoadBinaryFromFile(model, &err, &warn, (f.dir / "out/instant.glb").string())) << err;
}

// An ascii triangle whose vertices have `props` (header lines) and `values` (one row per vertex, after x y z).
std::string triangle(const std::string& props, const std::array<std::string, 3>& values, const std::string& comments = "") {
    return "ply\nformat ascii 1.0\n" + comments + "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n" +
           props + "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 " + values[0] + "\n1 0 0 " +
           values[1] + "\n0 1 0 " + values[2] + "\n3 0 1 2\n";
}

struct Read {
    Status status;
    mesh4d::RestMesh mesh;
    MeshWarnings warnings;
    std::shared_ptr<const SurfaceLook> look;
};

Read readLook(const std::string& path, const MeshLimits& limits = {}) {
    Read r;
    r.status = readPly(path, limits, &r.mesh, &r.warnings, &r.look);
    return r;
}

// The sRGB decoding written out: s / 12.92 up to 0.04045, ((s + 0.055) / 1.055)^2.4 above.
double decoded(double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); }

bool hasLine(const MeshWarnings& w, const std::string& text) {
    for (const std::string& l : w.lines())
        if (l.find(text) != std::string::npos) return true;
    return false;
}

}  // namespace

// uchar levels 0, 10 (below the knee: 10/255 = 0.0392), 128 and 255; the closed form's values at
// 0, 0.5 and 1 by hand (0.5 -> ((0.555 / 1.055)^2.4 = 0.21404114048223255).
TEST(PlyLook, UcharColoursAreDecodedFromSrgb) {
    PlyFolder f("uchar");
    const Read r = readLook(f.write("t.ply", triangle("property uchar red\nproperty uchar green\nproperty uchar blue\n",
                                                        {"0 10 128", "255 0 0", "0 255 10"})));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.look->color.size(), 12u);
    EXPECT_EQ(r.look->color[0], 0.0);
    EXPECT_NEAR(r.look->color[1], 10.0 / 255 / 12.92, 1e-15);
    EXPECT_NEAR(r.look->color[2], std::pow((128.0 / 255 + 0.055) / 1.055, 2.4), 1e-15);
    EXPECT_NEAR(r.look->color[2], 0.2158605001138992, 1e-12);  // 128/255 = 0.50196
    EXPECT_EQ(r.look->color[3], 1.0);  // no alpha: opaque
    EXPECT_EQ(r.look->color[4], 1.0);
    EXPECT_EQ(r.look->color[9], 1.0);
    EXPECT_NEAR(r.look->color[10], 10.0 / 255 / 12.92, 1e-15);
    EXPECT_TRUE(r.look->texcoord.empty());
    ASSERT_EQ(r.look->materials.size(), 1u);
    EXPECT_EQ(r.look->triangle_material, (std::vector<uint32_t>{0}));
    EXPECT_TRUE(r.warnings.lines().empty());
}

// Float colours taken as they are: 0, 0.5, 1 and 0.02 (below the knee); alpha 0.25 stays linear.
TEST(PlyLook, FloatColoursAndAlpha) {
    PlyFolder f("float");
    const Read r = readLook(f.write("t.ply", triangle("property float red\nproperty float green\nproperty float blue\nproperty float alpha\n",
                                                        {"0 0.5 1 0.25", "0.02 1 0 1", "0 0 0 0"})));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    EXPECT_EQ(r.look->color[0], 0.0);
    EXPECT_NEAR(r.look->color[1], 0.21404114048223255, 1e-12);
    EXPECT_EQ(r.look->color[2], 1.0);
    EXPECT_EQ(r.look->color[3], 0.25);
    EXPECT_NEAR(r.look->color[4], 0.02 / 12.92, 1e-15);
    EXPECT_EQ(r.look->color[7], 1.0);
    EXPECT_EQ(r.look->color[11], 0.0);
}

// ushort over 65535 (32768 -> 0.500008 -> just above the value at 0.5), uchar alpha over 255, and the
// diffuse_ spelling; binary little-endian.
TEST(PlyLook, UshortDiffuseSpellingAndBinary) {
    PlyFolder f("ushort");
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nproperty ushort diffuse_red\nproperty ushort diffuse_green\nproperty ushort "
                        "diffuse_blue\nproperty uchar alpha\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&](const void* p, size_t n) { bytes.append(static_cast<const char*>(p), n); };
    const float xyz[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const uint16_t rgb[3][3] = {{0, 32768, 65535}, {65535, 0, 0}, {1000, 2000, 3000}};
    const uint8_t alpha[3] = {255, 51, 0};
    for (int v = 0; v < 3; ++v) {
        put(xyz[v], 12);
        put(rgb[v], 6);
        put(&alpha[v], 1);
    }
    const uint8_t n = 3;
    const int32_t idx[3] = {0, 1, 2};
    put(&n, 1);
    put(idx, 12);
    const Read r = readLook(f.write("t.ply", bytes));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    EXPECT_EQ(r.look->color[0], 0.0);
    EXPECT_NEAR(r.look->color[1], decoded(32768.0 / 65535), 1e-15);
    EXPECT_GT(r.look->color[1], 0.21404114048223255);
    EXPECT_LT(r.look->color[1], 0.2141);
    EXPECT_EQ(r.look->color[2], 1.0);
    EXPECT_EQ(r.look->color[3], 1.0);
    EXPECT_NEAR(r.look->color[7], 0.2, 1e-15);  // 51 / 255
    EXPECT_NEAR(r.look->color[8], 1000.0 / 65535 / 12.92, 1e-15);  // 0.0153: below the knee
    EXPECT_EQ(r.look->color[11], 0.0);
}

TEST(PlyLook, ColoursOutOfRangeAreRefused) {
    PlyFolder f("range");
    const std::pair<std::string, std::string> cases[] = {
        {triangle("property float red\nproperty float green\nproperty float blue\n", {"0 0 0", "1.5 0 0", "0 0 0"}),
         "t.ply: vertex[1].red: 1.5 is not a colour value in [0, 1]"},
        {triangle("property float red\nproperty float green\nproperty float blue\n", {"0 0 0", "0 0 0", "0 0 -0.25"}),
         "t.ply: vertex[2].blue: -0.25 is not a colour value in [0, 1]"},
        {triangle("property char red\nproperty char green\nproperty char blue\n", {"0 -3 0", "0 0 0", "0 0 0"}),
         "t.ply: vertex[0].green: -3 is not a colour value in [0, 127]"},
        {triangle("property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float alpha\n", {"0 0 0 1", "0 0 0 2", "0 0 0 0"}),
         "t.ply: vertex[1].alpha: 2 is not a colour value in [0, 1]"},
        {triangle("property float red\nproperty float green\nproperty float blue\n", {"0 0 0", "0 inf 0", "0 0 0"}),
         "t.ply: vertex[1].green: 'inf' is not a finite number"},
        {triangle("property float s\nproperty float t\n", {"0 0", "0 nan", "0 0"}), "t.ply: vertex[1].t: 'nan' is not a finite number"},
    };
    for (const auto& [text, expected] : cases) {
        const Read r = readLook(f.write("t.ply", text));
        EXPECT_FALSE(r.status.ok) << expected;
        EXPECT_NE(r.status.message.find(expected), std::string::npos) << r.status.message;
        EXPECT_EQ(r.status.message.find('\n'), std::string::npos) << r.status.message;
    }
    // A NaN in a binary float colour (ascii cannot spell one as a number).
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nproperty float red\nproperty float green\nproperty float blue\nelement face 1\n"
                        "property list uchar int vertex_indices\nend_header\n";
    const float rows[3][6] = {{0, 0, 0, 0, 0, 0}, {1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, std::nanf("")}};
    bytes.append(reinterpret_cast<const char*>(rows), sizeof rows);
    const uint8_t n = 3;
    const int32_t idx[3] = {0, 1, 2};
    bytes.append(reinterpret_cast<const char*>(&n), 1);
    bytes.append(reinterpret_cast<const char*>(idx), 12);
    const Read r = readLook(f.write("t.ply", bytes));
    EXPECT_NE(r.status.message.find("t.ply: vertex[2].blue: nan is not a colour value in [0, 1]"), std::string::npos)
        << r.status.message;
}

// Each spelling of the texture coordinates, as glTF's (u, 1 - v).
TEST(PlyLook, TextureCoordinatesOfEachSpelling) {
    PlyFolder f("uv");
    for (const std::string names : {"texture_u texture_v", "s t", "u v"}) {
        const std::string a = names.substr(0, names.find(' ')), b = names.substr(names.find(' ') + 1);
        const Read r = readLook(f.write("t.ply", triangle("property float " + a + "\nproperty float " + b + "\n",
                                                            {"0.25 0.125", "1 0", "0 1"})));
        ASSERT_TRUE(r.status.ok) << r.status.message;
        ASSERT_TRUE(r.look) << names;
        EXPECT_EQ(r.look->texcoord, (std::vector<double>{0.25, 0.875, 1, 1, 0, 0})) << names;
        EXPECT_TRUE(r.look->color.empty());
        EXPECT_TRUE(r.look->images.empty());
        EXPECT_TRUE(r.warnings.lines().empty()) << names;
    }
}

// MeshLab's `comment TextureFile NAME`: the image beside the PLY becomes the material's texture,
// its bytes as they are; outside the folders, missing, not an image, or without texture
// coordinates: one warning and no texture.
TEST(PlyLook, TextureFileIsReadUnderTheLookRules) {
    PlyFolder f("texture");
    const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + "rest of a picture";
    f.write("skin.png", png);
    f.write("notes.png", "not an image");
    const std::string uv = "property float texture_u\nproperty float texture_v\n";
    const std::array<std::string, 3> rows{"0 0", "1 0", "0 1"};
    Read r = readLook(f.write("t.ply", triangle(uv, rows, "comment TextureFile skin.png\ncomment TextureFile other.png\n")));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.look->images.size(), 1u);
    EXPECT_EQ(r.look->images[0].mime_type, "image/png");
    EXPECT_EQ(r.look->images[0].name, "skin.png");
    EXPECT_EQ(std::string(r.look->images[0].bytes.begin(), r.look->images[0].bytes.end()), png);
    ASSERT_EQ(r.look->textures.size(), 1u);
    ASSERT_EQ(r.look->materials.size(), 1u);
    EXPECT_NE(r.look->materials[0].find(R"("baseColorTexture":{"index":0})"), std::string::npos) << r.look->materials[0];
    EXPECT_TRUE(hasLine(r.warnings, "1 more TextureFile comments after header line 3: comment TextureFile ignored")) << r.warnings.lines()[0];
    // Each way the image is not used, with its warning.
    const std::pair<std::string, std::string> cases[] = {
        {triangle(uv, rows, "comment TextureFile ../outside.png\n"), "is outside the folders a mesh may be read from"},
        {triangle(uv, rows, "comment TextureFile missing.png\n"), "missing.png not found"},
        {triangle(uv, rows, "comment TextureFile notes.png\n"), "notes.png is not PNG or JPEG (the texture is dropped)"},
        {triangle("property uchar red\nproperty uchar green\nproperty uchar blue\n", {"1 2 3", "1 2 3", "1 2 3"},
                  "comment TextureFile skin.png\n"),
         "header line 3: comment TextureFile skin.png ignored (no texture coordinates"},
    };
    std::ofstream(f.dir.parent_path() / "outside.png", std::ios::binary) << png;
    MeshLimits limits;
    limits.scene_path = (f.dir / "scene.json").string();
    for (const auto& [text, expected] : cases) {
        r = readLook(f.write("t.ply", text), limits);
        ASSERT_TRUE(r.status.ok) << r.status.message;
        ASSERT_TRUE(r.look);
        EXPECT_TRUE(r.look->images.empty()) << expected;
        EXPECT_EQ(r.look->materials[0].find("baseColorTexture"), std::string::npos);
        EXPECT_TRUE(hasLine(r.warnings, expected)) << expected << "\n" << (r.warnings.lines().empty() ? "" : r.warnings.lines()[0]);
    }    // A FIFO, or an image over the size limit: refused as a mesh file is, one line after the PLY's path.
    ASSERT_EQ(::mkfifo((f.dir / "pipe.png").c_str(), 0600), 0);
    r = readLook(f.write("t.ply", triangle(uv, rows, "comment TextureFile pipe.png\n")));
    EXPECT_NE(r.status.message.find("t.ply: " + (f.dir / "pipe.png").string() + ": is a FIFO, not a regular file (refused)"),
              std::string::npos) << r.status.message;
    limits.max_file_bytes = 400;
    f.write("big.png", png + std::string(500, 'x'));
    r = readLook(f.write("t.ply", triangle(uv, rows, "comment TextureFile big.png\n")), limits);
    EXPECT_NE(r.status.message.find("big.png: 525 bytes, larger than the limit of 400 bytes"), std::string::npos) << r.status.message;
    EXPECT_EQ(r.status.message.rfind((f.dir / "t.ply").string(), 0), 0u) << r.status.message;
}

// Every property not read is named, once per element; other elements in one more line.
TEST(PlyLook, PropertiesNotReadAreNamedOnce) {
    PlyFolder f("ignored");
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
        "property float ny\nproperty float nz\nproperty float quality\nproperty uchar red\nproperty uchar green\n"
        "property uchar blue\nproperty uchar diffuse_red\nproperty uchar diffuse_green\nproperty uchar diffuse_blue\n"
        "element face 1\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nproperty uchar flags\n"
        "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
        "0 0 0 0 0 1 0.5 1 2 3 4 5 6\n1 0 0 0 0 1 0.5 1 2 3 4 5 6\n0 1 0 0 0 1 0.5 1 2 3 4 5 6\n"
        "3 0 1 2 6 0 0 1 0 0 1 7\n0 1\n";
    const Read r = readLook(f.write("t.ply", text));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    EXPECT_EQ(r.warnings.lines(),
              (std::vector<std::string>{
                  "element vertex: properties nx, ny, nz, quality, diffuse_red, diffuse_green, diffuse_blue ignored "
                  "(normals are the apparent surface's own)",
                  "element face: property flags ignored",
                  "element edge ignored (vertex and face are read)"}));
    ASSERT_TRUE(r.look);
    EXPECT_NEAR(r.look->color[0], decoded(1.0 / 255), 1e-15);  // red green blue, the first spelling
}

// Vertices OpenMesh copies (a triangle given twice, once each way round) keep their original's
// colour and texture coordinate.
TEST(PlyLook, LookFollowsOpenMeshCopies) {
    PlyFolder f("copies");
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float s\nproperty float t\n"
        "element face 3\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0 255 0 0 0.25 0.5\n1 0 0 0 0 0 1 0\n0 1 0 0 0 0 0 1\n-1 0 0 0 0 0 1 0\n0 -1 0 0 0 0 0 1\n3 0 1 2\n3 0 3 4\n3 0 4 3\n";
    const Read r = readLook(f.write("t.ply", text));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    EXPECT_GT(r.mesh.positions.size(), 5u) << "OpenMesh copied no vertex: the test does not test the copies";
    ASSERT_EQ(r.look->color.size(), 4 * r.mesh.positions.size());
    ASSERT_EQ(r.look->texcoord.size(), 2 * r.mesh.positions.size());
    EXPECT_EQ(r.look->triangle_material, (std::vector<uint32_t>{0, 0, 0}));
    size_t at_origin = 0;
    for (const auto& t : r.mesh.triangles)
        for (uint32_t v : t)
            if (r.mesh.positions[v].x == 0 && r.mesh.positions[v].y == 0) {
                ++at_origin;
                EXPECT_EQ(r.look->color[4 * v], 1.0);
                EXPECT_EQ(r.look->color[4 * v + 1], 0.0);
                EXPECT_EQ(r.look->texcoord[2 * v], 0.25);
                EXPECT_EQ(r.look->texcoord[2 * v + 1], 0.5);
            }
    EXPECT_EQ(at_origin, 3u);
}

// readMesh keeps the look; a PLY without colours or texture coordinates has none (its outputs as before).
TEST(PlyLook, ReadMeshKeepsTheLookAndPlainFilesHaveNone) {
    PlyFolder f("dispatch");
    LoadedMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readMesh(f.write("t.ply", triangle("property uchar red\nproperty uchar green\nproperty uchar blue\n",
                                                   {"1 2 3", "1 2 3", "1 2 3"})), {}, &m, &w).ok);
    EXPECT_TRUE(m.look);
    LoadedMesh plain;
    ASSERT_TRUE(readMesh(std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/ply/tetra_ascii.ply", {}, &plain, &w).ok);
    EXPECT_FALSE(plain.look);
}

namespace {

using testglb::floats;

}  // namespace

// A coloured tetrahedron (uchar colours) rendered in `instant` at speed 0: every .glb vertex lies at
// an input vertex (the crease split copies vertices, never moves them), and its COLOR_0 is that
// vertex's colour decoded here from sRGB, within float32 rounding.
TEST(PlyLook, RenderAtRestWritesTheLinearColoursVertexForVertex) {
    PlyFolder f("render");
    const double xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const int rgb[4][3] = {{255, 0, 10}, {0, 128, 0}, {7, 200, 255}, {64, 64, 64}};
    std::string text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 4\n"
                       "property list uchar int vertex_indices\nend_header\n";
    for (int v = 0; v < 4; ++v)
        text += std::to_string(xyz[v][0]) + " " + std::to_string(xyz[v][1]) + " " + std::to_string(xyz[v][2]) + " " +
                std::to_string(rgb[v][0]) + " " + std::to_string(rgb[v][1]) + " " + std::to_string(rgb[v][2]) + "\n";
    text += "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    f.write("tetra.ply", text);
    f.write("scene.json", R"({"camera": {"position": [0.3, 0.3, 4], "look_at": [0.3, 0.3, 0], "fov_deg": 60},
        "frames": {"start": 0, "end": 1, "fps": 1}, "model": "instant", "tolerance": "vertex",
        "objects": [{"mesh": "tetra.ply", "position": [0, 0, 0], "velocity": [0, 0, 0]}]})");
    tinygltf::Model model;
    ASSERT_NO_FATAL_FAILURE(renderAtRest(f, &model));
    size_t checked = 0;
    std::set<int> seen;
    for (const tinygltf::Node& node : model.nodes) {
        if (node.mesh < 0) continue;
        std::array<double, 3> origin{0, 0, 0};
        for (size_t k = 0; k < node.translation.size(); ++k) origin[k] = node.translation[k];
        for (const tinygltf::Primitive& prim : model.meshes[size_t(node.mesh)].primitives) {
            ASSERT_TRUE(prim.attributes.count("COLOR_0"));
            const auto pos = floats(model, prim.attributes.at("POSITION"), 3);
            const auto col = floats(model, prim.attributes.at("COLOR_0"), 3);
            ASSERT_EQ(pos.size(), col.size());
            for (size_t i = 0; i < pos.size() / 3; ++i) {
                int found = -1;
                for (int v = 0; v < 4; ++v) {
                    bool same = true;
                    for (int c = 0; c < 3; ++c) same = same && std::fabs(origin[size_t(c)] + pos[3 * i + size_t(c)] - xyz[v][c]) < 1e-6;
                    if (same) found = v;
                }
                ASSERT_GE(found, 0) << "a vertex at no input vertex";
                seen.insert(found);
                for (int c = 0; c < 3; ++c) {
                    const double s = rgb[found][c] / 255.0;
                    const double linear = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
                    EXPECT_NEAR(col[3 * i + size_t(c)], linear, 1e-7) << "vertex " << found << " channel " << c;
                }
                ++checked;
            }
        }
    }
    EXPECT_EQ(seen.size(), 4u);
    EXPECT_GE(checked, 4u);
}

// Third-party files (Debian's assimp-testmodels): VCGLIB's float colours with alpha, and Blender's
// `s t` per vertex, as the files give them.
TEST(PlyLook, ThirdPartyColoursAndTextureCoordinates) {
    const std::string root = "/usr/share/assimp/models/PLY/";
    ASSERT_TRUE(fs::exists(root)) << "install Debian's assimp-testmodels (scripts/setup.sh does)";
    Read r = readLook(root + "float-color.ply");  // every vertex "0 0 1 1"
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    EXPECT_EQ(r.look->color, (std::vector<double>{0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1}));
    r = readLook(root + "cube_uv.ply");
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.look->texcoord.size(), 48u);
    // Vertices 0 to 3 of the file: s t = 0 0, 1 0, 1 1, 0 1.
    EXPECT_EQ(std::vector<double>(r.look->texcoord.begin(), r.look->texcoord.begin() + 8),
              (std::vector<double>{0, 1, 1, 1, 1, 0, 0, 0}));
    EXPECT_TRUE(r.look->color.empty());
}

// The committed fixture (data/fixtures/ply/make_fixtures.py): binary uchar colours with alpha, s t,
// and a TextureFile that is not there.
TEST(PlyLook, BinaryFixtureWithAlphaAndMissingTexture) {
    const Read r = readLook(std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/ply/look_tetra.ply");
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.mesh.positions.size(), 4u);
    EXPECT_EQ(r.look->color[0], 1.0);
    EXPECT_NEAR(r.look->color[2], 10.0 / 255 / 12.92, 1e-15);
    EXPECT_NEAR(r.look->color[5], decoded(128.0 / 255), 1e-15);
    EXPECT_NEAR(r.look->color[7], 128.0 / 255, 1e-15);  // alpha as it is
    EXPECT_EQ(r.look->color[11], 0.0);
    EXPECT_EQ(r.look->texcoord, (std::vector<double>{0, 1, 1, 1, 0, 0, 0.5, 0.5}));
    EXPECT_TRUE(r.look->images.empty());
    EXPECT_TRUE(hasLine(r.warnings, "header line 4: comment TextureFile: texture"));
    EXPECT_TRUE(hasLine(r.warnings, "skin.png not found"));
}

namespace {

// A unit cube whose six quads carry MeshLab's per-corner `texcoord` lists (and uchar colours
// red green blue = 255 x, 255 y, 255 z, so linear colour = position). Vertex i = x + 2y + 4z; face
// f lies on the plane of axis a = f / 2 at coordinate f % 2, wound outwards. Its corners' (u, v) in
// the file, by closed form: u = (2f + p[(a + 1) % 3]) / 16, v = p[(a + 2) % 3], so no two faces
// share a coordinate and each vertex, on three faces, becomes three: 24 vertices.
// `texnumber` (when not empty) is added as an int face property, `comments` to the header.
const int kCubeFace[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};

std::array<double, 2> cubeUv(int f, const double p[3]) {
    const int a = f / 2;
    return {(2 * f + p[(a + 1) % 3]) / 16, p[(a + 2) % 3]};
}

std::string cornerCube(const std::string& comments = "", const std::vector<int>& texnumber = {},
                       const std::string& extra_vertex_props = "") {
    std::string text = "ply\nformat ascii 1.0\n" + comments +
                       "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\n" + extra_vertex_props +
                       "element face 6\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n" +
                       (texnumber.empty() ? "" : "property int texnumber\n") + "end_header\n";
    for (int i = 0; i < 8; ++i) {
        const int x = i & 1, y = (i >> 1) & 1, z = (i >> 2) & 1;
        text += std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + " " + std::to_string(255 * x) + " " +
                std::to_string(255 * y) + " " + std::to_string(255 * z) + (extra_vertex_props.empty() ? "" : " 0.5 0.5") + "\n";
    }
    std::ostringstream rows;
    rows.precision(17);
    for (int f = 0; f < 6; ++f) {
        rows << "4";
        for (int k = 0; k < 4; ++k) rows << " " << kCubeFace[f][k];
        rows << " 8";
        for (int k = 0; k < 4; ++k) {
            const int i = kCubeFace[f][k];
            const double p[3] = {double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)};
            const auto uv = cubeUv(f, p);
            rows << " " << uv[0] << " " << uv[1];
        }
        if (!texnumber.empty()) rows << " " << texnumber[size_t(f)];
        rows << "\n";
    }
    return text + rows.str();
}

}  // namespace

// The cube's corners: 24 vertices (8 + 16 copies, each at its original's position exactly), each
// corner's texcoord the closed form's (u, 1 - v) for its face, its colour its position's.
TEST(PlyLook, CornerTexcoordsSplitTheVerticesAtSeams) {
    PlyFolder f("corner");
    const Read r = readLook(f.write("cube.ply", cornerCube()));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.mesh.positions.size(), 24u);
    ASSERT_EQ(r.mesh.triangles.size(), 12u);
    ASSERT_EQ(r.look->texcoord.size(), 48u);
    ASSERT_EQ(r.look->color.size(), 96u);
    EXPECT_EQ(r.look->triangle_material, std::vector<uint32_t>(12, 0));
    EXPECT_TRUE(hasLine(r.warnings, "16 vertices copied at texture seams")) << r.warnings.lines().size();
    EXPECT_EQ(r.warnings.polygons_triangulated, 6u);
    std::set<uint32_t> used;
    for (size_t t = 0; t < 12; ++t) {
        const int face = int(t / 2);  // a quad's fan: two triangles, in file order
        for (uint32_t v : r.mesh.triangles[t]) {
            used.insert(v);
            const mesh4d::Vec3& q = r.mesh.positions[v];
            const double p[3] = {q.x, q.y, q.z};
            // The position is a corner of this face.
            bool corner = false;
            for (int k = 0; k < 4; ++k) {
                const int i = kCubeFace[face][k];
                corner = corner || (p[0] == (i & 1) && p[1] == ((i >> 1) & 1) && p[2] == ((i >> 2) & 1));
            }
            EXPECT_TRUE(corner) << "triangle " << t << " vertex " << v;
            const auto uv = cubeUv(face, p);
            EXPECT_EQ(r.look->texcoord[2 * v], uv[0]) << "face " << face << " vertex " << v;
            EXPECT_EQ(r.look->texcoord[2 * v + 1], 1 - uv[1]) << "face " << face << " vertex " << v;
            for (int c = 0; c < 3; ++c) EXPECT_EQ(r.look->color[4 * v + size_t(c)], p[c]) << "vertex " << v;
            EXPECT_EQ(r.look->color[4 * v + 3], 1.0);
        }
    }
    EXPECT_EQ(used.size(), 24u);
}

// Two triangles on a square (0 1 2 and 0 2 3) sharing the diagonal 0-2: vertex 2's coordinate agrees
// across it and vertex 0's does not, so by hand 4 + 1 = 5 vertices; the texcoord list written
// before the indices, as doubles behind a ushort count; per-vertex u v given too: the corners win, one warning.
TEST(PlyLook, CornerTexcoordsWinOverPerVertexOnesAndMayComeFirst) {
    PlyFolder f("corner_order");
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
        "property float u\nproperty float v\nelement face 2\nproperty list ushort double texcoord\n"
        "property list uchar uint vertex_indices\nend_header\n"
        "0 0 0 9 9\n1 0 0 9 9\n1 1 0 9 9\n0 1 0 9 9\n"
        "6 0 0 1 0 1 1 3 0 1 2\n"
        "6 0.5 0 1 1 0 1 3 0 2 3\n";
    const Read r = readLook(f.write("sq.ply", text));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.mesh.positions.size(), 5u);
    EXPECT_EQ(r.mesh.positions[4].x, 0.0);
    EXPECT_EQ(r.mesh.positions[4].y, 0.0);
    EXPECT_EQ(r.look->texcoord, (std::vector<double>{0, 1, 1, 1, 1, 0, 0, 0, 0.5, 1}));
    EXPECT_EQ(r.mesh.triangles[1], (std::array<uint32_t, 3>{4, 2, 3}));
    EXPECT_TRUE(r.look->color.empty());
    EXPECT_TRUE(hasLine(r.warnings, "element vertex: per-vertex texture coordinates ignored (the faces' per-corner texcoord lists are read)"));
    EXPECT_TRUE(hasLine(r.warnings, "1 vertices copied at texture seams"));
}

// A list of the wrong length, a value that is not finite (ascii and binary), integer values, and a
// texnumber naming no texture: one line naming the file, the face row and the property.
TEST(PlyLook, CornerTexcoordErrors) {
    PlyFolder f("corner_bad");
    const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 2\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n";
    const std::string verts = "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 0 0 1 0 0 1\n";
    const std::pair<std::string, std::string> cases[] = {
        {head + verts + "3 0 2 1 4 0 0 1 0\n", "face[1].texcoord: 4 values for a face of 3 vertices (a u v pair per vertex: 6)"},
        {head + verts + "3 0 2 1 8 0 0 1 0 0 1 0 0\n", "face[1].texcoord: 8 values for a face of 3 vertices"},
        {head + verts + "3 0 2 1 6 0 0 1 nan 0 1\n", "face[1].texcoord[3]: 'nan' is not a finite number"},
        {head + verts + "3 0 2 1 6 0 0 1 1e39 0 1\n", "face[1].texcoord[3]: '1e39' is not a finite number"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nproperty list uchar int texcoord\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 0 0 1 0 0 1\n",
         "element face: texcoord: values must be of type float or double"},
        {"ply\nformat ascii 1.0\ncomment TextureFile a.png\ncomment TextureFile b.png\nelement vertex 3\nproperty float x\n"
         "property float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\n"
         "property list uchar float texcoord\nproperty int texnumber\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
         "3 0 1 2 6 0 0 1 0 0 1 1\n3 0 2 1 6 0 0 1 0 0 1 2\n",
         "face[1].texnumber: 2 names no texture (2 TextureFile comments; 0 to 1)"},
        {head.substr(0, head.size() - 1) + "\nproperty int texnumber\n" + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 0 0 1 0 0 1 0\n3 0 2 1 6 0 0 1 0 0 1 1\n",
         "face[1].texnumber: 1 names no texture (0 TextureFile comments; 0 to 0)"},
    };
    for (const auto& [text, expected] : cases) {
        const Read r = readLook(f.write("bad.ply", text));
        EXPECT_FALSE(r.status.ok) << expected;
        EXPECT_EQ(r.status.message.rfind((f.dir / "bad.ply").string() + ": " + expected, 0), 0u) << r.status.message;
        EXPECT_EQ(r.status.message.find('\n'), std::string::npos);
    }
    // Binary little-endian: a NaN float among the values.
    std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n";
    auto put = [&](const void* p, size_t n) { bin.append(static_cast<const char*>(p), n); };
    const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    put(xyz, sizeof xyz);
    const unsigned char three = 3, six = 6;
    const int32_t idx[3] = {0, 1, 2};
    put(&three, 1);
    put(idx, sizeof idx);
    put(&six, 1);
    const float uv[6] = {0, 0, 1, std::nanf(""), 0, 1};
    put(uv, sizeof uv);
    const Read r = readLook(f.write("bad.ply", bin));
    EXPECT_EQ(r.status.message, (f.dir / "bad.ply").string() + ": face[0].texcoord[3]: not a finite number within float range (|x| <= 3e38)");
}

// MeshLab's several textures: `texnumber` picks each face's TextureFile, one material (and image)
// per TextureFile, in their order; one texture with every texnumber 0: read as without it.
TEST(PlyLook, TexnumberPicksOneMaterialPerTextureFile) {
    PlyFolder f("texnumber");
    const std::string png_a = std::string("\x89PNG\r\n\x1a\n", 8) + "picture a", png_b = std::string("\x89PNG\r\n\x1a\n", 8) + "picture b";
    f.write("a.png", png_a);
    f.write("b.png", png_b);
    const std::vector<int> texnumber{0, 1, 1, 0, 1, 0};
    Read r = readLook(f.write("cube.ply", cornerCube("comment TextureFile a.png\ncomment TextureFile b.png\n", texnumber)));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.look->materials.size(), 2u);
    ASSERT_EQ(r.look->images.size(), 2u);
    EXPECT_EQ(std::string(r.look->images[0].bytes.begin(), r.look->images[0].bytes.end()), png_a);
    EXPECT_EQ(std::string(r.look->images[1].bytes.begin(), r.look->images[1].bytes.end()), png_b);
    EXPECT_NE(r.look->materials[0].find(R"("baseColorTexture":{"index":0})"), std::string::npos) << r.look->materials[0];
    EXPECT_NE(r.look->materials[1].find(R"("baseColorTexture":{"index":1})"), std::string::npos) << r.look->materials[1];
    EXPECT_EQ(r.look->textures, (std::vector<std::string>{R"({"sampler":0,"source":0})", R"({"sampler":0,"source":1})"}));
    ASSERT_EQ(r.look->triangle_material.size(), 12u);
    for (size_t t = 0; t < 12; ++t) EXPECT_EQ(r.look->triangle_material[t], uint32_t(texnumber[t / 2])) << t;
    EXPECT_FALSE(hasLine(r.warnings, "TextureFile"));
    // One texture, texnumber all 0: as the file without texnumber, silently.
    r = readLook(f.write("cube.ply", cornerCube("comment TextureFile a.png\n", std::vector<int>(6, 0))));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_EQ(r.look->materials.size(), 1u);
    ASSERT_EQ(r.look->images.size(), 1u);
    EXPECT_EQ(r.look->triangle_material, std::vector<uint32_t>(12, 0));
    EXPECT_EQ(r.warnings.lines(), (std::vector<std::string>{"6 polygons triangulated",
                                                             "16 vertices copied at texture seams (a vertex with more than one texcoord)"}));
    // Several TextureFile comments without texnumber: the first alone, one warning.
    r = readLook(f.write("cube.ply", cornerCube("comment TextureFile a.png\ncomment TextureFile b.png\n")));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_EQ(r.look->materials.size(), 1u);
    ASSERT_EQ(r.look->images.size(), 1u);
    EXPECT_TRUE(hasLine(r.warnings, "1 more TextureFile comments after header line 3: comment TextureFile ignored (one texture per PLY is read without a face texnumber)"));
}

namespace {

std::vector<uint32_t> indices(const tinygltf::Model& model, int accessor) {
    const tinygltf::Accessor& a = model.accessors[size_t(accessor)];
    const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
    const unsigned char* at = model.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
    std::vector<uint32_t> out(a.count);
    for (size_t i = 0; i < a.count; ++i) {
        if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) std::memcpy(&out[i], at + 4 * i, 4);
        else if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            uint16_t s;
            std::memcpy(&s, at + 2 * i, 2);
            out[i] = s;
        } else out[i] = at[i];
    }
    return out;
}

}  // namespace

// The corner-textured cube rendered in `instant` at speed 0: each .glb triangle lies on one face of
// the cube (the face found from its corners' positions), and each of its corners' TEXCOORD_0 is
// the closed form's (u, 1 - v) for that face and position, within float32 rounding.
TEST(PlyLook, RenderAtRestWritesTheCornerTexcoordsVertexForVertex) {
    PlyFolder f("corner_render");
    f.write("cube.ply", cornerCube());
    f.write("scene.json", R"({"camera": {"position": [0.5, 0.5, 4], "look_at": [0.5, 0.5, 0], "fov_deg": 60},
        "frames": {"start": 0, "end": 1, "fps": 1}, "model": "instant", "tolerance": "vertex",
        "objects": [{"mesh": "cube.ply", "position": [0, 0, 0], "velocity": [0, 0, 0]}]})");
    tinygltf::Model model;
    ASSERT_NO_FATAL_FAILURE(renderAtRest(f, &model));
    size_t checked = 0;
    std::set<int> faces;
    for (const tinygltf::Node& node : model.nodes) {
        if (node.mesh < 0) continue;
        std::array<double, 3> origin{0, 0, 0};
        for (size_t k = 0; k < node.translation.size(); ++k) origin[k] = node.translation[k];
        for (const tinygltf::Primitive& prim : model.meshes[size_t(node.mesh)].primitives) {
            ASSERT_TRUE(prim.attributes.count("TEXCOORD_0"));
            ASSERT_GE(prim.indices, 0);
            const auto pos = floats(model, prim.attributes.at("POSITION"), 3);
            const auto uv = floats(model, prim.attributes.at("TEXCOORD_0"), 2);
            const auto tri = indices(model, prim.indices);
            ASSERT_EQ(pos.size() / 3, uv.size() / 2);
            for (size_t t = 0; t + 2 < tri.size(); t += 3) {
                double p[3][3];
                for (int c = 0; c < 3; ++c)
                    for (int k = 0; k < 3; ++k) p[c][k] = std::round(origin[size_t(k)] + pos[3 * tri[t + size_t(c)] + size_t(k)]);
                int face = -1;
                for (int a = 0; a < 3; ++a)
                    if (p[0][a] == p[1][a] && p[1][a] == p[2][a]) face = 2 * a + int(p[0][a]);
                ASSERT_GE(face, 0) << "a triangle on no face of the cube";
                faces.insert(face);
                for (int c = 0; c < 3; ++c) {
                    const size_t v = tri[t + size_t(c)];
                    for (int k = 0; k < 3; ++k) ASSERT_NEAR(origin[size_t(k)] + pos[3 * v + size_t(k)], p[c][k], 1e-6);
                    const auto expected = cubeUv(face, p[c]);
                    EXPECT_NEAR(uv[2 * v], expected[0], 1e-7) << "face " << face;
                    EXPECT_NEAR(uv[2 * v + 1], 1 - expected[1], 1e-7) << "face " << face;
                    ++checked;
                }
            }
        }
    }
    EXPECT_EQ(faces.size(), 6u);
    EXPECT_GE(checked, 36u);
}

// The committed fixture (data/fixtures/ply/make_fixtures.py): binary per-corner coordinates, corner
// k of every face at (k == 1, k == 2). By hand over the faces (0 2 1), (0 1 3), (0 3 2), (1 2 3):
// vertex 0 always corner 0 (one coordinate), vertex 1 at corners 2, 1, 0 (three), vertex 2 at
// 1, 2, 1 (two), vertex 3 at 2, 1, 2 (two): 8 vertices. texnumber f % 2 over two missing images:
// two materials without texture, one warning each.
TEST(PlyLook, BinaryCornerFixtureWithTexnumber) {
    const Read r = readLook(std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/ply/corner_tetra.ply");
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    EXPECT_EQ(r.mesh.positions.size(), 8u);
    ASSERT_EQ(r.look->texcoord.size(), 16u);
    EXPECT_EQ(r.look->color.size(), 32u);
    EXPECT_EQ(r.look->texcoord[0], 0.0);  // vertex 0: (0, 0), flipped
    EXPECT_EQ(r.look->texcoord[1], 1.0);
    EXPECT_EQ(r.look->materials.size(), 2u);
    EXPECT_TRUE(r.look->images.empty());
    EXPECT_EQ(r.look->triangle_material, (std::vector<uint32_t>{0, 1, 0, 1}));
    EXPECT_TRUE(hasLine(r.warnings, "a.png not found"));
    EXPECT_TRUE(hasLine(r.warnings, "b.png not found"));
    EXPECT_TRUE(hasLine(r.warnings, "4 vertices copied at texture seams"));
}

// A quad whose last fan triangle (0 2 3) a triangle before it already holds: OpenMesh keeps the
// quad's first fan triangle and adds the whole quad again on copies, 4 triangles for 3 scanned (a
// fuzz_ply finding: the look then read past the scanned triangles). Every vertex keeps the texture
// coordinate of its position, here s t = x y.
TEST(PlyLook, LookFollowsAPolygonOpenMeshAddsTwice) {
    PlyFolder f("added_twice");
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "property float s\nproperty float t\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n3 0 2 3\n4 0 1 2 3\n";
    const Read r = readLook(f.write("t.ply", text));
    ASSERT_TRUE(r.status.ok) << r.status.message;
    ASSERT_TRUE(r.look);
    ASSERT_EQ(r.mesh.triangles.size(), 4u) << "OpenMesh did not add the quad twice: the test does not test it";
    ASSERT_EQ(r.look->texcoord.size(), 2 * r.mesh.positions.size());
    for (const auto& t : r.mesh.triangles)
        for (uint32_t v : t) {
            EXPECT_EQ(r.look->texcoord[2 * v], r.mesh.positions[v].x) << v;
            EXPECT_EQ(r.look->texcoord[2 * v + 1], 1 - r.mesh.positions[v].y) << v;
        }
    EXPECT_EQ(r.look->triangle_material, std::vector<uint32_t>(4, 0));
}
