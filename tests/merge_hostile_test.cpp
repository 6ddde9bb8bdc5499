// `apparent merge DIR` reads shard files as untrusted input. Each test renders
// real shards of a small scene (`render --shard I/3`), alters one header or record field, and
// expects one line naming the shard file and the field, exit code 2, and nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <sys/stat.h>

#include "file_bytes.h"
#include "measured_run.h"
#include "run_command.h"

namespace fs = std::filesystem;

namespace {

using testcli::apparentRun;
using testcli::source;
using testcli::TempDir;

uint64_t getU64(const std::string& b, size_t at) {
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(b[at + size_t(i)])) << (8 * i);
    return v;
}
std::string u64(uint64_t v) {
    std::string s;
    for (int i = 0; i < 8; ++i) s.push_back(char((v >> (8 * i)) & 0xff));
    return s;
}
std::string real(double v) {
    uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    return u64(bits);
}

// Where the fields of a shard file lie (the layout pipeline/run/shards.cpp writes, walked here
// independently): the header's fields, then the frame records, then the end record.
struct ShardLayout {
    size_t model = 0, tolerance = 0, fps = 0, scene_path = 0, objects = 0, name0 = 0, color0 = 0, mirror0 = 0,
           camera = 0, fov = 0, flags = 0, light = 0, looks = 0;
    std::vector<std::pair<size_t, size_t>> records;  // each frame record: its start and its length in all
    size_t end = 0;                                  // the end record's start
    explicit ShardLayout(const std::string& b) {
        size_t at = 17 + 5 * 8;  // "apparent shard 4\n", fingerprint, part, parts, first, last
        auto skipString = [&] { at += 8 + size_t(getU64(b, at)); };
        model = at;
        skipString();
        tolerance = at;
        fps = at + 8;
        at += 16;
        scene_path = at;
        skipString();
        objects = at;
        const uint64_t n = getU64(b, at);
        at += 8;
        for (uint64_t i = 0; i < n; ++i) {
            if (i == 0) name0 = at;
            skipString();
            if (i == 0) color0 = at;
            at += 32 + 40;  // base colour, metallic, roughness, emissive
            if (i == 0) mirror0 = at;
            at += 8;
            skipString();
        }
        camera = at;
        at += 9 * 8;
        fov = at;
        at += 8;
        flags = at;
        at += 8 * 8;
        // The light: point flag, position, direction, ambient, key direction, key weight.
        light = at;
        at += 8 + 3 * 8 + 3 * 8 + 8 + 3 * 8 + 8;
        looks = at;  // the objects' looks: none in these scenes' shards, then one reference per object
        const uint64_t nl = getU64(b, at);
        at += 8;
        for (uint64_t l = 0; l < nl; ++l) {
            for (int list = 0; list < 4; ++list) {  // materials, textures, samplers, extensions
                const uint64_t count = getU64(b, at);
                at += 8;
                for (uint64_t k = 0; k < count; ++k) skipString();
            }
            const uint64_t images = getU64(b, at);
            at += 8;
            for (uint64_t k = 0; k < 3 * images; ++k) skipString();  // type, name, bytes
        }
        at += 8 * n;
        while (getU64(b, at) == 1) {
            const size_t length = 16 + size_t(getU64(b, at + 8));
            records.emplace_back(at, length);
            at += length;
        }
        end = at;
    }
    // The frame a record carries (its encoded frame's number, after the 4-byte form tag).
    static long long carried(const std::string& b, const std::pair<size_t, size_t>& record) {
        return (long long)getU64(b, record.first + 16 + 4);
    }
};

std::string withString(const std::string& b, size_t at, const std::string& value) {
    const size_t old = 8 + size_t(getU64(b, at));
    return b.substr(0, at) + u64(value.size()) + value + b.substr(at + old);
}
std::string withBytes(const std::string& b, size_t at, const std::string& value) {
    return b.substr(0, at) + value + b.substr(at + value.size());
}

