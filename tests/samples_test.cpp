// The raytracer's anti-aliasing (pipeline/trace/raytrace.h SceneTracer::setSamplesSide, `--samples N`): a
// flat face, a 2 x 2 square at rest face-on 3.265 ls ahead, whose outline projects to a rectangle known
// in closed form. With 4, 9 and 16 samples the picture differs from the 1-sample picture only in
// pixels that the rectangle's outline crosses, and there each pixel shows the share of it that the
// rectangle covers (exact area of the overlap) to within one stratum per axis.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "mesh4d/angles.h"
#include "pipeline/trace/raytrace.h"
#include "quiet_stage.h"
#include "srgb.h"
#include "temp_dir.h"

using namespace apparent;

namespace {

constexpr int kWidth = 64, kHeight = 36;
constexpr double kFovDeg = 60, kDepth = 3.265, kHalf = 1;  // the outline at about 0.45 of a pixel

// The rectangle's extent in pixel coordinates (x right, y down, pixel px spans [px, px + 1]).
struct Rect {
    double x0, x1, y0, y1;
};
Rect projected() {
    const double half_h = std::tan(kFovDeg * mesh4d::kPi / 360), half_w = half_h * kWidth / kHeight;
    const double s = kHalf / kDepth;  // the image-plane half-size at distance 1
    return {(-s / half_w + 1) * kWidth / 2, (s / half_w + 1) * kWidth / 2, (1 - s / half_h) * kHeight / 2,
            (1 + s / half_h) * kHeight / 2};
}

// The share of pixel (px, py) inside the rectangle.
double coverage(const Rect& r, int px, int py) {
    const double w = std::max(0.0, std::min(r.x1, px + 1.0) - std::max(r.x0, double(px)));
    const double h = std::max(0.0, std::min(r.y1, py + 1.0) - std::max(r.y0, double(py)));
    return w * h;
}

}  // namespace

TEST(Samples, AntiAliasedFlatFaceDiffersOnlyAtItsEdges) {
    const std::filesystem::path dir = testio::processTempDir() + "samples";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "square.obj") << "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n";
    std::ofstream(dir / "scene.json") << R"({ "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_deg": )"
                                      << kFovDeg << R"(}, "frames": {"start": 0, "end": 0.1, "fps": 10},
      "objects": [{"mesh": "square.obj", "position": [0, 0, -)" << kDepth << R"(]}] })";
    Stage stage;
    std::string error;
    ASSERT_TRUE(loadQuietStage((dir / "scene.json").string(), &stage, &error, {Model::Relativistic})) << error;
    const Rect r = projected();
    // The outline must cut pixels, not run along their borders.
    for (double e : {r.x0, r.x1, r.y0, r.y1}) ASSERT_GT(std::fabs(e - std::round(e)), 0.05) << e;
    SceneTracer one(stage.scene, stage.objects, stage.mirrors, Model::Relativistic, 0, 0);
    const TracedFrame base = one.traceFrame(0, kWidth, kHeight);
    // The face's and the background's levels in the 1-sample picture (centre and corner pixels).
    const int face = base.image.pixel(kWidth / 2, kHeight / 2)[0], back = base.image.pixel(0, 0)[0];
    ASSERT_GT(face - back, 60);
    const double lin_face = testio::srgbToLinear(face), lin_back = testio::srgbToLinear(back);
    for (int side : {2, 3, 4}) {
        SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, Model::Relativistic, 0, 0);
        tracer.setSamplesSide(side);
        const TracedFrame aa = tracer.traceFrame(0, kWidth, kHeight);
        int edge_pixels = 0, changed = 0;
        double worst = 0;
        for (int py = 0; py < kHeight; ++py)
            for (int px = 0; px < kWidth; ++px) {
                const double c = coverage(r, px, py);
                const bool same = std::equal(aa.image.pixel(px, py), aa.image.pixel(px, py) + 3, base.image.pixel(px, py));
                changed += !same;
                if (c == 0 || c == 1) {
                    EXPECT_TRUE(same) << "side " << side << " pixel " << px << "," << py << " coverage " << c;
                    continue;
                }
                ++edge_pixels;
                const double shown = (testio::srgbToLinear(aa.image.pixel(px, py)[0]) - lin_back) / (lin_face - lin_back);
                worst = std::max(worst, std::fabs(shown - c));
                EXPECT_NEAR(shown, c, 1.0 / side + 0.02) << "side " << side << " pixel " << px << "," << py;
            }
        EXPECT_GT(changed, 0) << side;
        EXPECT_LE(changed, edge_pixels) << side;
        std::cout << "[samples] " << side * side << " samples: " << changed << " of " << edge_pixels
                  << " edge pixels changed, worst coverage error " << worst << "\n";
    }
}

// --samples on the command line: a square of 1..16 only.
TEST(Samples, SideOfASquareOnly) {
    EXPECT_EQ(samplesSide(1), 1);
    EXPECT_EQ(samplesSide(9), 3);
    EXPECT_EQ(samplesSide(256), 16);
    EXPECT_EQ(samplesSide(0), 0);
    EXPECT_EQ(samplesSide(8), 0);
    EXPECT_EQ(samplesSide(289), 0);
}
