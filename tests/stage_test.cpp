// The stage layer and the frame sinks (pipeline/stage/stage.h, pipeline/run/frame_loop.h,
// exporters/frame_sink.h): output bytes pinned across the refactor, exact PLY and OBJ far from the
// origin, one load preamble for every command, and the small shared pieces (check, box).
#include <gtest/gtest.h>

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "exporters/frame_sink.h"
#include "exporters/gltf.h"
#include "exporters/obj.h"
#include "exporters/ply.h"
#include "mesh4d/box.h"
#include "mesh4d/check.h"
#include "pipeline/run/frame_loop.h"
#include "pipeline/stage/stage.h"
#include "pipeline/stage/worlds.h"
#include "quiet_stage.h"
#include "run_command.h"
#include "file_bytes.h"
#include "temp_dir.h"

using namespace apparent;
using testcli::apparentRun;
using testcli::source;
namespace fs = std::filesystem;

namespace {

// FNV-1a, 64 bits: a fingerprint of a file's bytes (not a cryptographic hash).
uint64_t fnv1a(const std::string& bytes) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned char c : bytes) {
        h ^= c;
        h *= 0x100000001b3ull;
    }
    return h;
}

fs::path freshDir(const std::string& name) {
    const fs::path dir = testio::tempPath() / ("apparent_stage_test_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

}  // namespace

// The .glb bytes of a small scene (the default scene's frames 98..100: mirror reflections
// included): the FNV-1a of each file of `apparent render data/scenes/flanges.json --out DIR ARGS`,
// run from the source folder (so the scene_file extras read "data/scenes/flanges.json"). A
// reshaping of the code keeps these bytes; a change meant to alter them (other numbers, other
// pieces at the same tolerance, another layout of the file) pins them again and says why in its
// commit message, checked file by file against the earlier files (the pins' history is in git).
TEST(Stage, GlbBytesPinnedAcrossTheRefactor) {
    struct Case {
        std::vector<std::string> args;
        std::vector<std::pair<std::string, uint64_t>> files;
    };
    const std::vector<Case> cases = {
        {{"--model", "all", "--frames", "98:101"},
         {{"instant.glb", 0x5698d0ca77d1542bull},
          {"finite.glb", 0x7bb810c08e3b2b08ull},
          {"relativistic.glb", 0x70b2f2df50c84edeull},
          {"contracted.glb", 0x57d6bc114c00d19cull}}},
        {{"--model", "relativistic", "--frames", "98:101", "--draco"}, {{"relativistic.glb", 0x369aa14379f8b1a2ull}}},
        // The parametric error bounded at the tolerance: the refinement as it was before the rim rule.
        {{"--model", "finite,relativistic", "--frames", "98:101", "--attribute-tolerance", "0.01"},
         {{"finite.glb", 0x8118182bb969d6f9ull}, {"relativistic.glb", 0x879b263dae8225c1ull}}},
        {{"--model", "relativistic", "--frames", "98:101", "--tolerance", "vertex", "--cull-view"},
         {{"relativistic.glb", 0x8df986d85209c6daull}}},
    };
    const fs::path dir = freshDir("pinned");
    for (size_t c = 0; c < cases.size(); ++c) {
        const fs::path out = dir / std::to_string(c);
        std::vector<std::string> args = {"render", "data/scenes/flanges.json", "--out", out.string(), "--quiet"};
        args.insert(args.end(), cases[c].args.begin(), cases[c].args.end());
        const auto r = apparentRun(args);
        ASSERT_EQ(r.code, 0) << r.err;
        for (const auto& [name, hash] : cases[c].files)
            EXPECT_EQ(fnv1a(testio::readBytes(out / name)), hash) << "case " << c << ": " << name << " changed";
    }
    fs::remove_all(dir);
}

namespace {

// The vertices of a binary little-endian PLY with double x y z quality (then doppler and
// proper_time when computed, and the uchar object index), in file order.
std::vector<std::array<double, 4>> readPlyDoubles(const fs::path& p, size_t* faces) {
    const std::string bytes = testio::readBytes(p);
    const size_t end = bytes.find("end_header\n");
    EXPECT_NE(end, std::string::npos);
    const std::string header = bytes.substr(0, end);
    EXPECT_NE(header.find("property double x\nproperty double y\nproperty double z\nproperty double quality\n"),
              std::string::npos)
        << header;
    const size_t n = std::stoul(header.substr(header.find("element vertex ") + 15));
    *faces = std::stoul(header.substr(header.find("element face ") + 13));
    // x y z quality, then doppler and proper_time when the frame loop computed them, then the
    // object index (a uchar: these scenes have fewer than 257 objects).
    const bool factors = header.find("property double quality\nproperty double doppler\nproperty double proper_time\n") !=
                         std::string::npos;
    EXPECT_NE(header.find("property uchar object\n"), std::string::npos) << header;
    const size_t stride = (factors ? 48 : 32) + 1;
    std::vector<std::array<double, 4>> v(n);
    const char* data = bytes.data() + end + 11;
    EXPECT_EQ(bytes.size(), end + 11 + stride * n + 13 * *faces);
    for (size_t i = 0; i < n; ++i) std::memcpy(v[i].data(), data + stride * i, 32);  // the test machine is little-endian
    return v;
}

std::vector<mesh4d::Vec3> readObjPositions(const fs::path& p) {
    std::vector<mesh4d::Vec3> v;
    std::ifstream in(p);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("v ", 0) != 0) continue;
        std::array<double, 3> c{};
        EXPECT_TRUE(testio::objVertex(line, &c)) << line;
        v.push_back({c[0], c[1], c[2]});
    }
    return v;
}

}  // namespace

