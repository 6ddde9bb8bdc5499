// Job-array shards (pipeline/run/shards.h) and the frame split they share with MPI
// (pipeline/run/distribute.h): shards 0/3, 1/3, 2/3 run as separate commands and merged give the same
// bytes as one process for every output; a missing, duplicated or foreign shard is refused with one
// line and exit code 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <unistd.h>

#include "pipeline/run/distribute.h"
#include "pipeline/run/shards.h"
#include "run_command.h"
#include "file_bytes.h"

namespace fs = std::filesystem;

namespace {

using testcli::apparentRun;
using testcli::source;
using testcli::TempDir;

// Every file under `dir` (relative names), leaving out the shards folder.
std::map<std::string, std::string> outputs(const fs::path& dir) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string rel = fs::relative(e.path(), dir).string();
        if (e.is_regular_file() && rel.rfind("shards", 0) != 0) files[rel] = testio::readBytes(e.path());
    }
    return files;
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

// One line, "error: ...", naming `what`.
void expectOneLine(const testcli::CommandResult& r, const std::string& what) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
}

}  // namespace

// The split, counted independently: every frame of a range in exactly one part, parts within one
// frame of each other in size, and count() equal to the frames owns() takes.
TEST(Shards, SplitCoversEveryFrameOnce) {
    for (int parts : {1, 2, 3, 4, 7, 64})
        for (long long first : {0LL, 5LL})
            for (long long n : {1LL, 2LL, 3LL, 10LL, 100LL, 101LL}) {
                std::vector<int> owners(size_t(n), 0);
                long long least = n, most = 0;
                for (int p = 0; p < parts; ++p) {
                    const apparent::FrameSplit s{p, parts};
                    long long mine = 0;
                    for (long long k = first; k < first + n; ++k)
                        if (s.owns(k, first)) {
                            ++owners[size_t(k - first)];
                            ++mine;
                            EXPECT_EQ(s.partOf(k, first), p);
                        }
                    EXPECT_EQ(s.count(first, first + n), mine);
                    least = std::min(least, mine);
                    most = std::max(most, mine);
                }
                for (int o : owners) EXPECT_EQ(o, 1);
                EXPECT_LE(most - least, 1);
            }
}

TEST(Shards, ParseShard) {
    apparent::FrameSplit s;
    EXPECT_TRUE(apparent::parseShard("0/3", &s));
    EXPECT_EQ(s.part, 0);
    EXPECT_EQ(s.parts, 3);
    EXPECT_TRUE(apparent::parseShard("2/3", &s));
    EXPECT_EQ(s.part, 2);
    for (const char* bad : {"3/3", "1/0", "-1/3", "1/", "/3", "a/3", "1/3x", "1", "0/1000000"})
        EXPECT_FALSE(apparent::parseShard(bad, &s)) << bad;
    const auto r = apparentRun({"render", source("data/scenes/flanges.json"), "--shard", "3/3"});
    expectOneLine(r, "--shard: '3/3'");
}

// A frame as it travels between processes (its header and its sinks' bytes as the parts of one
// message) comes back as it was, the sinks' bytes moved out of the parts; a cut or altered one is refused.
TEST(Shards, FramePartsRoundTrip) {
    apparent::EncodedFrame f;
    f.index = 42;
    f.triangles = 1234;
    f.limited_triangles = 5;
    f.sinks.push_back({10, 20, std::string("ply bytes\0with a zero", 21)});
    f.sinks.push_back({0, 0, ""});
    const std::string header = apparent::frameHeader(f);
    const std::vector<std::string_view> views = apparent::frameParts(f, header);
    ASSERT_EQ(views.size(), 3u);
    EXPECT_EQ(views[1].data(), f.sinks[0].bytes.data());  // viewed, not copied, for sending
    auto parts = [&] { return std::vector<std::string>(views.begin(), views.end()); };
    std::vector<std::string> received = parts();
    const char* payload = received[1].data();
    apparent::EncodedFrame g;
    std::string error;
    ASSERT_TRUE(apparent::frameFromParts(&received, &g, &error)) << error;
    EXPECT_EQ(g.index, 42);
    EXPECT_EQ(g.triangles, 1234u);
    EXPECT_EQ(g.limited_triangles, 5u);
    EXPECT_FALSE(g.over_budget);
    ASSERT_EQ(g.sinks.size(), 2u);
    EXPECT_EQ(g.sinks[0].least, 10);
    EXPECT_EQ(g.sinks[0].estimate, 20);
    EXPECT_EQ(g.sinks[0].bytes, f.sinks[0].bytes);
    EXPECT_EQ(g.sinks[0].bytes.data(), payload);  // moved out of the received part, not copied
    EXPECT_TRUE(g.sinks[1].bytes.empty());
    apparent::EncodedFrame h;
    std::vector<std::string> bad = parts();
    bad[0].pop_back();  // a cut header
    EXPECT_FALSE(apparent::frameFromParts(&bad, &h, &error));
    bad = parts();
    bad[0] += "x";  // a longer header
    EXPECT_FALSE(apparent::frameFromParts(&bad, &h, &error));
    bad = parts();
    bad[1].pop_back();  // a sink's bytes not of the size the header gives
    EXPECT_FALSE(apparent::frameFromParts(&bad, &h, &error));
    bad = parts();
    bad.pop_back();  // a part missing
    EXPECT_FALSE(apparent::frameFromParts(&bad, &h, &error));
    bad = parts();
    bad.emplace_back("extra");  // one part too many
    EXPECT_FALSE(apparent::frameFromParts(&bad, &h, &error));
    bad.clear();
    EXPECT_FALSE(apparent::frameFromParts(&bad, &h, &error));
}

