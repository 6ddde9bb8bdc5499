// PLY reading by our own scan: ascii and binary files load, our exporter's
// per-frame PLY reads back, third-party files load or are refused with one line, malformed files
// name the element, row and property, and no truncated prefix crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "exporters/ply.h"
#include "pipeline/input/mesh_check.h"
#include "pipeline/input/mesh_input.h"
#include "pipeline/input/ply_reader.h"
#include "file_bytes.h"
#include "temp_dir.h"

using namespace apparent;
namespace fs = std::filesystem;

namespace {

std::string fixture(const std::string& name) { return std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/ply/" + name; }

Status read(const std::string& path, mesh4d::RestMesh* m, MeshWarnings* w, const MeshLimits& limits = {}) {
    return readPly(path, limits, m, w);
}

}  // namespace

TEST(PlyReader, TetrahedronInEveryEncoding) {
    for (const char* name : {"tetra_ascii.ply", "tetra_binary.ply", "tetra_big_endian.ply"}) {
        mesh4d::RestMesh m;
        MeshWarnings w;
        const Status st = read(fixture(name), &m, &w);
        ASSERT_TRUE(st.ok) << st.message;
        EXPECT_EQ(m.positions.size(), 4u) << name;
        EXPECT_EQ(m.triangles.size(), 4u) << name;
        EXPECT_TRUE(w.lines().empty()) << name;
        EXPECT_DOUBLE_EQ(m.positions[3].z, 1.0) << name;
        const Topology t = analyzeTopology(m.positions, m.triangles);
        EXPECT_TRUE(t.closed) << name;
        EXPECT_EQ(t.genus, 0) << name;
    }
}

TEST(PlyReader, ReadMeshDispatchesOnTheExtension) {
    LoadedMesh m;
    MeshWarnings w;
    ASSERT_TRUE(readMesh(fixture("tetra_binary.ply"), {}, &m, &w).ok);
    EXPECT_EQ(m.mesh.triangles.size(), 4u);
    const Status st = readMesh(fixture("tetra_binary.stl"), {}, &m, &w);
    EXPECT_NE(st.message.find("use .obj, .ply, .gltf or .glb"), std::string::npos) << st.message;
}

TEST(PlyReader, PolygonsAndDegenerateFacesAreCounted) {
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(read(fixture("quad.ply"), &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(w.polygons_triangulated, 1u);
    MeshWarnings w2;
    ASSERT_TRUE(read(fixture("degenerate.ply"), &m, &w2).ok);
    EXPECT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(w2.degenerate_dropped, 1u);
}

// Our own exporter's PLY (binary, double x y z quality and the object index) must read back vertex
// for vertex, as one object: the `object` property ignored with its warning, `quality` named in another.
TEST(PlyReader, ExporterOutputReadsBack) {
    ExportFrame frame;
    mesh4d::ApparentMesh a;
    a.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {5, 5, 5}};
    a.emission_times = {0, 1, 2, 3, 4};
    a.rest_points = a.positions;
    a.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    frame.objects.push_back(a);
    mesh4d::ApparentMesh b;
    b.positions = {{10, 0, 0}, {11, 0, 0}, {10, 1, 0}};
    b.emission_times = {5, 6, 7};
    b.rest_points = b.positions;
    b.triangles = {{0, 1, 2}};
    frame.objects.push_back(b);
    const fs::path dir = testio::tempPath() / ("apparent_ply_rt_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string path = (dir / "frame.ply").string();
    std::string error;
    ASSERT_TRUE(writePly(path, frame, SequenceInfo{}, &error)) << error;
    mesh4d::RestMesh m;
    MeshWarnings w;
    const Status st = read(path, &m, &w);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(m.positions.size(), 8u);
    EXPECT_EQ(m.triangles.size(), 5u);
    EXPECT_DOUBLE_EQ(m.positions[5].x, 10.0);
    EXPECT_DOUBLE_EQ(m.positions[3].z, 2.0);
    ASSERT_EQ(w.other.size(), 2u);
    EXPECT_NE(w.other[0].find("element vertex: property 'object' ignored"), std::string::npos) << w.other[0];
    EXPECT_EQ(w.other[1], "element vertex: property quality ignored");
    fs::remove_all(dir);
}

TEST(PlyReader, MalformedFilesNameTheField) {
    const std::pair<const char*, const char*> cases[] = {
        {"bad_index.ply", "bad_index.ply: face[1].vertex_indices[2]: index 9 is out of range (4 vertices)"},
        {"bad_number.ply", "bad_number.ply: vertex[1].y: 'nan' is not a finite number"},
        {"huge_count.ply", "huge_count.ply: element vertex: 4000000000 vertices, more than the limit of 10000000"},
        {"no_z.ply", "no_z.ply: element vertex: no scalar property 'z'"},
        {"no_faces.ply", "no_faces.ply: header: no 'element face'"},
        {"truncated.ply", "truncated.ply: face[3].vertex_indices[1]: the file ends early"},
        {"bad_format.ply", "bad_format.ply: header line 2: format: unknown format 'binary_middle_endian'"},
        {"two_vertex_face.ply", "two_vertex_face.ply: face[1].vertex_indices: a face needs at least 3 vertices, got 2"},
        {"float_indices.ply", "float_indices.ply: element face: vertex_indices: indices must be of an integer type"},
        {"does_not_exist.ply", "cannot open mesh file"},
    };
    for (const auto& [file, expected] : cases) {
        mesh4d::RestMesh m;
        MeshWarnings w;
        const Status st = read(fixture(file), &m, &w);
        EXPECT_FALSE(st.ok) << file;
        EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
        EXPECT_EQ(st.message.find('\n'), std::string::npos) << st.message;
    }
}

TEST(PlyReader, CountsAreCheckedAgainstLimitsAndFileSize) {
    mesh4d::RestMesh m;
    MeshWarnings w;
    MeshLimits limits;
    limits.max_vertices = 3;
    Status st = read(fixture("tetra_ascii.ply"), &m, &w, limits);
    EXPECT_NE(st.message.find("4 vertices, more than the limit of 3 (raise with --max-vertices)"), std::string::npos) << st.message;
    limits = {};
    limits.max_faces = 3;
    st = read(fixture("tetra_ascii.ply"), &m, &w, limits);
    EXPECT_NE(st.message.find("4 faces, more than the limit of 3 (raise with --max-faces)"), std::string::npos) << st.message;
    limits = {};
    limits.max_file_bytes = 100;
    st = read(fixture("tetra_ascii.ply"), &m, &w, limits);
    EXPECT_NE(st.message.find("larger than the limit of 100 bytes (raise with --max-file-bytes)"), std::string::npos) << st.message;
    // Within the limits, but more rows than the file could hold: refused before anything is allocated.
    limits = {};
    limits.max_vertices = size_t(1) << 40;
    st = read(fixture("huge_count.ply"), &m, &w, limits);
    EXPECT_NE(st.message.find("element vertex: 4000000000 rows need at least 12 bytes each, more than the file holds"),
              std::string::npos) << st.message;
}

// Debian's assimp-testmodels PLY files: each loads with triangles or is refused with one line.
TEST(PlyReader, ThirdPartyFilesImportOrAreRefusedClearly) {
    const fs::path root = "/usr/share/assimp/models";
    ASSERT_TRUE(fs::exists(root)) << "install Debian's assimp-testmodels (scripts/setup.sh does)";
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(root))
        if (e.path().extension() == ".ply") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    ASSERT_GE(files.size(), 8u);
    size_t loaded = 0;
    for (const auto& f : files) {
        mesh4d::RestMesh m;
        MeshWarnings w;
        const Status st = read(f.string(), &m, &w);
        if (st.ok) {
            ++loaded;
            EXPECT_FALSE(m.triangles.empty()) << f;
        } else {
            EXPECT_EQ(st.message.rfind(f.string(), 0), 0u) << st.message;
            EXPECT_EQ(st.message.find('\n'), std::string::npos) << st.message;
        }
    }
    std::printf("PLY corpus: %zu files, %zu imported\n", files.size(), loaded);
    EXPECT_GE(loaded, 4u);
    mesh4d::RestMesh m;
    MeshWarnings w;
    ASSERT_TRUE(read((root / "PLY/cube_binary.ply").string(), &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 12u);
    ASSERT_TRUE(read((root / "PLY/cube.ply").string(), &m, &w).ok);
    EXPECT_EQ(m.triangles.size(), 12u);  // six quads
    EXPECT_NE(read((root / "PLY/points.ply").string(), &m, &w).message.find("no 'element face'"), std::string::npos);
}

// Every truncated prefix of a binary and an ascii file either loads or fails with a message.
TEST(PlyReader, TruncatedPrefixesNeverCrash) {
    const fs::path dir = testio::tempPath() / ("apparent_ply_trunc_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string path = (dir / "prefix.ply").string();
    for (const char* name : {"tetra_binary.ply", "tetra_ascii.ply"}) {
        const std::string bytes = testio::readBytes(fixture(name));
        size_t loaded = 0;
        for (size_t n = 0; n <= bytes.size(); ++n) {
            std::ofstream(path, std::ios::binary) << bytes.substr(0, n);
            mesh4d::RestMesh m;
            MeshWarnings w;
            const Status st = read(path, &m, &w);
            if (!st.ok) {
                EXPECT_FALSE(st.message.empty()) << n;
            } else {
                ++loaded;
                EXPECT_FALSE(m.triangles.empty()) << n;
            }
        }
        EXPECT_GE(loaded, 1u) << name;
    }
    fs::remove_all(dir);
}