// An object at rest 1e6 ls from the camera: its apparent shape is its rest shape (closed form:
// position + q), which float32 positions would lose (their spacing at 1e6 is 0.0625 ls). The PLY
// and OBJ vertices must be the in-memory cut's doubles exactly, and every edge must be the rest
// edge to a few units in the last place of 1e6.
TEST(Stage, PlyAndObjKeepTheShapeOfAnObjectFarAway) {
    const fs::path dir = freshDir("far");
    // Dyadic coordinates, exact in OpenMesh's float reader and in any sum with 1e6.
    std::ofstream(dir / "tetra.obj") << "v 0.5 0.25 0\nv -0.5 0 0.125\nv 0 -0.75 0.5\nv 0.25 0.5 -0.5\n"
                                        "f 1 2 4\nf 1 3 2\nf 1 4 3\nf 2 3 4\n";
    std::ofstream(dir / "scene.json") << R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
        "frames": {"start": 0, "end": 0.2, "fps": 10}, "model": "relativistic", "tolerance": "vertex",
        "objects": [{"name": "far", "mesh": "tetra.obj", "position": [1, -2, -1000000]}]})";
    const auto r = apparentRun({"render", (dir / "scene.json").string(), "--out", (dir / "out").string(), "--format",
                                "ply,obj", "--frames", "1:2", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    size_t faces = 0;
    const auto ply = readPlyDoubles(dir / "out/relativistic/frame_00001.ply", &faces);
    const auto obj = readObjPositions(dir / "out/relativistic/frame_00001.obj");
    ASSERT_EQ(ply.size(), obj.size());
    ASSERT_FALSE(ply.empty());

    // Step: the same frame cut in memory, all objects merged as the writers merge them.
    StageOptions options;
    options.scene_path = (dir / "scene.json").string();
    options.quiet = true;
    Stage stage;
    std::ostringstream log;
    std::string error;
    ASSERT_TRUE(loadStage(options, &stage, log, &error)) << error;
    const mesh4d::World4D world = buildWorld(stage.objects[0], Model::Relativistic, stage.scene, 1, 1);
    ExportFrame frame;
    frame.objects.push_back(mesh4d::sliceWorld(world, viewForFrame(stage.scene, Model::Relativistic, 1), {}));
    const mesh4d::ApparentMesh merged = mergeObjects(frame);
    ASSERT_EQ(merged.positions.size(), ply.size());
    EXPECT_EQ(faces, merged.triangles.size());

    const mesh4d::Vec3 origin{1, -2, -1000000};
    const double ulp = std::nextafter(1e6, 2e6) - 1e6;  // 1.16e-10
    for (size_t i = 0; i < ply.size(); ++i) {
        const mesh4d::Vec3 p{ply[i][0], ply[i][1], ply[i][2]};
        EXPECT_EQ(p, merged.positions[i]) << "PLY vertex " << i;
        EXPECT_EQ(obj[i], merged.positions[i]) << "OBJ vertex " << i;
        EXPECT_EQ(ply[i][3], merged.emission_times[i]) << "PLY quality " << i;
        // Closed form: at rest, the apparent point of rest point q is origin + q.
        const mesh4d::Vec3 q = merged.rest_points[i];
        const mesh4d::Vec3 exact = origin + q;
        for (int c = 0; c < 3; ++c) EXPECT_LE(std::fabs(p[c] - exact[c]), 2 * ulp) << "vertex " << i << " axis " << c;
    }
    // The shape: every edge between output vertices is the rest edge, to double precision at 1e6.
    for (const auto& t : merged.triangles)
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = t[e], b = t[(e + 1) % 3];
            const mesh4d::Vec3 edge = mesh4d::Vec3{ply[b][0], ply[b][1], ply[b][2]} - mesh4d::Vec3{ply[a][0], ply[a][1], ply[a][2]};
            const mesh4d::Vec3 rest = merged.rest_points[b] - merged.rest_points[a];
            EXPECT_LE(mesh4d::norm(edge - rest), 4 * ulp);
            const mesh4d::Vec3 obj_edge = obj[b] - obj[a];
            EXPECT_LE(mesh4d::norm(obj_edge - rest), 4 * ulp);
        }
    fs::remove_all(dir);
}

