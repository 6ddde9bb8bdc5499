// Frames by reference (exporters/frame_spill.h): a .glb sequence whose frames go through
// GlbSequenceWriter::encode with a frame spill installed, then addEncoded, is byte-identical to the
// same frames added directly, for plain, meshopt and Draco frames, with index lists shared between
// frames in whole, in part (one object of two: meshopt's partly shared stream) and not at all; the
// descriptions that travel are a small fraction of the data, also for meshopt frames that are
// morph targets of the frame before (each encoded against the previous frame, as a rank that cut
// it again does), with the previous frame's normals in their own stream or in the records; a
// target without the previous frame, or a description naming an unknown source, is refused with
// a message. PLY frames written by the rank that cut them (exporters/frame_files.h)
// are renamed into place byte-identical to frames added directly, a replaced or planted temporary
// is refused, and what was not taken is removed; on SIGTERM the writer removes every rank's
// temporary of the run in the registered folders, and nothing else.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "exporters/atomic_file.h"
#include "exporters/frame_files.h"
#include "exporters/frame_spill.h"
#include "exporters/gltf.h"
#include "exporters/ply.h"
#include "file_bytes.h"
#include "temp_dir.h"

using namespace apparent;
namespace fs = std::filesystem;

namespace {

// A wavy n x n grid; `flip` cuts each quad along the other diagonal (another index list).
mesh4d::ApparentMesh grid(int n, double phase, bool flip, double x0) {
    mesh4d::ApparentMesh m;
    m.origin = {x0, 0.0, -5.0};
    m.time_origin = -5.0;
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
            const double x = double(i) / n, y = double(j) / n;
            m.positions.push_back({x, y, 0.1 * std::sin(6 * x + phase) * std::cos(5 * y)});
            m.emission_times.push_back(-x);
            m.doppler.push_back(1 + 0.1 * x);
            m.proper_time.push_back(y);
        }
    auto at = [n](int i, int j) { return uint32_t(i * (n + 1) + j); };
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            if (flip) {
                m.triangles.push_back({a, b, d});
                m.triangles.push_back({b, c, d});
            } else {
                m.triangles.push_back({a, b, c});
                m.triangles.push_back({a, c, d});
            }
        }
    return m;
}

// Six frames of two objects: object 0 keeps its index list (shared from frame 1 on), object 1
// changes it every second frame and is hidden in frame 4.
std::vector<ExportFrame> frames() {
    std::vector<ExportFrame> out;
    for (int k = 0; k < 6; ++k) {
        ExportFrame f;
        f.index = 10 + k;
        f.t_c = 0.1 * k;
        f.objects.push_back(grid(40, 0.3 * k, false, -1.5));
        f.objects.push_back(k == 4 ? mesh4d::ApparentMesh() : grid(30, -0.2 * k, (k / 2) % 2 == 1, 0.5));
        out.push_back(std::move(f));
    }
    return out;
}

SequenceInfo info() {
    SequenceInfo s;
    s.model = "relativistic";
    s.tolerance = 1e-3;
    s.fps = 10;
    s.objects.resize(2);
    s.objects[0].name = "left";
    s.objects[1].name = "right";
    return s;
}

struct Written {
    std::string bytes;
    size_t descriptions = 0;  // bytes of the encoded frames (by reference: what reaches the writer)
};

// Frames by reference are encoded against the frame before (`with_previous`), as the frame loop
// does under MPI.
Written write(const fs::path& file, const GlbOptions& options, bool by_reference,
              const std::vector<ExportFrame>& sequence = frames(), const SequenceInfo& sequence_info = info(),
              bool with_previous = true) {
    Written w;
    std::string error;
    int spill = -1;
    if (by_reference) {
        spill = openAnonymousFile(file.parent_path().string(), &error);
        EXPECT_GE(spill, 0) << error;
        installFrameSpill(spill, 7);
        addFrameSource(7, ::dup(spill));
    }
    GlbSequenceWriter writer(file.string(), sequence_info, options);
    for (size_t k = 0; k < sequence.size(); ++k) {
        const ExportFrame& f = sequence[k];
        if (!by_reference) {
            EXPECT_TRUE(writer.add(f, &error)) << error;
            continue;
        }
        const bool previous = with_previous && k > 0;
        const std::string description = writer.encode(f, *writer.prepare(f), previous ? &sequence[k - 1] : nullptr);
        w.descriptions += description.size();
        EXPECT_TRUE(writer.addEncoded(description, &error)) << error;
    }
    GlbStats stats;
    EXPECT_TRUE(writer.finish(&stats, &error)) << error;
    if (by_reference) {
        installFrameSpill(-1, -1);  // the process's other tests encode frames whole
        ::close(spill);
    }
    w.bytes = testio::readBytes(file);
    return w;
}

