// The PLY and OBJ frame writers, serialized in parallel blocks: the same bytes on 1 and 2 threads,
// and the values read back independently (absolute lab positions and times, faces with the
// objects' vertex offsets, triangles with a repeated corner left out). The lone .glb frame
// likewise: the same bytes on 1 and 2 threads, and POSITION's bounds (found in the parallel
// float32 conversion) those of the float32 values read back from its BIN chunk. Whole files
// (writeWhole, the lone .glb frame's write): the pieces' bytes in order, past the page cache or not,
// and through it where the file system refuses the direct writes (EINVAL).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <charconv>
#include <random>
#include <sstream>

#include <tbb/task_arena.h>

#include <nlohmann/json.hpp>

#include "exporters/atomic_file.h"
#include "exporters/frame_files.h"
#include "exporters/gltf.h"
#include "exporters/obj.h"
#include "exporters/ply.h"
#include "file_bytes.h"
#include "file_size_limit.h"
#include "temp_dir.h"

using namespace apparent;
namespace fs = std::filesystem;

namespace {

// Two objects, large enough for several blocks of each writer, with degenerate triangles.
ExportFrame testFrame() {
    ExportFrame frame;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int o = 0; o < 2; ++o) {
        mesh4d::ApparentMesh m;
        const uint32_t n = o == 0 ? 150'000 : 1'000;
        m.origin = {1e6 * (o + 1), -3.25, 0.5};
        m.time_origin = -2e6 * (o + 1);
        for (uint32_t i = 0; i < n; ++i) {
            m.positions.push_back({u(rng), u(rng), u(rng)});
            m.emission_times.push_back(u(rng));
        }
        for (uint32_t i = 0; i + 2 < n; ++i)
            m.triangles.push_back(i % 97 == 0 ? std::array<uint32_t, 3>{i, i, i + 1} : std::array<uint32_t, 3>{i, i + 2, i + 1});
        frame.objects.push_back(std::move(m));
    }
    return frame;
}

std::string writeOn(int threads, bool ply, const ExportFrame& frame, const fs::path& file) {
    tbb::task_arena arena(threads);
    std::string error;
    bool ok = false;
    arena.execute([&] {
        ok = ply ? writePly(file.string(), frame, SequenceInfo{}, &error) : writeObj(file.string(), frame, SequenceInfo{}, &error);
    });
    EXPECT_TRUE(ok) << error;
    return testio::readBytes(file);
}

}  // namespace

// The frame files' camera time without std::to_chars for doubles (the WebAssembly build's libc++ has
// none): the same text as std::to_chars's plain form, on edge cases, frame times k / fps and random
// bit patterns (one wrong digit, a missing exponent zero or the wrong form on a tie fails).
TEST(FrameExport, ShortestDecimalByPrintfIsToCharsPlainForm) {
    auto toChars = [](double v) {
        char buffer[32];
        return std::string(buffer, std::to_chars(buffer, buffer + sizeof(buffer), v).ptr);
    };
    std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 0.1, 1e-5, 1e-4, 1e16, 1e15, 123456789.0, 1e21, 1e22, 5e-324,
                                  1.7976931348623157e308, 2.2250738585072014e-308, 0.3, 1.0 / 3.0, 100000.0, 1234567.0,
                                  0.000123, 9.5367431640625e-07, 4.35, 2.5e-3, 1e100, -7.25e-12};
    for (int k = 0; k < 2000; ++k) values.push_back(k / 30.0), values.push_back(-5.0 + k / 24.0), values.push_back(std::ldexp(1.0, k - 1000));
    std::mt19937_64 random(31);
    while (values.size() < 100000) {
        const uint64_t bits = random();
        double v;
        std::memcpy(&v, &bits, 8);
        if (std::isfinite(v)) values.push_back(v);
    }
    size_t wrong = 0;
    for (double v : values)
        if (shortestDecimalByPrintf(v) != toChars(v) && ++wrong <= 5)
            ADD_FAILURE() << toChars(v) << " written as " << shortestDecimalByPrintf(v);
    EXPECT_EQ(wrong, 0u) << "of " << values.size();
}