// Shards 0/3, 1/3 and 2/3 of a short run of the default scene (.glb only) in a fresh folder.
class MergeHostile : public ::testing::Test {
protected:
    void SetUp() override {
        for (int i = 0; i < 3; ++i) {
            const auto r = apparentRun({"render", source("data/scenes/flanges.json"), "--frames", "0:12", "--quiet",
                                        "--out", dir.str(), "--shard", std::to_string(i) + "/3"});
            ASSERT_EQ(r.code, 0) << r.err;
        }
        path = (dir / "shards/relativistic.0-of-3.shard").string();
        original = testio::readBytes(path);
        ASSERT_GT(original.size(), 200u);
    }
    void put(const std::string& bytes) { std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes; }
    // merge refuses with one line naming the shard (or `file`) and `what`, exit 2, and writes nothing.
    void expectRefused(const std::string& what, const std::string& file = "relativistic.0-of-3.shard") {
        const auto r = apparentRun({"merge", dir.str()});
        EXPECT_EQ(r.code, 2) << what << ": " << r.err;
        EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
        nothingWritten();
    }
    void nothingWritten() {
        for (const auto& e : fs::directory_iterator(dir / ""))
            EXPECT_EQ(e.path().filename(), "shards") << "written: " << e.path();
        for (const auto& e : fs::directory_iterator(dir / "shards"))
            EXPECT_EQ(e.path().extension(), ".shard") << "written: " << e.path();
    }
    TempDir dir;
    std::string path, original;
};

}  // namespace

// The unaltered shards merge (the tests below change one field of them).
TEST_F(MergeHostile, RealShardsMerge) {
    const auto r = apparentRun({"merge", dir.str(), "--quiet"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "relativistic.glb"));
}

// The model name makes the output's name: only the known models, so nothing is written outside
// DIR, at an absolute path, or under a name with a newline.
TEST_F(MergeHostile, ModelNameOutsideTheKnownModelsIsRefused) {
    const ShardLayout l(original);
    TempDir elsewhere;
    fs::create_directories(elsewhere / "");
    const std::string outside = elsewhere.str() + "/x";
    for (const std::string& name : {std::string("../../x"), outside, std::string("relativistic\nx"), std::string("")}) {
        put(withString(original, l.model, name));
        expectRefused("model");
        EXPECT_FALSE(fs::exists(outside + ".glb"));
        EXPECT_FALSE(fs::exists(dir / "../../x.glb"));
    }
}

// Numbers out of range or not finite, and flags and bits outside the ones the command line takes.
TEST_F(MergeHostile, HeaderNumbersAndFlagsOutOfRangeAreRefused) {
    const ShardLayout l(original);
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    struct Case {
        size_t at;
        std::string bytes, field;
    };
    const std::vector<Case> cases = {
        {l.fps, real(nan), "fps"},
        {l.fps, real(0), "fps"},
        {l.fps, real(-24), "fps"},
        {l.tolerance, real(inf), "tolerance"},
        {l.tolerance, real(-1), "tolerance"},
        {l.camera, real(nan), "camera"},
        {l.camera + 8 * 6, real(0) + real(0) + real(0), "camera"},  // up = 0
        {l.fov, real(180), "camera.fov_deg"},
        {l.fov, real(nan), "camera.fov_deg"},
        {l.color0, real(nan), "objects[0].base_color"},
        {l.color0 + 8, real(2), "objects[0].base_color"},
        {l.color0 + 32, real(-1), "objects[0].material"},
        {l.color0 + 64, real(nan), "objects[0].material"},
        {l.mirror0, u64(7), "objects[0].mirror_index"},
        {l.flags, u64(2), "draco"},
        {l.flags + 8, u64(999), "draco position bits"},
        {l.flags + 16, u64(0), "draco normal bits"},
        {l.flags + 32, u64(17), "meshopt bits"},
        {l.flags + 56, u64(uint64_t(1) << 40), "shade doppler"},
        {l.objects, u64(uint64_t(1) << 40), "objects"},
        {l.light, u64(2), "light.point"},
        {l.light + 8, real(inf), "light"},               // position
        {l.light + 8 + 24 + 8, real(nan), "light"},      // direction's y
        {l.light + 8 + 48, real(1.5), "light.ambient"},
        {l.light + 8 + 48, real(nan), "light.ambient"},
        {l.light + 8 + 56 + 24, real(-0.1), "light.key_weight"},
        {l.looks, u64(1000), "looks"},
        {l.looks + 8, u64(5), "objects[0].look"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.field);
        put(withBytes(original, c.at, c.bytes));
        expectRefused(c.field);
    }
}

