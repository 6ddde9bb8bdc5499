// glTF import through tinygltf: real third-party files (the Khronos samples in tests/data and the
// glTF files of Debian's assimp-testmodels) import or are refused with a reason, never crash;
// expected counts come from the files' own documentation (SOURCES.md) and accessor bounds.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <cstring>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/commands/cli.h"
#include "pipeline/input/gltf_document.h"
#include "pipeline/input/mesh_input.h"
#include "temp_dir.h"

using namespace apparent;
namespace fs = std::filesystem;

namespace {

std::string fixture(const std::string& name) { return std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/gltf/" + name; }
const fs::path kSamples = fs::path(APPARENT_SOURCE_DIR) / "tests/data/gltf-samples";
const fs::path kAssimp = "/usr/share/assimp/models/glTF2";

Status load(const std::string& path, LoadedMesh* m, MeshWarnings* w = nullptr) {
    MeshWarnings local;
    return readMesh(path, {}, m, w ? w : &local);
}

}  // namespace

// Triangle counts from tests/data/gltf-samples/SOURCES.md ("drawn in default scene").
TEST(GltfReader, KhronosSamplesGiveTheirDocumentedTriangleCounts) {
    ASSERT_TRUE(fs::exists(kSamples)) << kSamples;
    const std::pair<const char*, size_t> expected[] = {
        {"Box.gltf", 12}, {"BoxVertexColors.gltf", 12}, {"AnimatedTriangle.gltf", 1}, {"Cameras.gltf", 2},
        {"SimpleMeshes.gltf", 2}, {"TriangleWithoutIndices.gltf", 1}, {"Triangle.gltf", 1},
        {"SimpleSparseAccessor.gltf", 12}, {"SimpleMorph.gltf", 1}, {"MultipleScenes.gltf", 2},
        {"BoxAnimated.gltf", 254}};
    for (const auto& [file, triangles] : expected) {
        LoadedMesh m;
        const Status st = load((kSamples / file).string(), &m);
        ASSERT_TRUE(st.ok) << st.message;
        EXPECT_EQ(m.mesh.triangles.size(), triangles) << file;
    }
}

// The sparse sample substitutes three positions; the accessor's declared min/max (written by the
// file's author) describe the substituted data, and the loaded bounds must match them.
TEST(GltfReader, SparseAccessorSubstitutionsAreApplied) {
    const std::string path = (kSamples / "SimpleSparseAccessor.gltf").string();
    std::ifstream in(path);
    const nlohmann::json j = nlohmann::json::parse(in);
    const auto& acc = j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>()];
    ASSERT_TRUE(acc.contains("sparse"));
    LoadedMesh m;
    ASSERT_TRUE(load(path, &m).ok);
    for (int c = 0; c < 3; ++c) {
        double lo = INFINITY, hi = -INFINITY;
        for (const auto& p : m.mesh.positions) { lo = std::min(lo, p[c]); hi = std::max(hi, p[c]); }
        EXPECT_NEAR(lo, acc["min"][c].get<double>(), 1e-6) << c;
        EXPECT_NEAR(hi, acc["max"][c].get<double>(), 1e-6) << c;
    }
}