TEST(FrameExport, PlyAndObjBytesDoNotDependOnTheThreadCount) {
    const fs::path dir = testio::tempPath() / ("apparent_frame_export_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const ExportFrame frame = testFrame();
    for (bool ply : {true, false}) {
        const std::string one = writeOn(1, ply, frame, dir / (ply ? "a.ply" : "a.obj"));
        const std::string two = writeOn(2, ply, frame, dir / (ply ? "b.ply" : "b.obj"));
        EXPECT_EQ(one, two) << (ply ? "PLY" : "OBJ");
    }
    fs::remove_all(dir);
}

TEST(FrameExport, PlyHoldsAbsoluteValuesAndOffsetFaces) {
    const fs::path dir = testio::tempPath() / ("apparent_frame_export_v_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const ExportFrame frame = testFrame();
    const std::string bytes = writeOn(2, true, frame, dir / "f.ply");
    const size_t body = bytes.find("end_header\n") + 11;
    size_t kept = 0, vertices = 0;
    for (const auto& o : frame.objects) {
        vertices += o.positions.size();
        for (const auto& t : o.triangles) kept += t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    }
    EXPECT_NE(bytes.find("element vertex " + std::to_string(vertices) + "\n"), std::string::npos);
    EXPECT_NE(bytes.find("element face " + std::to_string(kept) + "\n"), std::string::npos);
    // x y z quality (double), then the object index (uchar: 2 objects).
    ASSERT_NE(bytes.find("property double quality\nproperty uchar object\n"), std::string::npos);
    ASSERT_EQ(bytes.size(), body + 33 * vertices + 13 * kept);
    // Little-endian doubles on this (x86-64) host: compared with origin + local, computed here.
    size_t v = 0;
    for (size_t o_index = 0; o_index < frame.objects.size(); ++o_index) {
        const auto& o = frame.objects[o_index];
        for (size_t i = 0; i < o.positions.size(); ++i, ++v) {
            double d[4];
            std::memcpy(d, bytes.data() + body + 33 * v, 32);
            ASSERT_EQ(bytes[body + 33 * v + 32], char(o_index));
            ASSERT_EQ(d[0], o.origin.x + o.positions[i].x);
            ASSERT_EQ(d[1], o.origin.y + o.positions[i].y);
            ASSERT_EQ(d[2], o.origin.z + o.positions[i].z);
            ASSERT_EQ(d[3], o.time_origin + o.emission_times[i]);
        }
    }
    // The last face: the second object's last triangle, its indices offset by the first's vertices.
    const auto& last = frame.objects[1].triangles.back();
    int32_t idx[3];
    ASSERT_EQ(bytes[bytes.size() - 13], char(3));
    std::memcpy(idx, bytes.data() + bytes.size() - 12, 12);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(uint32_t(idx[c]), last[c] + frame.objects[0].positions.size());
    fs::remove_all(dir);
}

TEST(FrameExport, GlbFrameBoundsAreThoseOfItsFloatPositions) {
    const ExportFrame frame = testFrame();
    SequenceInfo info;
    info.model = "relativistic";
    info.fps = 10;
    info.objects.resize(2);
    info.objects[0].name = "a";
    info.objects[1].name = "b";
    info.objects[1].base_color = {0.5, 0.5, 0.5, 1};
    const fs::path dir = testio::tempPath() / ("apparent_glb_bounds_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::string bytes[2];
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        std::string error;
        bool ok = false;
        const fs::path file = dir / ("t" + std::to_string(threads) + ".glb");
        arena.execute([&] { ok = writeAnimatedGlb(file.string(), {frame}, info, {}, nullptr, &error); });
        ASSERT_TRUE(ok) << error;
        bytes[threads - 1] = testio::readBytes(file);
    }
    fs::remove_all(dir);
    EXPECT_TRUE(bytes[0] == bytes[1]);
    // The chunks (glTF 2.0, section 4.4): 12-byte header, JSON chunk, BIN chunk.
    const std::string& glb = bytes[0];
    ASSERT_GT(glb.size(), 28u);
    uint32_t json_length = 0, bin_length = 0;
    std::memcpy(&json_length, glb.data() + 12, 4);
    ASSERT_LE(20 + size_t(json_length) + 8, glb.size());
    std::memcpy(&bin_length, glb.data() + 20 + json_length, 4);
    const char* bin = glb.data() + 28 + json_length;
    ASSERT_EQ(28 + size_t(json_length) + bin_length, glb.size());
    const nlohmann::json json = nlohmann::json::parse(glb.substr(20, json_length));
    size_t checked = 0;
    for (const auto& mesh : json.at("meshes"))
        for (const auto& prim : mesh.at("primitives")) {
            const auto& accessor = json.at("accessors").at(prim.at("attributes").at("POSITION").get<size_t>());
            const auto& view = json.at("bufferViews").at(accessor.at("bufferView").get<size_t>());
            const size_t count = accessor.at("count"), offset = view.value("byteOffset", size_t(0));
            ASSERT_LE(offset + 12 * count, size_t(bin_length));
            double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (size_t i = 0; i < 3 * count; ++i) {
                float f = 0;
                std::memcpy(&f, bin + offset + 4 * i, 4);
                lo[i % 3] = std::min(lo[i % 3], double(f));
                hi[i % 3] = std::max(hi[i % 3], double(f));
            }
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(accessor.at("min")[c].get<double>(), lo[c]) << c;
                EXPECT_EQ(accessor.at("max")[c].get<double>(), hi[c]) << c;
            }
            ++checked;
        }
    EXPECT_EQ(checked, 2u);  // both objects
}

// writeWhole gives the file exactly its pieces' bytes in order: below kDirectLeast (buffered) and
// above it (in kDirectChunk chunks through a page-aligned buffer, O_DIRECT where the file system
// takes it), with empty pieces, pieces across chunk boundaries and a length that is no whole
// number of pages; and a write that fails (RLIMIT_FSIZE: EFBIG, as a full disk gives ENOSPC) says
// so, with the bytes written up to the limit.
TEST(FrameExport, WriteWholeWritesThePiecesInOrder) {
    const fs::path dir = testio::tempPath() / ("apparent_write_whole_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::mt19937_64 rng(5);
    auto bytes = [&](size_t n) {
        std::string b(n, '\0');
        for (char& c : b) c = char(rng());
        return b;
    };
    const std::vector<std::vector<size_t>> cases = {
        {5, 0, 1000},
        {0, 1, 4093, kDirectChunk - 4094 + 7, 3, 0, kDirectChunk + 12345, 17},
        {kDirectLeast},
        {kDirectChunk, kDirectChunk},
    };
    int k = 0;
    for (const auto& sizes : cases) {
        std::vector<std::string> pieces;
        std::string expected;
        for (size_t n : sizes) {
            pieces.push_back(bytes(n));
            expected += pieces.back();
        }
        std::vector<iovec> iov;
        for (std::string& p : pieces) iov.push_back({p.data(), p.size()});
        const fs::path file = dir / ("whole" + std::to_string(k++) + ".bin");
        const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
        ASSERT_GE(fd, 0);
        std::string error;
        EXPECT_TRUE(writeWhole(fd, iov.data(), iov.size(), &error)) << error;
        EXPECT_EQ(::fsync(fd), 0);
        ::close(fd);
        EXPECT_EQ(fs::file_size(file), expected.size()) << k;
        EXPECT_TRUE(testio::readBytes(file) == expected) << k;
    }

    constexpr size_t kLimit = 3 * 4096;
    std::string big = bytes(kDirectLeast + 100), error;
    const iovec one{big.data(), big.size()};
    const int fd = ::open((dir / "limited.bin").c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    size_t written = 0;
    bool ok = false;
    {
        const testio::FileSizeLimit limit(kLimit);
        ASSERT_TRUE(limit.ok());
        ok = writeWhole(fd, &one, 1, &error, &written);
    }
    ::close(fd);
    EXPECT_FALSE(ok);
    EXPECT_EQ(error, std::strerror(EFBIG));
    EXPECT_EQ(written, kLimit);  // up to the limit, then refused
    fs::remove_all(dir);
}

// The fallback where O_DIRECT writes are refused (EINVAL, atomic_file.h writeWhole): the staging
// buffer placed 1 byte past a page boundary (detail::writeWholeStaged, the seam), which a file
// system that checks O_DIRECT's memory alignment refuses. That it refuses is checked first with a
// direct write of our own (where it does not, tmpfs for one, the test is skipped: the fallback
// cannot be reached there). Then the file holds exactly its pieces' bytes, the same as the direct
// write's file, and went through the page cache (mincore: every page of it resident) where the
// direct write's left none there: the refused writes were made again buffered.
TEST(FrameExport, WriteWholeFallsBackWhereDirectWritesAreRefused) {
    const fs::path dir = testio::tempPath() / ("apparent_write_fallback_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    {
        const int probe = ::open((dir / "probe.bin").c_str(), O_RDWR | O_CREAT | O_TRUNC | O_DIRECT, 0644);
        void* page = nullptr;
        ASSERT_EQ(::posix_memalign(&page, 4096, 2 * 4096), 0);
        const bool refused = probe >= 0 && ::pwrite(probe, static_cast<char*>(page) + 1, 4096, 0) < 0 && errno == EINVAL;
        std::free(page);
        if (probe >= 0) ::close(probe);
        if (!refused) {
            fs::remove_all(dir);
            GTEST_SKIP() << dir << ": its file system takes O_DIRECT writes from any address (or no O_DIRECT at "
                         << "all): the EINVAL fallback cannot be reached here";
        }
    }
    std::mt19937_64 rng(11);
    std::vector<std::string> pieces;
    std::string expected;
    for (const size_t n : {size_t(4093), kDirectChunk - 4093 + 5, size_t(0), kDirectLeast + 12345}) {
        std::string b(n, '\0');
        for (char& c : b) c = char(rng());
        pieces.push_back(b);
        expected += b;
    }
    std::vector<iovec> iov;
    for (std::string& p : pieces) iov.push_back({p.data(), p.size()});
    // Pages of `file` in the page cache.
    auto resident = [](const fs::path& file) {
        const int fd = ::open(file.c_str(), O_RDONLY);
        const size_t n = size_t(fs::file_size(file));
        void* map = ::mmap(nullptr, n, PROT_READ, MAP_SHARED, fd, 0);
        std::vector<unsigned char> in((n + 4095) / 4096);
        size_t count = 0;
        if (map != MAP_FAILED && ::mincore(map, n, in.data()) == 0)
            for (const unsigned char c : in) count += c & 1;
        if (map != MAP_FAILED) ::munmap(map, n);
        ::close(fd);
        return count;
    };
    const size_t pages = (expected.size() + 4095) / 4096;
    for (const size_t offset : {size_t(0), size_t(1)}) {
        const fs::path file = dir / ("staged" + std::to_string(offset) + ".bin");
        const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
        ASSERT_GE(fd, 0);
        std::string error;
        size_t written = 0;
        EXPECT_TRUE(detail::writeWholeStaged(fd, iov.data(), iov.size(), offset, &error, &written)) << error;
        EXPECT_EQ(written, expected.size());
        EXPECT_EQ(::fcntl(fd, F_GETFL) & O_DIRECT, 0);  // the descriptor's flags as they were
        EXPECT_EQ(::fsync(fd), 0);
        ::close(fd);
        EXPECT_EQ(resident(file), offset == 0 ? 0 : pages) << "offset " << offset;
        EXPECT_EQ(fs::file_size(file), expected.size());
        EXPECT_TRUE(testio::readBytes(file) == expected) << "offset " << offset;
    }
    fs::remove_all(dir);
}
