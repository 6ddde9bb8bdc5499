// The scene's units (pipeline/input/units.h, scene field `units`): a scene in metres
// (positions p metres, frame times t seconds) gives the output of the light-second scene with
// positions p / c at the same times, times c, to 1e-12 relative; its labels read in ns. And an
// oracle in metres: the instant model shows a vertex at p + s q + v c (t - t0) metres.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "pipeline/stage/frame_cut.h"
#include "pipeline/trace/figure.h"
#include "quiet_stage.h"
#include "run_command.h"
#include "temp_dir.h"

using namespace apparent;
using mesh4d::Vec3;

namespace {

// A box of edge `scale` at `p` moving at 0.8c along x, seen from `eye`; lengths multiplied by
// `k` as written (1 for metres, 1 / c for the light-second twin). Frames every 10 ns over 200 ns.
std::string boxScene(const std::filesystem::path& dir, const std::string& name, const char* units, double k) {
    std::filesystem::copy_file(std::filesystem::path(APPARENT_SOURCE_DIR) / "data/meshes/box.obj", dir / "box.obj",
                               std::filesystem::copy_options::overwrite_existing);
    std::ostringstream s;
    s.precision(17);
    s << "{ " << (units ? std::string(R"("units": ")") + units + "\", " : "") << R"("camera": {"position": [)" << 0.5 * k
      << ", " << 1.0 * k << ", 0], \"look_at\": [0, 0, " << -30 * k << R"(]},
      "frames": {"start": 0, "end": 2e-7, "fps": 1e8},
      "objects": [{"mesh": "box.obj", "scale": )" << 2 * k << R"(, "position": [)" << -12 * k << ", " << 0.25 * k << ", "
      << -30 * k << R"(], "t0": 5e-8, "velocity": [0.8, 0, 0]}] })";
    const auto path = dir / name;
    std::ofstream(path) << s.str();
    return path.string();
}

}  // namespace

TEST(Units, AMetreSceneIsTheLightSecondSceneTimesC) {
    const std::filesystem::path dir = testio::processTempDir() + "units";
    std::filesystem::create_directories(dir);
    const std::string metres = boxScene(dir, "metres.json", "m", 1), ls = boxScene(dir, "ls.json", nullptr, 1 / kSpeedOfLight);
    for (Model model : {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted}) {
        Stage sm, sl;
        std::string error;
        ASSERT_TRUE(loadQuietStage(metres, &sm, &error, {model})) << error;
        ASSERT_TRUE(loadQuietStage(ls, &sl, &error, {model})) << error;
        const FrameCutter cm(sm, model), cl(sl, model);
        double worst = 0;
        for (long long k : {0LL, 7LL, 13LL, 19LL}) {
            const double t = frameTime(sm.scene.frames, k);
            ExportFrame fm, fl;
            ASSERT_TRUE(cm.cut(t, 0, &fm, &error)) << error;
            ASSERT_TRUE(cl.cut(t, 0, &fl, &error)) << error;
            EXPECT_EQ(fm.units, "metres, seconds, speeds as fractions of c");
            EXPECT_EQ(fl.units, "");
            ASSERT_EQ(fm.objects[0].positions.size(), fl.objects[0].positions.size()) << modelName(model) << " " << k;
            ASSERT_GT(fm.objects[0].positions.size(), 0u);
            for (size_t i = 0; i < fm.objects[0].positions.size(); ++i) {
                const Vec3 a = fm.objects[0].absolutePosition(i), b = fl.objects[0].absolutePosition(i) * kSpeedOfLight;
                const double rel = mesh4d::norm(a - b) / mesh4d::norm(b);
                worst = std::max(worst, rel);
                EXPECT_LE(rel, 1e-12) << modelName(model) << " frame " << k << " point " << i;
                const double ta = fm.objects[0].absoluteTime(i), tb = fl.objects[0].absoluteTime(i);
                EXPECT_LE(std::fabs(ta - tb), 1e-12 * std::fabs(tb)) << modelName(model) << " frame " << k;
            }
        }
        std::cout << "[units] " << modelName(model) << ": worst relative difference " << worst << "\n";
    }
    // Its labels read in ns, the light-second twin's too (its times are the same).
    Stage sm;
    std::string error;
    ASSERT_TRUE(loadQuietStage(metres, &sm, &error)) << error;
    EXPECT_EQ(cameraTimeLabel(sm.scene, 3), "t = 30 ns");
    EXPECT_EQ(cameraTimeLabel(sm.scene, 19), "t = 190 ns");
}

// The instant model in metres against the closed form: input vertex q of the box (edge 2 m) at
// p + 2 q + (0.8 c) (t - t0) x, metres.
TEST(Units, TheInstantModelInMetresMovesAtEightTenthsOfC) {
    const std::filesystem::path dir = testio::processTempDir() + "units_oracle";
    std::filesystem::create_directories(dir);
    const std::string metres = boxScene(dir, "metres.json", "m", 1);
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage(metres, &stage, &error, {Model::Instant})) << error;
    const FrameCutter cutter(stage, Model::Instant);
    const double t = 1.3e-7;
    ExportFrame frame;
    ASSERT_TRUE(cutter.cut(t, 0, &frame, &error)) << error;
    const Vec3 corner{-0.5, -0.5, -0.5};  // box.obj's first vertex
    const Vec3 expect = Vec3{-12, 0.25, -30} + 2 * corner + Vec3{0.8 * kSpeedOfLight * (t - 5e-8), 0, 0};
    const Vec3 got = frame.objects[0].absolutePosition(0);
    EXPECT_NEAR(got.x, expect.x, 1e-12 * 30);
    EXPECT_NEAR(got.y, expect.y, 1e-12 * 30);
    EXPECT_NEAR(got.z, expect.z, 1e-12 * 30);
}

// The outputs say their units; a figure's summary and labels read in ns; unknown units are refused.
TEST(Units, OutputsAndMessagesUseTheScenesUnits) {
    const std::filesystem::path dir = testio::processTempDir() + "units_outputs";
    std::filesystem::create_directories(dir);
    const std::string metres = boxScene(dir, "metres.json", "m", 1);
    auto r = testcli::apparentRun({"render", metres, "--out", (dir / "out").string(), "--format", "glb,ply,obj",
                                   "--frames", "3:4", "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    auto read = [](const std::filesystem::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string ply = read(dir / "out/relativistic/frame_00003.ply"), obj = read(dir / "out/relativistic/frame_00003.obj");
    EXPECT_NE(ply.find("\ncomment units: metres, seconds, speeds as fractions of c\n"), std::string::npos);
    EXPECT_NE(obj.find("\n# units: metres, seconds, speeds as fractions of c\n"), std::string::npos);
    EXPECT_NE(read(dir / "out/relativistic.glb").find(R"("units":"metres, seconds, speeds as fractions of c")"),
              std::string::npos);
    // --tolerance T is in the scene's units too: the .glb's extras give it back in metres.
    r = testcli::apparentRun({"render", metres, "--out", (dir / "tol").string(), "--frames", "3:4", "--tolerance", "0.01",
                              "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string glb = read(dir / "tol/relativistic.glb");
    const size_t at = glb.find("\"tolerance\":");
    ASSERT_NE(at, std::string::npos);
    EXPECT_NEAR(std::stod(glb.substr(at + 12, 30)), 0.01, 1e-15);
    r = testcli::apparentRun({"figure", metres, "--out", (dir / "sheet.png").string(), "--frames", "3:5", "--size",
                              "64x36", "--samples", "1"});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("frames 3 (t = 30 ns) 4 (t = 40 ns)"), std::string::npos) << r.out;
    std::ofstream(dir / "km.json") << R"({ "units": "km", "objects": [{"mesh": "box.obj"}] })";
    r = testcli::apparentRun({"render", (dir / "km.json").string(), "--out", (dir / "km").string()});
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("km.json: units: unknown units 'km' (ls: light-seconds and seconds, the default; m: metres"),
              std::string::npos)
        << r.err;
}