// Every .gltf/.glb of the samples and of assimp-testmodels (many deliberately broken) imports or
// is refused with a one-line reason naming the file; none crashes. Known-broken ones must fail.
TEST(GltfReader, EveryThirdPartyFileImportsOrIsRefusedClearly) {
    ASSERT_TRUE(fs::exists(kAssimp)) << "install Debian's assimp-testmodels (scripts/setup.sh does)";
    std::vector<fs::path> files;
    for (const auto& dir : {kSamples, kAssimp})
        for (const auto& e : fs::recursive_directory_iterator(dir))
            if (e.path().extension() == ".gltf" || e.path().extension() == ".glb") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    ASSERT_GE(files.size(), 50u);
    size_t loaded = 0, refused = 0;
    for (const auto& f : files) {
        LoadedMesh m;
        const Status st = load(f.string(), &m);
        if (st.ok) {
            ++loaded;
            EXPECT_FALSE(m.mesh.triangles.empty()) << f;
            for (const auto& p : m.mesh.positions) ASSERT_TRUE(mesh4d::isFinite(p)) << f;
        } else {
            ++refused;
            EXPECT_EQ(st.message.rfind(f.string(), 0), 0u) << st.message;
            EXPECT_EQ(st.message.find('\n'), std::string::npos) << st.message;
        }
    }
    std::printf("glTF corpus: %zu files, %zu imported, %zu refused\n", files.size(), loaded, refused);
    const std::pair<const char*, const char*> broken[] = {
        {"IndexOutOfRange/IndexOutOfRange.gltf", "index 255 out of range (24 vertices)"},
        {"IndexOutOfRange/AllIndicesOutOfRange.gltf", "out of range"},
        {"RecursiveNodes/RecursiveNodes.gltf", "cycle"},
        {"MissingBin/BoxTextured.gltf", "File not found"},
        {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "is not finite"},
        {"IncorrectVertexArrays/Cube.gltf", "not a multiple of 3"},
    };
    for (const auto& [file, reason] : broken) {
        LoadedMesh m;
        const Status st = load((kAssimp / file).string(), &m);
        EXPECT_FALSE(st.ok) << file;
        EXPECT_NE(st.message.find(reason), std::string::npos) << st.message;
    }
}

// Strips and fans are triangulated (n - 2 triangles for n indices), points and lines skipped;
// both are counted. Modes per file are read from the files themselves.
TEST(GltfReader, PrimitiveModes) {
    const fs::path dir = kAssimp / "glTF-Asset-Generator/Mesh_PrimitiveMode";
    int strips_or_fans = 0, lines_or_points = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".gltf") continue;
        std::ifstream in(e.path());
        const nlohmann::json j = nlohmann::json::parse(in);
        const int mode = j["meshes"][0]["primitives"][0].value("mode", 4);
        LoadedMesh m;
        MeshWarnings w;
        const Status st = load(e.path().string(), &m, &w);
        if (mode <= 3) {
            EXPECT_FALSE(st.ok) << e.path();
            EXPECT_EQ(w.points_lines_skipped, 1u) << e.path();
            ++lines_or_points;
        } else {
            ASSERT_TRUE(st.ok) << st.message;
            if (mode != 4) {
                EXPECT_EQ(w.strips_fans_triangulated, 1u) << e.path();
                ++strips_or_fans;
            }
        }
    }
    EXPECT_GT(strips_or_fans, 0);
    EXPECT_GT(lines_or_points, 0);
}

// Debian's package has 2CylinderEngine plain (.glb) and Draco-compressed (.gltf): both import,
// with the same triangle count and bounding boxes equal to Draco's quantization.
TEST(GltfReader, DracoPrimitivesDecodeLikeThePlainFile) {
    LoadedMesh plain, draco;
    ASSERT_TRUE(load((kAssimp / "2CylinderEngine-glTF-Binary/2CylinderEngine.glb").string(), &plain).ok);
    const Status st = load((kAssimp / "draco/2CylinderEngine.gltf").string(), &draco);
    ASSERT_TRUE(st.ok) << st.message;
    // Draco's encoder drops degenerate faces that the plain file keeps and that survive our
    // exact collinearity test (near-zero area): allow 0.1 % of the count.
    const double nt = double(plain.mesh.triangles.size());
    EXPECT_NEAR(double(draco.mesh.triangles.size()), nt, 1e-3 * nt);
    double extent = 0;
    for (int c = 0; c < 3; ++c) {
        double plo = INFINITY, phi = -INFINITY, dlo = INFINITY, dhi = -INFINITY;
        for (const auto& p : plain.mesh.positions) { plo = std::min(plo, p[c]); phi = std::max(phi, p[c]); }
        for (const auto& p : draco.mesh.positions) { dlo = std::min(dlo, p[c]); dhi = std::max(dhi, p[c]); }
        extent = std::max(extent, phi - plo);
        EXPECT_NEAR(dlo, plo, 1e-3 * (phi - plo)) << c;
        EXPECT_NEAR(dhi, phi, 1e-3 * (phi - plo)) << c;
    }
    EXPECT_GT(extent, 0);
    // Read again, the file is neither parsed nor Draco-decoded again (gltf_document.h): the
    // document comes from the cache, with the same result.
    const size_t parses = gltfParseCount();
    LoadedMesh again;
    ASSERT_TRUE(load((kAssimp / "draco/2CylinderEngine.gltf").string(), &again).ok);
    EXPECT_EQ(gltfParseCount(), parses);
    EXPECT_EQ(again.mesh.positions, draco.mesh.positions);
    EXPECT_EQ(again.mesh.triangles, draco.mesh.triangles);
}

