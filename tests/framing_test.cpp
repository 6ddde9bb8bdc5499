// `figure --frame-objects` (pipeline/stage/framing.h) against closed forms: a unit box at rest, and a unit
// box at 0.6c in the contracted model (its Lorentz-contracted shape at the frame time, a box of
// length 1/gamma) seen at two times when it is symmetric about the view axis. By symmetry the
// framed camera looks along the axis; the box's extreme points are the near face's corners, at
// x/z and y/z on the image plane, so the field of view is 2 atan((1 + margin) max(y/z, x/z H/W)).
// And the objects framed: the moving ones, not a floor at rest.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mesh4d/angles.h"
#include "pipeline/stage/framing.h"
#include "box_scene.h"
#include "run_command.h"
#include "exporters/png.h"

using namespace apparent;
using mesh4d::Vec3;

namespace {

constexpr int kWidth = 160, kHeight = 90;

double expectedFov(double hx, double hy) {
    return 2 * std::atan((1 + kFramingMargin) * std::max(hy, hx * kHeight / kWidth)) * 180 / mesh4d::kPi;
}

void expectAlongAxis(const CameraSpec& camera) {
    const Vec3 f = (camera.look_at - camera.position) / mesh4d::norm(camera.look_at - camera.position);
    EXPECT_NEAR(f.x, 0, 1e-12);
    EXPECT_NEAR(f.y, 0, 1e-12);
    EXPECT_NEAR(f.z, -1, 1e-12);
}

}  // namespace

// A box at rest 6 ls ahead, the camera looking away from it: turned onto it, the view its near face.
TEST(Framing, ABoxAtRestFillsTheView) {
    BoxScene f;
    loadBoxScene("framing_rest", R"({ "camera": {"position": [0, 0, 0], "look_at": [3, 2, -6], "fov_deg": 60},
        "frames": {"start": 0, "end": 1, "fps": 1}, "objects": [{"mesh": "box.obj", "position": [0, 0, -6]}] })", &f);
    CameraSpec camera = f.stage.scene.camera;
    const Status s = frameObjects(f.stage, {Model::Relativistic, Model::Instant}, {0}, kWidth, kHeight, &camera);
    ASSERT_TRUE(s.ok) << s.message;
    expectAlongAxis(camera);
    EXPECT_NEAR(camera.fov_deg, expectedFov(0.5 / 5.5, 0.5 / 5.5), 1e-9);
}

// A box at 0.6c (gamma 1.25, length 0.8) in the contracted model at t = -2 and 2, centred at
// x = -1.2 and 1.2: the near face's outer corners are at x = +-1.6, y = +-0.5, z = -5.5. A floor
// at rest is left out.
TEST(Framing, AMovingBoxIsFramedOverTheChosenTimes) {
    BoxScene f;
    loadBoxScene("framing_moving", R"({ "camera": {"position": [0, 0, 0], "look_at": [0, 1, -6], "fov_deg": 20},
        "frames": {"start": -2, "end": 2.5, "fps": 1},
        "objects": [{"name": "box", "mesh": "box.obj", "position": [0, 0, -6], "velocity": [0.6, 0, 0]},
                    {"name": "floor", "mesh": "box.obj", "position": [0, -3, -6], "scale": [40, 0.1, 40]}] })", &f);
    EXPECT_EQ(framedObjects(f.stage), std::vector<size_t>{0});
    CameraSpec camera = f.stage.scene.camera;
    const Status s = frameObjects(f.stage, {Model::Contracted}, {0, 4}, kWidth, kHeight, &camera);
    ASSERT_TRUE(s.ok) << s.message;
    expectAlongAxis(camera);
    EXPECT_NEAR(camera.fov_deg, expectedFov(1.6 / 5.5, 0.5 / 5.5), 1e-9);
    // The look_at keeps its distance.
    EXPECT_NEAR(mesh4d::norm(camera.look_at), std::hypot(1.0, 6.0), 1e-12);
}

// Nothing to frame in view: one line.
TEST(Framing, RefusesWhatItCannotFrame) {
    BoxScene f;
    loadBoxScene("framing_none", R"({ "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
        "frames": {"start": 0, "end": 1, "fps": 1},
        "objects": [{"mesh": "box.obj", "position": [0, 0, -6], "exists": [50, 60]}] })", &f);
    CameraSpec camera = f.stage.scene.camera;
    const Status s = frameObjects(f.stage, {Model::Relativistic}, {0}, kWidth, kHeight, &camera);
    EXPECT_FALSE(s.ok);
    EXPECT_NE(s.message.find("--frame-objects: no object to frame is seen"), std::string::npos) << s.message;
}

// End to end: the Terrell cube's figure framed; over its panels the cube reaches to within the
// margin (plus two pixels) of both edges of the panel along the axis that limits the view, and
// never touches an edge.
TEST(Framing, FigureFramesTheTerrellCube) {
    testcli::TempDir dir;
    std::filesystem::create_directories(dir.str());
    const std::string out = (dir / "framed.png").string();
    const auto r = testcli::apparentRun({"figure", testcli::source("data/scenes/terrell_cube.json"), "--models",
                                         "contracted,relativistic", "--times", "3,4,5", "--size", "160x90", "--samples",
                                         "1", "--no-labels", "--frame-objects", "--out", out});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("framed: camera.look_at"), std::string::npos) << r.out;
    RgbImage sheet;
    std::string error;
    ASSERT_TRUE(readPng(out, &sheet, &error)) << error;
    constexpr int kGap = 4;
    const uint8_t* background = sheet.pixel(kGap, kGap);  // the first panel's corner, outside the framed extent
    int x_lo = kWidth, x_hi = -1, y_lo = kHeight, y_hi = -1;
    for (int row = 0; row < 2; ++row)
        for (int col = 0; col < 3; ++col)
            for (int y = 0; y < kHeight; ++y)
                for (int x = 0; x < kWidth; ++x) {
                    const uint8_t* p = sheet.pixel(kGap + col * (kWidth + kGap) + x, kGap + row * (kHeight + kGap) + y);
                    if (std::equal(p, p + 3, background)) continue;
                    x_lo = std::min(x_lo, x);
                    x_hi = std::max(x_hi, x);
                    y_lo = std::min(y_lo, y);
                    y_hi = std::max(y_hi, y);
                }
    ASSERT_GE(x_hi, 0);
    EXPECT_GT(x_lo, 0);
    EXPECT_GT(y_lo, 0);
    EXPECT_LT(x_hi, kWidth - 1);
    EXPECT_LT(y_hi, kHeight - 1);
    const double mx = kWidth / 2.0 * (1 - 1 / (1 + kFramingMargin)), my = kHeight / 2.0 * (1 - 1 / (1 + kFramingMargin));
    const bool fills_x = x_lo <= mx + 2 && kWidth - 1 - x_hi <= mx + 2;
    const bool fills_y = y_lo <= my + 2 && kHeight - 1 - y_hi <= my + 2;
    EXPECT_TRUE(fills_x || fills_y) << "x " << x_lo << ".." << x_hi << ", y " << y_lo << ".." << y_hi;
}
