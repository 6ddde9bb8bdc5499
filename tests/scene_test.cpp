// Scene loading: valid scenes load with their fields; each malformed fixture fails with one line
// naming the file, the field and the problem.
#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <functional>

#include "pipeline/input/scene.h"

#include "temp_dir.h"

using namespace apparent;

namespace {
std::string fixture(const std::string& name) { return std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/" + name; }
}  // namespace

TEST(Scene, LoadsTheDefaultFlangeScene) {
    Scene s;
    const std::string path = std::string(APPARENT_SOURCE_DIR) + "/data/scenes/flanges.json";
    const Status st = loadScene(path, &s);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(s.model, Model::Relativistic);
    ASSERT_EQ(s.objects.size(), 4u);  // two flanges, the stage floor, the mirrored backdrop
    EXPECT_DOUBLE_EQ(s.objects[0].velocity.x, 0.866);
    EXPECT_TRUE(s.objects[3].mirror);
    EXPECT_FALSE(s.objects[0].mirror);
    EXPECT_DOUBLE_EQ(s.camera.instant_delay, 18.675);
    EXPECT_EQ(s.light.kind, LightSpec::Kind::Point);
    EXPECT_EQ(frameCount(s.frames), 200);
    // Relative mesh paths resolve against the scene's folder.
    EXPECT_NE(s.objects[0].mesh_path.find("data/meshes/flange.obj"), std::string::npos) << s.objects[0].mesh_path;
    EXPECT_TRUE(s.objects[0].exists_from < -1e300 && s.objects[0].exists_to > 1e300);
}

TEST(Scene, FrameCountFollowsTheDefinition) {
    // k = 0, 1, ... while start + k / fps < end.
    EXPECT_EQ(frameCount({0, 20, 10}), 200);
    EXPECT_EQ(frameCount({0, 1, 3}), 3);           // 0, 1/3, 2/3
    EXPECT_EQ(frameCount({0, 1.05, 10}), 11);      // 0 .. 1.0
    EXPECT_EQ(frameCount({10, 10.5, 10}), 5);      // 10.0 .. 10.4
    EXPECT_EQ(frameCount({0, 0.3, 10}), 3);        // 0, 0.1, 0.2 (0.3 excluded even with rounding)
    EXPECT_DOUBLE_EQ(frameTime({5, 10, 4}, 3), 5.75);
}

struct BadScene {
    const char* file;
    const char* expected;  // a substring of the one-line message
};

void PrintTo(const BadScene& b, std::ostream* os) { *os << b.file << " -> " << b.expected; }

class SceneErrors : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneErrors, NameFileFieldAndProblem) {
    Scene s;
    Status st = loadScene(fixture(GetParam().file), &s);
    if (st.ok) st = checkSceneForModel(s, Model::Relativistic);
    ASSERT_FALSE(st.ok);
    EXPECT_NE(st.message.find(GetParam().file), std::string::npos) << st.message;
    EXPECT_NE(st.message.find(GetParam().expected), std::string::npos) << st.message;
    EXPECT_EQ(st.message.find('\n'), std::string::npos) << "one line: " << st.message;
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, SceneErrors,
    ::testing::Values(BadScene{"scene_malformed.json", "invalid JSON"},
                      BadScene{"scene_malformed.json", "line 3"},
                      BadScene{"scene_superluminal.json", "objects[0].velocity: |velocity| = 1.2 must be < 1"},
                      BadScene{"scene_unknown_field.json", "objects[0].velocty: unknown field"},
                      BadScene{"scene_bad_exists.json", "objects[0].exists: from (5) must be less than to (1)"},
                      BadScene{"scene_bad_vector.json", "objects[0].position: expected an array of 3 numbers"},
                      BadScene{"no_such_scene.json", "cannot open scene file"}),
    [](const ::testing::TestParamInfo<BadScene>& info) {
        std::string name = std::string(info.param.file).substr(0, std::string(info.param.file).find('.'));
        return name + "_" + std::to_string(info.index);
    });