TEST(GltfReader, NodeTransformsAndNodeSelection) {
    LoadedMesh m;
    ASSERT_TRUE(load(fixture("triangle.gltf"), &m).ok);
    ASSERT_EQ(m.mesh.positions.size(), 3u);
    EXPECT_EQ(m.mesh.positions[1], (mesh4d::Vec3{11, 0, 0}));  // node translation applied

    ASSERT_TRUE(load(fixture("two_nodes.gltf"), &m).ok);
    EXPECT_EQ(m.mesh.triangles.size(), 2u);
    EXPECT_EQ(m.mesh.positions[1], (mesh4d::Vec3{96, 0, 0}));   // root (100) + left (-5) + 1
    EXPECT_EQ(m.mesh.positions[4], (mesh4d::Vec3{104, 0, 0}));  // root + right (5) - 1 (mirrored)
    // The mirrored copy keeps an outward winding: its normal points the same way (+z).
    auto normalZ = [&](const std::array<uint32_t, 3>& t) {
        return mesh4d::cross(m.mesh.positions[t[1]] - m.mesh.positions[t[0]], m.mesh.positions[t[2]] - m.mesh.positions[t[0]]).z;
    };
    EXPECT_GT(normalZ(m.mesh.triangles[0]), 0);
    EXPECT_GT(normalZ(m.mesh.triangles[1]), 0);

    // Interleaved POSITION/NORMAL (byteStride 24): positions read from every 24th byte.
    ASSERT_TRUE(load(fixture("interleaved.gltf"), &m).ok);
    ASSERT_EQ(m.mesh.positions.size(), 3u);
    EXPECT_EQ(m.mesh.positions[2], (mesh4d::Vec3{10, 1, 0}));

    // "#right": that node's subtree in its own frame, without its or its ancestors' transforms.
    ASSERT_TRUE(load(fixture("two_nodes.gltf") + "#right", &m).ok);
    EXPECT_EQ(m.mesh.triangles.size(), 1u);
    EXPECT_EQ(m.mesh.positions[1], (mesh4d::Vec3{1, 0, 0}));
    const Status st = load(fixture("two_nodes.gltf") + "#nobody", &m);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("no node named 'nobody'"), std::string::npos) << st.message;
}

TEST(GltfReader, HostileFilesAreRefusedWithTheField) {
    const std::pair<const char*, const char*> cases[] = {
        {"escape_parent.gltf", "buffers[0].uri: '../../x.bin' leaves the glTF file's folder (refused)"},
        {"escape_absolute.gltf", "buffers[0].uri: '/etc/hostname' is not a relative path"},
        {"missing_bin.gltf", "File not found"},
        {"accessor_overflow.gltf", "accessors[0]: count 1000 with byteOffset 0 reaches past bufferViews[0]"},
        {"absurd_count.gltf", "accessors[0]"},
        {"int_position.gltf", "accessors[0].componentType: POSITION must be FLOAT, got UNSIGNED_SHORT"},
        {"view_overflow.gltf", "bufferViews[0]"},
        {"draco_bad_view.gltf", "KHR_draco_mesh_compression.bufferView: 99 out of range"},
    };
    for (const auto& [file, expected] : cases) {
        LoadedMesh m;
        const Status st = load(fixture(file), &m);
        EXPECT_FALSE(st.ok) << file;
        EXPECT_NE(st.message.find(expected), std::string::npos) << file << ": " << st.message;
        EXPECT_NE(st.message.find(file), std::string::npos) << st.message;
    }
}

