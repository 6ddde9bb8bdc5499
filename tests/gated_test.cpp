// The gated camera (raytrace and figure --gate DEPTH, pipeline/trace/raytrace.h SceneTracer::setGate):
// the Vienna experiment's composite of exposures of light-path slices (Hornof et al., Commun. Phys.
// 8, 161 (2025)), against its closed form.
//
// The scene: an orthographic camera at z = 5 looking along -z (image plane z = 5, view 1 wide, 500 x
// 300 pixels of 0.002), and a plate moving at b = 0.8 along +x (finite model) whose rest points are
// (x, -z / 2, z) for x in [0, 1], z in [-1/2, 1/2]: tilted towards the camera, so that it spans the
// depths 4.5 .. 5.5 and the image rows y = -z / 2. Its left edge (x = 0) is at 0.8 t at time t.
//   Ungated (finite): the point at depth s = 5 - z is seen as it was at t_c - s, so at t_c = 5 the
//     edge in image row y (z = -2 y) is at x = 0.8 (5 - s) = 0.8 z: a straight slanted edge.
//   Gated by DEPTH: slice j = floor(s / DEPTH) shows it as it was at t_c - (j + 1/2) DEPTH, so the
//     edge is at x = 0.8 (5 - (j + 1/2) DEPTH): a staircase, a step of 0.8 DEPTH at each slice
//     boundary, rows within a slice on one column.
// Its mean distance from the ungated edge is 0.8 DEPTH / 4 (a sawtooth of amplitude 0.8 DEPTH / 2),
// so it halves as DEPTH halves.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "pipeline/trace/raytrace.h"
#include "quiet_stage.h"
#include "temp_dir.h"

using namespace apparent;

namespace {

constexpr int kWidth = 500, kHeight = 300;

// Per image row, the first column showing the plate (-1: none).
std::vector<int> leftEdges(const Stage& stage, double gate) {
    SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, Model::Finite, 0, 0);
    tracer.setGate(gate);
    const TracedFrame frame = tracer.traceFrame(0, kWidth, kHeight);
    std::vector<int> edges(kHeight, -1);
    for (int py = 0; py < kHeight; ++py)
        for (int px = 0; px < kWidth && edges[size_t(py)] < 0; ++px)
            if (frame.object[size_t(py) * kWidth + size_t(px)] == 0) edges[size_t(py)] = px;
    return edges;
}

double rowY(int py) { return (1 - 2 * (py + 0.5) / kHeight) * 0.5 * kHeight / kWidth; }
// The first pixel column whose centre lies at or right of image x.
int columnAt(double x) { return int(std::ceil((x + 0.5) * kWidth - 0.5)); }

class Gated : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string dir = testio::processTempDir();
        std::ofstream(dir + "gated_plate.obj") << "v 0 0.25 -0.5\nv 1 0.25 -0.5\nv 1 -0.25 0.5\nv 0 -0.25 0.5\nf 1 2 3\nf 1 3 4\n";
        std::ofstream(dir + "gated.json")
            << R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "projection": "orthographic", "width": 1},
                   "frames": {"start": 5, "end": 6, "fps": 1}, "model": "finite", "tolerance": "vertex",
                   "objects": [{"name": "plate", "mesh": "gated_plate.obj", "velocity": [0.8, 0, 0]}]})";
        std::string error;
        ASSERT_TRUE(loadQuietStage(dir + "gated.json", &stage_, &error, {Model::Finite})) << error;
    }
    Stage stage_;
};

}  // namespace

TEST_F(Gated, SlicesOf6cmShowAStepAtEachBoundary) {
    const double gate = 0.06;
    const std::vector<int> edges = leftEdges(stage_, gate);
    int checked = 0, steps = 0, last = -1;
    for (int py = 0; py < kHeight; ++py) {
        const double y = rowY(py), z = -2 * y, s = 5 - z;
        if (std::fabs(y) > 0.249) continue;  // off the plate's ends
        const double j = std::floor(s / gate);
        // Rows within a pixel of a slice boundary may fall either way.
        if (s - j * gate < 0.004 || (j + 1) * gate - s < 0.004) continue;
        const int expected = columnAt(0.8 * (5 - (j + 0.5) * gate));
        EXPECT_NEAR(edges[size_t(py)], expected, 1) << "row " << py << ", depth " << s;
        if (last >= 0 && std::abs(edges[size_t(py)] - last) >= 20) ++steps;  // 0.8 x 0.06 = 24 pixels
        last = edges[size_t(py)];
        ++checked;
    }
    EXPECT_GT(checked, 200);
    // The plate spans 1 in depth: 16 or 17 boundaries, each a step of about 24 pixels.
    EXPECT_GE(steps, 15);
    // Ungated: the straight edge x = 0.8 z.
    const std::vector<int> smooth = leftEdges(stage_, 0);
    for (int py = 0; py < kHeight; ++py)
        if (std::fabs(rowY(py)) < 0.249) EXPECT_NEAR(smooth[size_t(py)], columnAt(-1.6 * rowY(py)), 1) << "row " << py;
}

TEST_F(Gated, ConvergesToTheUngatedPicture) {
    const std::vector<int> smooth = leftEdges(stage_, 0);
    double previous = INFINITY;
    for (double gate : {0.06, 0.03, 0.015, 0.0075}) {
        const std::vector<int> edges = leftEdges(stage_, gate);
        double sum = 0;
        int n = 0;
        for (int py = 0; py < kHeight; ++py) {
            if (smooth[size_t(py)] < 0 || edges[size_t(py)] < 0) continue;
            sum += std::abs(edges[size_t(py)] - smooth[size_t(py)]);
            ++n;
        }
        const double mean = sum / n;  // pixels; expected 0.8 gate / 4 / 0.002
        std::cout << "gate " << gate << ": mean edge distance " << mean << " px (closed form " << 100 * gate << ")\n";
        EXPECT_NEAR(mean, 100 * gate, 0.35 + 0.1 * 100 * gate);
        EXPECT_LT(mean, 0.65 * previous);
        previous = mean;
    }
}
