// The pipeline's 4D stage: each object is extruded only over the proper-time span the requested
// frames can see, and only the ends of its existence become clipping caps.
#include <gtest/gtest.h>

#include "mesh4d/robust.h"
#include "pipeline/stage/worlds.h"

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

// takeWorlds (render's last model) hands each rest mesh to its world instead of copying it: the
// worlds are those buildWorlds makes from the untouched meshes, bit for bit, also where the
// camera's motion turns the rest points (Thomas-Wigner rotation, applied in place there), and
// the objects' meshes are left empty.
TEST(Render, TakeWorldsEqualsBuildWorlds) {
    Scene scene;
    std::vector<PreparedObject> objects;
    ASSERT_NO_FATAL_FAILURE(loadPrepared("data/scenes/flanges.json", &scene, &objects));
    Scene moving = scene;  // a camera moving across the flanges' motion: their rest points turn
    moving.camera.velocity = {0, 0.6, 0};
    ASSERT_TRUE(cutMotionOf(objects[0].spec, Model::Relativistic, moving).rotated);
    for (const Scene* s : {&scene, &moving})
        for (Model model : {Model::Finite, Model::Relativistic}) {
            const std::vector<mesh4d::World4D> copied = buildWorlds(objects, model, *s, 20, 60);
            std::vector<PreparedObject> taken_from = objects;
            const std::vector<mesh4d::World4D> taken = takeWorlds(&taken_from, model, *s, 20, 60);
            ASSERT_EQ(taken.size(), copied.size());
            for (size_t i = 0; i < copied.size(); ++i) {
                const mesh4d::World4D &a = copied[i], &b = taken[i];
                EXPECT_TRUE(taken_from[i].rest.positions.empty() && taken_from[i].rest.triangles.empty());
                ASSERT_FALSE(a.empty());
                EXPECT_EQ(a.tau_a, b.tau_a);
                EXPECT_EQ(a.tau_b, b.tau_b);
                ASSERT_EQ(a.mesh.positions.size(), b.mesh.positions.size());
                for (size_t v = 0; v < a.mesh.positions.size(); ++v) {
                    EXPECT_EQ(a.mesh.positions[v].x, b.mesh.positions[v].x);
                    EXPECT_EQ(a.mesh.positions[v].y, b.mesh.positions[v].y);
                    EXPECT_EQ(a.mesh.positions[v].z, b.mesh.positions[v].z);
                }
                EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
                ASSERT_EQ(a.events.size(), b.events.size());
                for (size_t e = 0; e < a.events.size(); ++e) {
                    EXPECT_EQ(a.events[e].t, b.events[e].t);
                    EXPECT_EQ(a.events[e].x.x, b.events[e].x.x);
                    EXPECT_EQ(a.events[e].x.y, b.events[e].x.y);
                    EXPECT_EQ(a.events[e].x.z, b.events[e].x.z);
                }
                EXPECT_EQ(a.slot_next, b.slot_next);
                EXPECT_EQ(a.triangle_edges, b.triangle_edges);
                ASSERT_EQ(a.edges.size(), b.edges.size());
                for (size_t e = 0; e < a.edges.size(); ++e) EXPECT_TRUE(a.edges[e].lo == b.edges[e].lo && a.edges[e].hi == b.edges[e].hi);
                EXPECT_EQ(a.shape_radius, b.shape_radius);
            }
        }
}