// One load preamble: raytrace and figure refuse a scene over --max-frames as render does.
TEST(Stage, EveryCommandHonoursMaxFrames) {
    const std::string scene = source("data/scenes/flanges.json");  // 200 frames
    const std::string want = "frames: 200 frames requested, more than the limit of 150 (raise it with --max-frames)";
    const fs::path dir = freshDir("max_frames");
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"render", scene, "--out", (dir / "r").string(), "--max-frames", "150"},
          std::vector<std::string>{"raytrace", scene, "--out", (dir / "t").string(), "--max-frames", "150"},
          std::vector<std::string>{"figure", scene, "--out", (dir / "f.png").string(), "--max-frames", "150"}}) {
        const auto r = apparentRun(args);
        EXPECT_EQ(r.code, kExitBadInput) << args[0];
        EXPECT_NE(r.err.find(want), std::string::npos) << args[0] << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "r") || fs::exists(dir / "t") || fs::exists(dir / "f.png"));
    fs::remove_all(dir);
}

namespace {

// A sink that records what the loop gives it: a new format needs no more than this.
class RecordingSink : public FrameSink {
public:
    bool begin(const SequenceInfo& info, std::string*) override {
        objects = info.objects.size();
        ++begun;
        return true;
    }
    std::shared_ptr<const PreparedFrame> prepare(const ExportFrame& frame) const override {
        auto p = std::make_shared<Prepared>();
        p->index = frame.index;
        return p;
    }
    PendingOutput pending(const ExportFrame&) override { return {0, "recording"}; }
    bool add(const ExportFrame& frame, const PreparedFrame* prepared, std::vector<std::string>*,
             std::string*) override {
        order.push_back(frame.index);
        prepared_for_it += static_cast<const Prepared*>(prepared)->index == frame.index;
        triangles += frame.triangleCount();
        for (size_t i = 0; i < frame.objects.size(); ++i) {
            const mesh4d::ApparentMesh& o = frame.objects[i];
            if (o.positions.empty()) continue;
            ++non_empty;
            reflections_seen += i >= 4;  // the default scene's 4 objects come first
            const bool both = o.doppler.size() == o.positions.size() && o.proper_time.size() == o.positions.size();
            with_factors += both;
            without_factors += o.doppler.empty() && o.proper_time.empty();
            with_rest += o.rest_points.size() == o.positions.size() && o.source_triangles.size() == o.triangles.size();
            without_rest += o.rest_points.empty() && o.source_triangles.empty();
        }
        return true;
    }
    bool readsLightFactors() const override { return reads; }
    bool readsRestPoints() const override { return reads_rest; }
    bool finish(SinkSummary* summary, std::string*) override {
        summary->text = ", recorded";
        ++finished;
        return true;
    }

    struct Prepared : PreparedFrame {
        long long index = -1;
    };
    bool reads = true;       // readsLightFactors()
    bool reads_rest = true;  // readsRestPoints()
    size_t objects = 0, triangles = 0;
    size_t non_empty = 0, reflections_seen = 0;    // objects delivered with points; of them reflections
    size_t with_factors = 0, without_factors = 0;  // of them with both light factors or neither
    size_t with_rest = 0, without_rest = 0;        // with rest points and source triangles, or neither
    int begun = 0, finished = 0;
    long long prepared_for_it = 0;
    std::vector<long long> order;
};

}  // namespace