TEST(Scene, SuperluminalIsAllowedOnlyInTheInstantModel) {
    Scene s;
    ASSERT_TRUE(loadScene(fixture("scene_superluminal.json"), &s).ok);
    EXPECT_TRUE(checkSceneForModel(s, Model::Instant).ok);
    for (Model m : {Model::Finite, Model::Relativistic, Model::Contracted}) EXPECT_FALSE(checkSceneForModel(s, m).ok);
}

// A scene authored in glTF (node and scene extras, a camera node) loads into the same scene as
// its JSON twin; the two files are written independently (data/scenes/make_flanges_gltf.py).
TEST(Scene, GltfSceneMatchesItsJsonTwin) {
    Scene js, gs;
    ASSERT_TRUE(loadScene(std::string(APPARENT_SOURCE_DIR) + "/data/scenes/flanges.json", &js).ok);
    const Status st = loadScene(std::string(APPARENT_SOURCE_DIR) + "/data/scenes/flanges.gltf", &gs);
    ASSERT_TRUE(st.ok) << st.message;
    ASSERT_EQ(gs.objects.size(), js.objects.size());
    EXPECT_EQ(gs.model, js.model);
    EXPECT_EQ(frameCount(gs.frames), frameCount(js.frames));
    EXPECT_NEAR(gs.camera.fov_deg, js.camera.fov_deg, 1e-9);
    EXPECT_EQ(gs.camera.instant_delay, js.camera.instant_delay);
    EXPECT_EQ(gs.light.position, js.light.position);
    EXPECT_EQ(gs.light.ambient, js.light.ambient);
    for (size_t i = 0; i < js.objects.size(); ++i) {
        EXPECT_EQ(gs.objects[i].name, js.objects[i].name);
        EXPECT_EQ(gs.objects[i].position, js.objects[i].position);
        EXPECT_EQ(gs.objects[i].velocity, js.objects[i].velocity);
        EXPECT_EQ(gs.objects[i].t0, js.objects[i].t0);
        EXPECT_EQ(gs.objects[i].mirror, js.objects[i].mirror);
        EXPECT_NE(gs.objects[i].mesh_path.find("flanges.gltf#" + js.objects[i].name), std::string::npos);
    }
}

TEST(Scene, GltfSceneErrorsNameTheNode) {
    const std::pair<const char*, const char*> cases[] = {
        {"scene_superluminal.gltf", "nodes[1].extras.velocity: |velocity| = 1.5 must be < 1"},
        {"scene_no_objects.gltf", "no node carries object extras"},
        {"scene_duplicate_names.gltf", "nodes[2].name: 'flange-a' names two object nodes"},
    };
    for (const auto& [file, expected] : cases) {
        Scene s;
        Status st = loadScene(std::string(APPARENT_SOURCE_DIR) + "/data/fixtures/gltf/" + file, &s);
        if (st.ok) st = checkSceneForModel(s, Model::Relativistic);
        ASSERT_FALSE(st.ok) << file;
        EXPECT_NE(st.message.find(expected), std::string::npos) << st.message;
    }
}

// Speeds stated exactly: direction with gamma or rapidity; velocity is derived, and mixing the
// two forms is refused.
// Writes scene text beside a tetrahedron "tetra.obj" in the process's temporary folder; returns its path.
std::function<std::string(const std::string&, const std::string&)> tetraSceneWriter() {
    const std::string dir = testio::processTempDir();
    std::ofstream(dir + "tetra.obj") << "v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\nf 1 2 4\nf 1 3 2\nf 1 4 3\nf 2 3 4\n";
    return [dir](const std::string& name, const std::string& text) {
        std::ofstream(dir + name) << text;
        return dir + name;
    };
}