class FrameSpill : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = testio::tempPath() / ("apparent_frame_spill_" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path dir_;
};

}  // namespace

TEST_F(FrameSpill, ByReferenceIsByteIdenticalForEveryCodec) {
    for (const char* codec : {"plain", "meshopt", "draco"}) {
        GlbOptions options;
        options.doppler = options.proper_time = true;
        options.meshopt = std::string(codec) == "meshopt";
        options.draco = std::string(codec) == "draco";
        const Written direct = write(dir_ / "direct.glb", options, false);
        const Written by_reference = write(dir_ / "by_reference.glb", options, true);
        ASSERT_GT(direct.bytes.size(), 100000u) << codec;
        EXPECT_TRUE(direct.bytes == by_reference.bytes) << codec << ": the files differ";
        // What travels to the writer: counts, bounds, hashes and spans (under 700 bytes per
        // object whatever its size), not the frames' data (38 to 100 KiB per frame here).
        EXPECT_LT(by_reference.descriptions, 8u * 1024u) << codec;
    }
    // Meshopt frames without attributes may be morph targets of the frame before (frame
    // coherence): by reference too, and the file is still the same.
    GlbOptions options;
    options.meshopt = true;
    const Written direct = write(dir_ / "direct.glb", options, false);
    const Written by_reference = write(dir_ / "by_reference.glb", options, true);
    ASSERT_GT(direct.bytes.size(), 10000u);
    EXPECT_TRUE(direct.bytes == by_reference.bytes) << "meshopt without attributes: the files differ";
    EXPECT_LT(by_reference.descriptions, 8u * 1024u) << "meshopt without attributes";
}

namespace {

// Twenty frames of one slowly waving grid (one index list): frame coherence makes runs of morph
// targets. `n` sets the grid's size: a small grid keeps its normals in the records, a large one
// in a stream of their own (gltf.h), which the first target of a run differs from.
std::vector<ExportFrame> waving(int n) {
    std::vector<ExportFrame> out;
    for (int k = 0; k < 20; ++k) {
        ExportFrame f;
        f.index = k;
        f.t_c = 0.1 * k;
        f.objects.push_back(grid(n, 0.02 * k, false, -0.5));
        out.push_back(std::move(f));
    }
    return out;
}

SequenceInfo oneObject() {
    SequenceInfo s = info();
    s.objects.resize(1);
    return s;
}

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

}  // namespace

TEST_F(FrameSpill, MorphTargetsByReferenceAreByteIdentical) {
    GlbOptions options;
    options.meshopt = true;
    for (const int n : {12, 150}) {
        const Written direct = write(dir_ / "direct.glb", options, false, waving(n), oneObject());
        const Written by_reference = write(dir_ / "by_reference.glb", options, true, waving(n), oneObject());
        // The sequence has runs (a target's "weights"), so the targets were taken from the descriptions.
        EXPECT_GE(count(direct.bytes, "\"targets\""), 1u) << n;
        EXPECT_TRUE(direct.bytes == by_reference.bytes) << n << ": the files differ";
        // Whether the normals had a stream of their own (the form the first target picks).
        EXPECT_EQ(count(direct.bytes, "OCTAHEDRAL") > 0, n == 150) << n;
        EXPECT_LT(by_reference.descriptions, 20u * 1024u) << n;
    }
}