// The loop cuts frames [A, B) in parallel batches and hands them to every sink in frame order,
// each with its own prepared conversion; the result does not depend on the thread count.
TEST(Stage, FrameLoopDeliversFramesInOrder) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietFrames(source("data/scenes/flanges.json"), 37, 58, &stage, &error)) << error;
    std::ostringstream progress;
    size_t triangles_one_thread = 0;
    for (int threads : {1, 2}) {
        RecordingSink a, b;
        OutputBudget budget(1);
        FrameLoopSettings settings;
        settings.threads = threads;
        settings.progress = false;
        FrameLoopResult result;
        ASSERT_TRUE(runFrameLoop(stage, Model::Relativistic, settings, {&a, &b}, &budget, progress, &result, &error))
            << error;
        for (const RecordingSink* s : {&a, &b}) {
            EXPECT_EQ(s->begun, 1);
            EXPECT_EQ(s->finished, 1);
            ASSERT_EQ(s->order.size(), 21u);
            for (size_t i = 0; i < s->order.size(); ++i) EXPECT_EQ(s->order[i], 37 + (long long)i);
            EXPECT_EQ(s->prepared_for_it, 21);
            // The scene's 4 objects, then one reflection per other object in the one mirror.
            EXPECT_EQ(s->objects, 4u + 3u);
        }
        EXPECT_EQ(result.summaries.size(), 2u);
        EXPECT_EQ(result.summaries[0].text, ", recorded");
        EXPECT_GT(a.triangles, 0u);
        if (threads == 1) triangles_one_thread = a.triangles;
        else EXPECT_EQ(a.triangles, triangles_one_thread);
    }
}

// The loop computes the light factors (doppler, proper_time) only when some sink reads them:
// sinks that all say no get none, on the scene objects and on the mirror reflections alike; one
// sink that says yes gets them for every object, and so does the sink beside it. The default scene
// and the same seen by a moving camera (pipeline/stage/mirror.h: its reflections are made apart).
TEST(Stage, LightFactorsOnlyWhenASinkReadsThem) {
    for (const char* scene : {"data/scenes/flanges.json", "data/fixtures/scene_mirror_camera.json"}) {
        Stage stage;
        std::string error;
        ASSERT_TRUE(loadQuietFrames(source(scene), 8, 11, &stage, &error)) << error;  // one mirror: reflections too
        std::ostringstream progress;
        for (Model model : {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted}) {
            for (bool second_reads : {false, true}) {
                RecordingSink a, b;
                a.reads = false;
                b.reads = second_reads;
                OutputBudget budget(0);
                FrameLoopSettings settings;
                settings.progress = false;
                FrameLoopResult result;
                ASSERT_TRUE(runFrameLoop(stage, model, settings, {&a, &b}, &budget, progress, &result, &error)) << error;
                for (const RecordingSink* s : {&a, &b}) {
                    EXPECT_GT(s->reflections_seen, 0u) << scene << " " << modelName(model);
                    EXPECT_EQ(second_reads ? s->with_factors : s->without_factors, s->non_empty)
                        << scene << " " << modelName(model) << " " << second_reads;
                }
            }
        }
    }
}

// The loop releases the rest points and source triangles once the frame is prepared when no sink
// reads them (the frames held for the output estimate then do not keep them); one sink that reads
// them keeps them for every sink. The default scene with its mirror (reflections), frames held for
// the estimate and delivered after it.
TEST(Stage, RestPointsReleasedWhenNoSinkReadsThem) {
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietFrames(source("data/scenes/flanges.json"), 8, 16, &stage, &error)) << error;
    std::ostringstream progress;
    for (bool second_reads : {false, true}) {
        RecordingSink a, b;
        a.reads_rest = false;
        b.reads_rest = second_reads;
        OutputBudget budget(1LL << 40);  // a limit: the first frames are held for the estimate
        FrameLoopSettings settings;
        settings.progress = false;
        FrameLoopResult result;
        ASSERT_TRUE(runFrameLoop(stage, Model::Relativistic, settings, {&a, &b}, &budget, progress, &result, &error))
            << error;
        for (const RecordingSink* s : {&a, &b}) {
            EXPECT_EQ(s->order.size(), 8u);
            EXPECT_GT(s->reflections_seen, 0u);
            EXPECT_GT(s->non_empty, 0u);
            EXPECT_EQ(second_reads ? s->with_rest : s->without_rest, s->non_empty) << second_reads;
        }
    }
}