// Names written into the .glb (JSON: UTF-8 only) and its summary: not valid UTF-8, or a control
// character, is one line (it was an internal json type_error, exit 1).
TEST_F(MergeHostile, NamesNotUtf8OrWithControlCharactersAreRefused) {
    const ShardLayout l(original);
    put(withString(original, l.scene_path, "scene\xff\xfe.json"));
    expectRefused("scene path: not valid UTF-8");
    put(withString(original, l.name0, "obj\xc3"));
    expectRefused("objects[0].name: not valid UTF-8");
    put(withString(original, l.name0, "two\nlines"));
    expectRefused("objects[0].name: holds a control character");
}

// A 5 GiB frame claimed by a small shard: refused from the file's size, before any allocation,
// quickly and in little memory (it peaked at 5.25 GB for 20 s).
TEST_F(MergeHostile, LengthsBeyondTheFileAreRefusedBeforeAllocating) {
    const ShardLayout l(original);
    ASSERT_FALSE(l.records.empty());
    put(withBytes(original, l.records[0].first + 8, u64(uint64_t(5) << 30)));
    const testcli::Measured m = testcli::runMeasured({"merge", dir.str()}, 60);
    EXPECT_EQ(m.code, 2) << m.err;
    EXPECT_NE(m.err.find("relativistic.0-of-3.shard: frame 0's record claims more bytes than the file holds"),
              std::string::npos)
        << m.err;
    EXPECT_EQ(std::count(m.err.begin(), m.err.end(), '\n'), 1) << m.err;
    EXPECT_LT(m.seconds, 30.0);  // a guard against the old minutes-long path; the figure is printed below
#ifndef APPARENT_SANITIZED  // ASan's shadow memory and quarantine: no RSS bound
    EXPECT_LT(m.peak_rss, 100LL << 20);
#endif
    std::cout << "  refused in " << m.seconds << " s, peak RSS " << (m.peak_rss >> 20) << " MB\n";
    nothingWritten();
    // A string length beyond the file too (the scene path).
    put(withBytes(original, l.scene_path, u64(uint64_t(1) << 19)));
    expectRefused("shard header is malformed");
}

// A FIFO named *.shard is refused at once (it was opened for reading and waited on forever).
TEST_F(MergeHostile, OnlyRegularFilesAreRead) {
    const std::string fifo = (dir / "shards/pipe.shard").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const testcli::Measured m = testcli::runMeasured({"merge", dir.str()}, 10);
    EXPECT_EQ(m.code, 2) << m.err;
    EXPECT_NE(m.err.find("pipe.shard: is a FIFO, not a regular file"), std::string::npos) << m.err;
    EXPECT_EQ(std::count(m.err.begin(), m.err.end(), '\n'), 1) << m.err;
    fs::remove(fifo);
    nothingWritten();
}

// Frames are placed by the frame each record carries: records swapped, repeated or left out
// (the count kept) are refused, not written out of order.
TEST_F(MergeHostile, FramesAreCheckedAgainstTheirCarriedIndex) {
    const ShardLayout l(original);
    ASSERT_EQ(l.records.size(), 4u);  // frames 0, 3, 6, 9
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(ShardLayout::carried(original, l.records[i]), (long long)(3 * i));
    auto record = [&](size_t i) { return original.substr(l.records[i].first, l.records[i].second); };
    const std::string head = original.substr(0, l.records[0].first), tail = original.substr(l.end);
    put(head + record(1) + record(0) + record(2) + record(3) + tail);  // swapped
    expectRefused("frame record 3 where frame 0 belongs");
    put(head + record(0) + record(0) + record(2) + record(3) + tail);  // repeated
    expectRefused("frame record 0 where frame 3 belongs");
    put(head + record(0) + record(2) + record(3) + record(3) + tail);  // a gap
    expectRefused("frame record 6 where frame 3 belongs");
}

// Every shard of a model has the header of the others (the fingerprint can be copied): a
// shard whose camera alone differs is refused rather than merged with the first one's.
TEST_F(MergeHostile, HeadersDifferingUnderOneFingerprintAreRefused) {
    const ShardLayout l(original);
    put(withBytes(original, l.fov, real(50)));
    const auto r = apparentRun({"merge", dir.str()});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("shard header differs from"), std::string::npos) << r.err;
    nothingWritten();
}