TEST_F(FrameSpill, AMorphTargetWithoutThePreviousFrameIsRefused) {
    GlbOptions options;
    options.meshopt = true;
    std::string error;
    const int spill = openAnonymousFile(dir_.string(), &error);
    ASSERT_GE(spill, 0) << error;
    installFrameSpill(spill, 7);
    addFrameSource(7, ::dup(spill));
    GlbSequenceWriter writer((dir_ / "refused.glb").string(), oneObject(), options);
    const std::vector<ExportFrame> sequence = waving(12);
    bool refused = false;
    for (size_t k = 0; k < 2 && !refused; ++k)
        refused = !writer.addEncoded(writer.encode(sequence[k], *writer.prepare(sequence[k])), &error);
    installFrameSpill(-1, -1);
    ::close(spill);
    EXPECT_TRUE(refused);
    EXPECT_NE(error.find("internal: frame 1 by reference without its morph target"), std::string::npos) << error;
}

TEST_F(FrameSpill, ADescriptionOfAnUnknownSourceIsRefused) {
    std::string error;
    const int spill = openAnonymousFile(dir_.string(), &error);
    ASSERT_GE(spill, 0) << error;
    installFrameSpill(spill, 3);  // the writer knows no source 3
    GlbSequenceWriter writer((dir_ / "refused.glb").string(), info(), GlbOptions());
    const ExportFrame f = frames().front();
    const std::string description = writer.encode(f, *writer.prepare(f));
    installFrameSpill(-1, -1);
    ::close(spill);
    EXPECT_FALSE(writer.addEncoded(description, &error));
    EXPECT_NE(error.find("refused.glb: frame data from another process is malformed (frame 10)"), std::string::npos)
        << error;
}

// PLY frames written by the rank that cut them (exporters/frame_files.h): the rank writes the file
// under the run's temporary name just before sending, a few bytes travel, and the writer renames
// it into place: the same files, byte for byte, as frames added directly, and nothing else left.
// A temporary replaced after the rank wrote it is refused; a name planted where the rank would
// write is never written through (the rank's message reaches the writer); dropEncoded() removes
// what was not taken.
TEST_F(FrameSpill, FrameFilesWrittenByTheirRankAreRenamedInPlace) {
    std::string error;
    const SequenceInfo seq = info();
    const fs::path direct = dir_ / "direct", ranks = dir_ / "ranks";
    {
        auto sink = plySink(direct.string());
        ASSERT_TRUE(sink->begin(seq, &error)) << error;
        for (const ExportFrame& f : frames()) {
            std::vector<std::string> completed;
            ASSERT_TRUE(sink->add(f, sink->prepare(f).get(), &completed, &error)) << error;
        }
    }
    const int spill = openAnonymousFile(dir_.string(), &error);
    ASSERT_GE(spill, 0) << error;
    installFrameSpill(spill, 1);
    setFrameRunToken("0123456789abcdef");
    auto sink = plySink(ranks.string());
    ASSERT_TRUE(sink->beginEncoding(seq, &error)) << error;  // the rank makes the folder it writes into
    size_t travelled = 0;
    for (const ExportFrame& f : frames()) {
        EncodedOutput e = sink->encode(f, sink->prepare(f).get());
        sink->beforeSending(f.index, &e);
        travelled += e.bytes.size();
        std::vector<std::string> completed;
        ASSERT_TRUE(sink->addEncoded(f.index, e, &completed, &error)) << error;
        ASSERT_EQ(completed.size(), 1u);
        EXPECT_EQ(fs::path(completed[0]).filename().string(), "frame_000" + std::to_string(f.index) + ".ply");
    }
    EXPECT_LT(travelled, 6u * 64u);  // 24 bytes per frame, not the frames' 40 to 80 KiB
    size_t files = 0;
    for (const auto& entry : fs::directory_iterator(direct)) {
        ++files;
        EXPECT_TRUE(testio::readBytes(entry.path()) == testio::readBytes(ranks / entry.path().filename())) << entry.path();
    }
    EXPECT_EQ(files, 6u);
    EXPECT_EQ(size_t(std::distance(fs::directory_iterator(ranks), fs::directory_iterator())), 6u) << "a temporary left";

    // A temporary replaced between the rank's write and the rename: refused, nothing renamed.
    ExportFrame f = frames().front();
    f.index = 20;
    EncodedOutput e = sink->encode(f, sink->prepare(f).get());
    sink->beforeSending(20, &e);
    const fs::path temp = ranks / ".frame_00020.tmp-0123456789abcdef.ply";
    ASSERT_TRUE(fs::exists(temp));
    fs::remove(temp);
    std::ofstream(temp) << "not the frame";
    std::vector<std::string> completed;
    EXPECT_FALSE(sink->addEncoded(20, e, &completed, &error));
    EXPECT_EQ(error, (ranks / "frame_00020.ply").string() + ": the temporary file " + temp.string() +
                         " was replaced while writing (not renamed into place)");
    EXPECT_FALSE(fs::exists(ranks / "frame_00020.ply"));
    // A name planted where the rank writes frame 21: not written through; the rank's line arrives.
    const fs::path planted = ranks / ".frame_00021.tmp-0123456789abcdef.ply";
    std::ofstream(planted) << "planted";
    f.index = 21;
    e = sink->encode(f, sink->prepare(f).get());
    sink->beforeSending(21, &e);
    EXPECT_EQ(testio::readBytes(planted), "planted");
    EXPECT_FALSE(sink->addEncoded(21, e, &completed, &error));
    EXPECT_EQ(error.rfind((ranks / "frame_00021.ply").string() + ": cannot create " + planted.string() + ": ", 0), 0u)
        << error;
    // The run failed: what the ranks left for frames it did not take goes.
    sink->dropEncoded(10, 30);
    EXPECT_FALSE(fs::exists(temp));
    EXPECT_FALSE(fs::exists(planted));
    EXPECT_EQ(size_t(std::distance(fs::directory_iterator(ranks), fs::directory_iterator())), 6u);
    sink.reset();
    installFrameSpill(-1, -1);
    setFrameRunToken("");
    ::close(spill);
}