TEST(Scene, ExactSpeedAsGammaOrRapidity) {
    const auto write = tetraSceneWriter();
    Scene s;
    ASSERT_TRUE(loadScene(write("g.json", R"({"objects":[{"mesh":"tetra.obj","direction":[0,0,2],"gamma":1e7}]})"), &s).ok);
    EXPECT_EQ(s.objects[0].speed, ObjectSpec::Speed::Gamma);
    EXPECT_EQ(s.objects[0].direction, (mesh4d::Vec3{0, 0, 1}));
    EXPECT_EQ(s.objects[0].gamma, 1e7);
    EXPECT_TRUE(checkSceneForModel(s, Model::Relativistic).ok);  // b < 1 by construction
    ASSERT_TRUE(loadScene(write("r.json", R"({"objects":[{"mesh":"tetra.obj","direction":[1,0,0],"rapidity":1.5}]})"), &s).ok);
    EXPECT_NEAR(s.objects[0].velocity.x, std::tanh(1.5), 1e-15);
    EXPECT_NEAR(s.objects[0].gamma, std::cosh(1.5), 1e-12);
    Status st = loadScene(write("b.json", R"({"objects":[{"mesh":"tetra.obj","velocity":[0.5,0,0],"gamma":2}]})"), &s);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("either velocity or direction"), std::string::npos) << st.message;
    st = loadScene(write("c.json", R"({"objects":[{"mesh":"tetra.obj","direction":[1,0,0],"gamma":0.5}]})"), &s);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("objects[0].gamma: must be in [1, 1e15]"), std::string::npos) << st.message;
}

// An object's `color` or `material` (docs/SCENES.md), and each refusal naming the field.
TEST(Scene, ColorAndMaterialFields) {
    const auto write = tetraSceneWriter();
    Scene s;
    ASSERT_TRUE(loadScene(write("c.json", R"({"objects":[{"mesh":"tetra.obj","color":[0.9,0.1,0.2]}]})"), &s).ok);
    EXPECT_TRUE(s.objects[0].material.given);
    EXPECT_EQ(s.objects[0].material.base_color, (std::array<double, 4>{0.9, 0.1, 0.2, 1}));
    EXPECT_EQ(s.objects[0].material.roughness, 0.8);
    ASSERT_TRUE(loadScene(write("m.json", R"({"objects":[{"mesh":"tetra.obj","material":{"base_color":[0.1,0.2,0.3,0.5],
        "metallic":1,"roughness":0.25,"emissive":[0,0.5,1]}}]})"), &s).ok);
    const ObjectSpec::Material& m = s.objects[0].material;
    EXPECT_EQ(m.base_color, (std::array<double, 4>{0.1, 0.2, 0.3, 0.5}));
    EXPECT_EQ(m.metallic, 1);
    EXPECT_EQ(m.roughness, 0.25);
    EXPECT_EQ(m.emissive, (std::array<double, 3>{0, 0.5, 1}));
    ASSERT_TRUE(loadScene(write("n.json", R"({"objects":[{"mesh":"tetra.obj"}]})"), &s).ok);
    EXPECT_FALSE(s.objects[0].material.given);
    const std::pair<const char*, const char*> bad[] = {
        {R"("color":[1,2,0])", "objects[0].color[1]: 2 is outside [0, 1]"},
        {R"("color":[1,0])", "objects[0].color: expected [r, g, b] or [r, g, b, a]"},
        {R"("color":[1,0,0],"material":{})", "objects[0].color: give either color or material.base_color"},
        {R"("material":{"shiny":1})", "objects[0].material.shiny: unknown field"},
        {R"("material":{"emissive":[0,0,0,1]})", "objects[0].material.emissive: expected [r, g, b]"},
        {R"("material":{"roughness":-0.5})", "objects[0].material.roughness: -0.5 is outside [0, 1]"},
        {R"("material":"red")", "objects[0].material: expected an object"},
    };
    for (const auto& [fields, message] : bad) {
        const Status st = loadScene(write("bad.json", std::string(R"({"objects":[{"mesh":"tetra.obj",)") + fields + "}]}"), &s);
        EXPECT_FALSE(st.ok) << fields;
        EXPECT_NE(st.message.find(message), std::string::npos) << st.message;
    }
}
