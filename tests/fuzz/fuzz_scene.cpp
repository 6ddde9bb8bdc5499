// libFuzzer harness for the JSON scene loader: the input bytes become a scene file read by
// loadScene (nlohmann parse, then every field checked). A scene must load or fail with one line
// that starts with the path; a loaded scene's frame count and model checks must terminate.
#include <cstdint>
#include <cstdlib>

#include "pipeline/input/scene.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    apparent_fuzz::removeInputFolderAtExit();
    const std::string path = apparent_fuzz::writeInput(data, size, ".json");
    apparent::Scene scene;
    const apparent::Status st = apparent::loadScene(path, &scene);
    if (!st.ok) {
        if (st.message.rfind(path, 0) != 0 || st.message.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    if (scene.objects.empty()) std::abort();
    (void)apparent::frameCount(scene.frames);
    for (apparent::Model m : {apparent::Model::Instant, apparent::Model::Finite, apparent::Model::Relativistic})
        (void)apparent::checkSceneForModel(scene, m);
    return 0;
}