// Rank 0's interrupt cleanup of the ranks' frame files (removeFrameTemporariesOnInterrupt): a
// process with the run's folders registered and the usual cleanup installed, ended by SIGTERM,
// removes every ".frame_*.tmp-TOKEN.*" in them, as many as there are (here 100, more than the
// cleanup's 64 slots of single names), whichever rank's and extension, and exits 143 as the usual
// cleanup does; final frames, another run's temporaries, other hidden files and the folders not
// registered are untouched.
TEST_F(FrameSpill, AnInterruptRemovesEveryRanksFrameFilesOfTheRun) {
    const std::string token = "0123456789abcdef";
    const fs::path a = dir_ / "relativistic", b = dir_ / "instant", apart = dir_ / "finite";
    for (const fs::path& d : {a, b, apart}) fs::create_directories(d);
    auto touch = [](const fs::path& p) { std::ofstream(p) << "bytes"; };
    std::vector<fs::path> gone, kept;
    for (int k = 0; k < 100; ++k) {
        gone.push_back((k % 2 ? a : b) / ("." + frameName(k) + ".tmp-" + token + (k % 3 ? ".ply" : ".obj")));
        touch(gone.back());
    }
    for (const char* name : {"frame_00001.ply", ".frame_00002.tmp-fedcba9876543210.ply", ".frame_00003.ply.tmp-123-abc.ply",
                             ".apparent-frames-0123456789abcdef.1", "frame_00004.tmp-0123456789abcdef.ply"})
        kept.push_back(a / name);
    kept.push_back(apart / (".frame_00005.tmp-" + token + ".ply"));
    for (const fs::path& p : kept) touch(p);
    EXPECT_EXIT(
        {
            installInterruptCleanup();
            if (!removeFrameTemporariesOnInterrupt(token, {a.string(), b.string()})) std::_Exit(1);
            std::raise(SIGTERM);
            std::_Exit(2);
        },
        ::testing::ExitedWithCode(128 + SIGTERM), "terminated \\(SIGTERM\\): temporary files removed");
    for (const fs::path& p : gone) EXPECT_FALSE(fs::exists(p)) << p;
    for (const fs::path& p : kept) EXPECT_TRUE(fs::exists(p)) << p;
    // More folders than one per model: refused, nothing registered.
    EXPECT_FALSE(removeFrameTemporariesOnInterrupt(token, std::vector<std::string>(9, a.string())));
}