// Every truncated prefix of a real .glb either loads or fails with a message; none crashes.
TEST(GltfReader, TruncatedGlbPrefixesNeverCrash) {
    const fs::path src = kAssimp / "BoxTextured-glTF-Binary/BoxTextured.glb";
    std::ifstream in(src, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GT(bytes.size(), 100u);
    const fs::path dir = testio::tempPath() / ("apparent_glb_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string path = (dir / "prefix.glb").string();
    for (size_t n = 0; n < bytes.size(); n += std::max<size_t>(1, bytes.size() / 300)) {
        std::ofstream(path, std::ios::binary) << bytes.substr(0, n);
        LoadedMesh m;
        const Status st = load(path, &m);
        EXPECT_FALSE(st.ok) << n;  // a strict prefix is never a valid GLB (its length field says more)
        EXPECT_FALSE(st.message.empty());
    }
    fs::remove_all(dir);
}

namespace {
// Rewrites a GLB's JSON chunk with `edit` and keeps its BIN chunk (glTF 2.0 section 4.4).
std::string editGlbJson(const std::string& glb, const std::function<void(nlohmann::json&)>& edit) {
    uint32_t json_len;
    std::memcpy(&json_len, glb.data() + 12, 4);
    nlohmann::json j = nlohmann::json::parse(glb.substr(20, json_len));
    edit(j);
    std::string text = j.dump();
    while (text.size() % 4) text += ' ';
    const std::string bin = glb.substr(20 + json_len);
    std::string out(12, '\0');
    const uint32_t header[3] = {0x46546C67u, 2u, uint32_t(12 + 8 + text.size() + bin.size())};
    std::memcpy(out.data(), header, 12);
    const uint32_t chunk[2] = {uint32_t(text.size()), 0x4E4F534Au};
    out.append(reinterpret_cast<const char*>(chunk), 8);
    return out + text + bin;
}
}  // namespace

// tinygltf 2.7 dereferences the Draco attribute named by each id without checking it exists:
// a file listing an id its payload lacks must be refused before tinygltf sees it.
TEST(GltfReader, DracoAttributeIdMissingFromThePayloadIsRefused) {
    const fs::path dir = testio::tempPath() / ("apparent_draco_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string scene = std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/scene_tetra.json";
    const char* argv[] = {"apparent", "render", scene.c_str(), "--out", dir.c_str(), "--draco", "--frames", "0:1",
                          "--tolerance", "vertex", "--quiet"};
    std::ostringstream o, e;
    ASSERT_EQ(apparent::runCommandLine(11, argv, o, e), 0) << e.str();
    std::ifstream in(dir / "relativistic.glb", std::ios::binary);
    const std::string glb((std::istreambuf_iterator<char>(in)), {});
    LoadedMesh m;
    ASSERT_TRUE(load((dir / "relativistic.glb").string(), &m).ok);  // the unedited file loads
    const std::string bad = editGlbJson(glb, [](nlohmann::json& j) {
        auto& prim = j["meshes"][0]["primitives"][0];
        // A fourth attribute whose Draco id (3) the payload (ids 0, 1, 2) does not have.
        prim["attributes"]["TEXCOORD_0"] = prim["attributes"]["NORMAL"];
        prim["extensions"]["KHR_draco_mesh_compression"]["attributes"]["TEXCOORD_0"] = 3;
    });
    std::ofstream(dir / "bad.glb", std::ios::binary) << bad;
    const Status st = load((dir / "bad.glb").string(), &m);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("attributes.TEXCOORD_0: Draco attribute id 3 is not in the payload"), std::string::npos)
        << st.message;
    fs::remove_all(dir);
}

// tinygltf 2.7 passes an image's bufferView to the image loader without checking its range: a view
// that reaches past its buffer (past the BIN chunk, or past the buffer's declared byteLength inside
// it) is refused with the image and the view named, before tinygltf reads it.
TEST(GltfReader, ImageViewsPastTheirBufferAreRefused) {
    const fs::path dir = testio::tempPath() / ("apparent_image_view_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ifstream in(kAssimp / "BoxTextured-glTF-Binary/BoxTextured.glb", std::ios::binary);
    const std::string glb((std::istreambuf_iterator<char>(in)), {});
    const std::pair<std::function<void(nlohmann::json&)>, const char*> cases[] = {
        {[](nlohmann::json& j) { j["bufferViews"][3]["byteLength"] = 1000000; },
         "images[0].bufferView: bufferViews[3] (byteOffset 840, byteLength 1000000) reaches past buffers[0] (3273 bytes)"},
        {[](nlohmann::json& j) { j["buffers"][0]["byteLength"] = 900; },
         "images[0].bufferView: bufferViews[3] (byteOffset 840, byteLength 2433) reaches past buffers[0] (900 bytes)"},
        {[](nlohmann::json& j) { j["images"][0]["bufferView"] = 7; }, "images[0].bufferView: 7 out of range (4 bufferViews)"},
        {[](nlohmann::json& j) { j["bufferViews"][3]["byteOffset"] = -5; },
         "bufferViews[3]: byteOffset and byteLength must be integers from 0 to 2^53"},
    };
    for (const auto& [edit, expected] : cases) {
        std::ofstream(dir / "bad.glb", std::ios::binary) << editGlbJson(glb, edit);
        LoadedMesh m;
        const Status st = load((dir / "bad.glb").string(), &m);
        EXPECT_FALSE(st.ok) << expected;
        EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    }
    LoadedMesh m;
    std::ofstream(dir / "good.glb", std::ios::binary) << editGlbJson(glb, [](nlohmann::json&) {});
    EXPECT_TRUE(load((dir / "good.glb").string(), &m).ok);  // the unedited JSON loads
    fs::remove_all(dir);
}

// A .gltf whose texture is a file beside it (assimp-testmodels' BoxTexcoords: one PNG, two texture
// coordinate sets, the metallic-roughness texture read through TEXCOORD_1): the image's bytes are
// the file's, both sets are kept, and nothing is dropped.
TEST(GltfReader, ExternalImagesAreReadBesideTheFile) {
    const fs::path dir = kAssimp / "BoxTexcoords-glTF";
    LoadedMesh m;
    MeshWarnings w;
    const Status st = load((dir / "boxTexcoords.gltf").string(), &m, &w);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_TRUE(m.look);
    ASSERT_EQ(m.look->images.size(), 1u);
    std::ifstream png(dir / "texture.png", std::ios::binary);
    const std::vector<unsigned char> want((std::istreambuf_iterator<char>(png)), std::istreambuf_iterator<char>());
    EXPECT_EQ(m.look->images[0].bytes, want);
    EXPECT_EQ(m.look->images[0].mime_type, "image/png");
    EXPECT_EQ(m.look->texcoord.size(), 2 * m.mesh.positions.size());
    EXPECT_EQ(m.look->texcoord1.size(), 2 * m.mesh.positions.size());
    ASSERT_EQ(m.look->materials.size(), 1u);
    EXPECT_NE(m.look->materials[0].find("\"metallicRoughnessTexture\":{\"index\":0,\"texCoord\":1}"), std::string::npos)
        << m.look->materials[0];
    for (const std::string& line : w.lines()) ADD_FAILURE() << "unexpected warning: " << line;
}

// An image URI that leaves the glTF file's folder is refused with its path named, as a buffer's is:
// textually ("../", absolute) before anything is read, and a symlink out of the folder once resolved.
TEST(GltfReader, ImageUrisStayInTheFilesFolder) {
    const fs::path dir = testio::tempPath() / ("apparent_gltf_images_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "model");
    const fs::path src = kAssimp / "BoxTexcoords-glTF";
    fs::copy_file(src / "boxTexcoords.bin", dir / "model/boxTexcoords.bin");
    fs::copy_file(src / "texture.png", dir / "texture.png");
    std::ifstream in(src / "boxTexcoords.gltf");
    nlohmann::json j = nlohmann::json::parse(in);
    auto write = [&](const std::string& uri) {
        j["images"][0]["uri"] = uri;
        std::ofstream(dir / "model/box.gltf") << j.dump();
        LoadedMesh m;
        return load((dir / "model/box.gltf").string(), &m);
    };
    Status st = write("../texture.png");
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("images[0].uri: '../texture.png' leaves the glTF file's folder (refused)"), std::string::npos)
        << st.message;
    st = write((dir / "texture.png").string());
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("images[0].uri: '" + (dir / "texture.png").string() + "' is not a relative path"),
              std::string::npos)
        << st.message;
    fs::create_symlink(dir / "texture.png", dir / "model/link.png");
    st = write("link.png");
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("images: URI"), std::string::npos) << st.message;
    EXPECT_NE(st.message.find("link.png' is outside the glTF file's folder (refused)"), std::string::npos) << st.message;
    // Inside the folder: read.
    fs::copy_file(dir / "texture.png", dir / "model/texture.png");
    LoadedMesh m;
    st = write("texture.png");
    ASSERT_TRUE(st.ok) << st.message;
    fs::remove_all(dir);
}

// Two primitives of one mesh that read the same POSITION accessor (a unit square, two materials
// meeting along its diagonal, as the web file writes a mesh whose materials share vertices) read
// its 4 vertices once: the triangles of both index them, and each keeps its material.
//   3 ---- 2
//   |  1 / |     triangle (0, 1, 2): material 0; triangle (0, 2, 3): material 1
//   | / 0  |
//   0 ---- 1
TEST(GltfReader, PrimitivesSharingTheirVertexAccessorsShareTheVertices) {
    const float square[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::string bytes((const char*)square, sizeof(square));
    bytes.append((const char*)indices, sizeof(indices));
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string uri = "data:application/octet-stream;base64,";
    for (size_t i = 0; i < bytes.size(); i += 3) {  // 60 bytes: no padding
        const uint32_t n = (uint32_t((unsigned char)bytes[i]) << 16) | (uint32_t((unsigned char)bytes[i + 1]) << 8) |
                           uint32_t((unsigned char)bytes[i + 2]);
        for (int s = 18; s >= 0; s -= 6) uri += digits[(n >> s) & 63];
    }
    const nlohmann::json g = {
        {"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}}, {"nodes", {{{"mesh", 0}}}},
        {"materials", {{{"name", "a"}}, {{"name", "b"}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}, {"material", 0}},
                                     {{"attributes", {{"POSITION", 0}}}, {"indices", 2}, {"material", 1}}}}}}},
        {"buffers", {{{"byteLength", 60}, {"uri", uri}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}}, {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 12}}}},
        {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {0, 0, 0}}, {"max", {1, 1, 0}}},
                       {{"bufferView", 1}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}},
                       {{"bufferView", 1}, {"byteOffset", 6}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}}};
    const fs::path file = testio::tempPath() / "shared_vertices.gltf";
    std::ofstream(file) << g.dump();
    LoadedMesh m;
    const Status st = load(file.string(), &m);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(m.mesh.positions.size(), 4u);
    EXPECT_EQ(m.mesh.positions[2], (mesh4d::Vec3{1, 1, 0}));
    ASSERT_EQ(m.mesh.triangles.size(), 2u);
    EXPECT_EQ(m.mesh.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(m.mesh.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
    ASSERT_TRUE(m.look);
    EXPECT_EQ(m.look->triangle_material, (std::vector<uint32_t>{0, 1}));
    fs::remove(file);
}