// Shards 0/3, 1/3 and 2/3 as separate commands, then merge: every file byte-identical to one
// process (the .glb plain, with Draco and with meshopt; PLY; OBJ), on the default scene (a mirror)
// and on a mirrored scene whose mirror exists only part of the time (clipped frames), in vertex
// mode too (index buffers shared across frames that lie in different shards).
TEST(Shards, MergedShardsAreByteIdenticalToOneProcess) {
    struct Case {
        std::string scene;
        std::vector<std::string> options;
    };
    const std::vector<Case> cases = {
        {"data/scenes/flanges.json", {"--format", "glb,ply,obj"}},
        {"data/scenes/flanges.json", {"--frames", "60:120", "--compress", "draco"}},
        {"data/scenes/flanges.json", {"--frames", "60:120", "--compress", "meshopt"}},
        {"data/fixtures/scene_mirror_exists.json", {"--format", "glb,ply,obj", "--frames", "60:200"}},
        {"data/fixtures/scene_mirror_exists.json", {"--frames", "60:200", "--compress", "draco"}},
        {"data/fixtures/scene_mirror_exists.json", {"--frames", "60:200", "--compress", "meshopt"}},
        {"data/fixtures/scene_mirror_exists.json", {"--tolerance", "vertex", "--model", "relativistic,finite"}},
    };
    for (const Case& c : cases) {
        TempDir one, sharded;
        const std::vector<std::string> base = with({"render", source(c.scene), "--quiet"}, c.options);
        const auto r = apparentRun(with(base, {"--out", one.str()}));
        ASSERT_EQ(r.code, 0) << r.err;
        for (int i = 0; i < 3; ++i) {
            const auto s = apparentRun(with(base, {"--out", sharded.str(), "--shard", std::to_string(i) + "/3"}));
            ASSERT_EQ(s.code, 0) << s.err;
        }
        const auto m = apparentRun({"merge", sharded.str()});
        ASSERT_EQ(m.code, 0) << m.err;
        EXPECT_NE(m.out.find("merged from 3 shards"), std::string::npos) << m.out;
        const auto expected = outputs(one / ""), got = outputs(sharded / "");
        EXPECT_GT(expected.size(), 0u);
        ASSERT_EQ(expected.size(), got.size()) << c.scene;
        for (const auto& [name, bytes] : expected) {
            ASSERT_TRUE(got.count(name)) << c.scene << ": " << name << " missing";
            EXPECT_TRUE(got.at(name) == bytes) << c.scene << " " << c.options.back() << ": " << name << " differs";
        }
    }
}

// merge refuses, with one line and exit code 2: no shards, a missing one, a shard of another
// scene, a shard run with another tolerance, a duplicated shard, a truncated one; and writes no .glb.
TEST(Shards, MergeRefusesMissingForeignDuplicatedShards) {
    const std::string scene = source("data/scenes/flanges.json");
    const std::vector<std::string> frames = {"--frames", "0:30", "--quiet"};
    TempDir dir;
    auto shard = [&](const std::string& which, std::vector<std::string> more = {}) {
        more.insert(more.end(), {"--out", dir.str(), "--shard", which});
        const auto r = apparentRun(with(with({"render", scene}, frames), more));
        ASSERT_EQ(r.code, 0) << r.err;
    };
    expectOneLine(apparentRun({"merge", dir.str()}), "no shard files");
    shard("0/3");
    shard("2/3");
    expectOneLine(apparentRun({"merge", dir.str()}), "shard 1/3 of model relativistic is missing");
    // Another scene: the fixture differs from the default scene only in the mirror's `exists`.
    {
        const auto r = apparentRun({"render", source("data/fixtures/scene_mirror_exists.json"), "--frames", "0:30",
                                    "--quiet", "--out", dir.str(), "--shard", "1/3"});
        ASSERT_EQ(r.code, 0) << r.err;
        expectOneLine(apparentRun({"merge", dir.str()}), "from another scene or option set");
    }
    shard("1/3", {"--tolerance", "0.02"});
    expectOneLine(apparentRun({"merge", dir.str()}), "from another scene or option set");
    shard("1/3");
    const fs::path shards = dir / "shards";
    fs::copy_file(shards / "relativistic.1-of-3.shard", shards / "copy.shard");
    expectOneLine(apparentRun({"merge", dir.str()}), "shard 1/3 of model relativistic again");
    fs::remove(shards / "copy.shard");
    // A shard cut short (a copy gone wrong): refused, not merged.
    const std::string whole = testio::readBytes(shards / "relativistic.2-of-3.shard");
    std::ofstream(shards / "relativistic.2-of-3.shard", std::ios::binary) << whole.substr(0, whole.size() - 100);
    expectOneLine(apparentRun({"merge", dir.str()}), "relativistic.2-of-3.shard");
    EXPECT_FALSE(fs::exists(dir / "relativistic.glb"));
    std::ofstream(shards / "relativistic.2-of-3.shard", std::ios::binary) << whole;
    const auto m = apparentRun({"merge", dir.str(), "--quiet"});
    EXPECT_EQ(m.code, 0) << m.err;
    EXPECT_TRUE(fs::exists(dir / "relativistic.glb"));
}

// The output budget applies per shard: the estimate is made from the shard's own first frames and
// scaled to the shard's frames (the message says "of N frames" with the shard's N).
TEST(Shards, OutputBudgetIsPerShard) {
    TempDir dir;
    const auto r = apparentRun({"render", source("data/scenes/flanges.json"), "--format", "ply", "--shard", "1/4",
                                "--out", dir.str(), "--max-output-bytes", "1000"});
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.err.find("of 50 frames"), std::string::npos) << r.err;  // 200 frames / 4
    EXPECT_FALSE(fs::exists(dir / "relativistic"));
}