// The file sinks and the .glb read neither rest points nor source triangles.
TEST(Stage, SinksSayWhetherTheyReadRestPoints) {
    const fs::path dir = freshDir("reads_rest");
    EXPECT_FALSE(plySink((dir / "p").string())->readsRestPoints());
    EXPECT_FALSE(objSink((dir / "o").string())->readsRestPoints());
    EXPECT_FALSE(GlbSink((dir / "a.glb").string(), GlbOptions(), false).readsRestPoints());
    fs::remove_all(dir);
}

// The sinks' answers: the PLY writes doppler and proper_time, the OBJ nothing of them, the .glb
// only with --attributes doppler / proper_time or --shade doppler.
TEST(Stage, SinksSayWhetherTheyReadLightFactors) {
    const fs::path dir = freshDir("reads_factors");
    EXPECT_TRUE(plySink((dir / "p").string())->readsLightFactors());
    EXPECT_FALSE(objSink((dir / "o").string())->readsLightFactors());
    GlbOptions plain;
    EXPECT_FALSE(GlbSink((dir / "a.glb").string(), plain, false).readsLightFactors());
    for (int which = 0; which < 3; ++which) {
        GlbOptions o;
        (which == 0 ? o.doppler : which == 1 ? o.proper_time : o.shade_doppler) = true;
        EXPECT_TRUE(GlbSink((dir / "a.glb").string(), o, false).readsLightFactors()) << which;
    }
    fs::remove_all(dir);
}

// A .glb beside the PLY leaves the PLY its light factors; the PLY alone has them too.
TEST(Stage, PlyKeepsLightFactorsBesideAPlainGlb) {
    const fs::path dir = freshDir("ply_factors");
    for (const std::string formats : {"glb,ply", "ply"}) {
        const fs::path out = dir / formats;
        const auto r = apparentRun({"render", source("data/scenes/flanges.json"), "--out", out.string(), "--quiet",
                                    "--model", "relativistic", "--frames", "98:99", "--format", formats});
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string bytes = testio::readBytes(out / "relativistic" / "frame_00098.ply");
        EXPECT_NE(bytes.substr(0, bytes.find("end_header")).find("property double doppler\nproperty double proper_time\n"),
                  std::string::npos)
            << formats;
    }
    fs::remove_all(dir);
}

// The budget refuses before writing past the limit and names what would have passed it.
TEST(Stage, OutputBudgetMessages) {
    OutputBudget budget(100);
    std::string error;
    EXPECT_TRUE(budget.fits(100, "a.ply", &error));
    EXPECT_FALSE(budget.fits(101, "a.ply", &error));
    EXPECT_EQ(error, "--max-output-bytes: a.ply would bring the output to 101 bytes, more than the limit of 100 (0 "
                     "bytes written, every written file is complete; raise it with --max-output-bytes)");
}

// APPARENT_CHECK names the file, the expression and both operands' values.
TEST(Check, PrintsItsOperands) {
    const size_t have = 2, need = 4;
    try {
        APPARENT_CHECK(have, >=, need);
        FAIL() << "the check passed";
    } catch (const std::logic_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("stage_test.cpp:"), std::string::npos) << what;
        EXPECT_NE(what.find("check failed: have >= need (2 >= 4)"), std::string::npos) << what;
    }
    EXPECT_NO_THROW(APPARENT_CHECK(need, >, have));
}

// One 4D box: events grow both parts, points the spatial part alone.
TEST(Box, EventsAndPoints) {
    mesh4d::EventBox box;
    box.add({2, {1, -1, 0}});
    box.add({-3, {0, 4, 2}});
    EXPECT_EQ(box.t_lo, -3);
    EXPECT_EQ(box.t_hi, 2);
    EXPECT_EQ(box.lo, (mesh4d::Vec3{0, -1, 0}));
    EXPECT_EQ(box.hi, (mesh4d::Vec3{1, 4, 2}));
    EXPECT_EQ(box.center(), (mesh4d::Vec3{0.5, 1.5, 1}));
    EXPECT_DOUBLE_EQ(box.diagonal(), std::sqrt(1.0 + 25.0 + 4.0));
    EXPECT_EQ(box.extent(), 5);
    EXPECT_TRUE(box.contains({0, {0.5, 0, 1}}, 0));
    EXPECT_FALSE(box.contains({2.5, {0.5, 0, 1}}, 0));
    EXPECT_TRUE(box.contains({2.5, {0.5, 0, 1}}, 0.5));
    mesh4d::EventBox points;
    points.addPoint({1, 2, 3});
    EXPECT_EQ(points.lo, points.hi);
    EXPECT_EQ(points.t_lo, INFINITY);  // no time added
}
