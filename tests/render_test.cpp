// The pipeline's 4D stage: each object is extruded only over the proper-time span the requested
// frames can see, and only the ends of its existence become clipping caps.
#include <gtest/gtest.h>

#include "mesh4d/robust.h"
#include "pipeline/worlds.h"

using namespace apparent;

namespace {
std::string source(const std::string& rel) { return std::string(APPARENT_SOURCE_DIR) + "/" + rel; }

// Loads a shipped scene and its meshes, as `apparent render` does before the 4D stage.
void loadPrepared(const std::string& rel, Scene* scene, std::vector<PreparedObject>* objects) {
    ASSERT_TRUE(loadScene(source(rel), scene).ok);
    std::ostringstream log;
    ASSERT_TRUE(prepareObjects(*scene, {}, objects, log, true).ok);
}
}  // namespace

TEST(Render, ExtrudesOnlyTheSpanTheFramesSee) {
    Scene scene;
    std::vector<PreparedObject> objects;
    ASSERT_NO_FATAL_FAILURE(loadPrepared("data/scenes/flanges.json", &scene, &objects));
    for (Model model : {Model::Finite, Model::Relativistic}) {
        const mesh4d::World4D all = buildWorld(objects[0], model, scene, 0, 199);
        const mesh4d::World4D few = buildWorld(objects[0], model, scene, 95, 104);
        // The object always exists, so both caps are open; the span is finite and shrinks with the frames.
        EXPECT_FALSE(all.cap_a_real || all.cap_b_real);
        EXPECT_TRUE(std::isfinite(all.tau_a) && std::isfinite(all.tau_b));
        EXPECT_LT(few.tau_b - few.tau_a, all.tau_b - all.tau_a);
        // Every vertex's crossing in every requested frame lies inside the extruded span.
        for (long long k = 95; k <= 104; ++k) {
            const mesh4d::ViewSurface view = viewForFrame(scene, model, k);
            for (size_t i = 0; i < few.mesh.positions.size(); ++i) {
                EXPECT_GE(mesh4d::viewSide(view, few.events[2 * i]), 0) << k;
                EXPECT_LE(mesh4d::viewSide(view, few.events[2 * i + 1]), 0) << k;
            }
        }
        // Frames 95..104 cover 0.9 s of camera time; emission times advance at most 1/(1 - b)
        // times faster (the Doppler factor of an approaching source), and the span is padded at
        // each end by the flange's diagonal sqrt(2^2 + 4^2 + 2^2) over (1 - b) (render.cpp).
        const double bound = (0.9 + 2 * std::sqrt(24.0)) / (1 - 0.866);
        EXPECT_LT(few.tau_b - few.tau_a, bound);
    }
}

TEST(Render, ExistenceEndsBecomeRealCaps) {
    Scene scene;
    std::vector<PreparedObject> objects;
    ASSERT_NO_FATAL_FAILURE(loadPrepared("data/fixtures/scene_exists_window.json", &scene, &objects));
    const mesh4d::World4D w = buildWorld(objects[0], Model::Relativistic, scene, 0, frameCount(scene.frames) - 1);
    EXPECT_TRUE(w.cap_a_real);
    EXPECT_TRUE(w.cap_b_real);
    EXPECT_EQ(w.tau_a, 0.0);
    EXPECT_EQ(w.tau_b, 3.0);
    // Frames that see none of the existence give an empty world.
    Scene late = scene;
    late.frames.start = 1000;
    late.frames.end = 1001;
    EXPECT_TRUE(buildWorld(objects[0], Model::Relativistic, late, 0, 0).empty());
}
