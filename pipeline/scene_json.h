// The scene's JSON form, shared by the JSON scene file and scenes authored in glTF (whose node
// and scene extras are gathered into the same document, with their own field paths for errors).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/scene.h"

namespace apparent {

struct SceneJsonPaths {
    std::string top;                       // prefix of top-level fields ("" for a JSON scene file)
    std::string camera;                    // path named for camera errors ("" -> top + ".camera")
    std::vector<std::string> objects;      // path named for each object ("" -> "objects[i]")
    std::vector<std::array<double, 9>> linear;  // each object's extra linear map (glTF node world matrix)
};

Status parseScene(const nlohmann::json& root, const std::string& path, const SceneJsonPaths& paths, Scene* scene);

// A scene authored in glTF: see gltf_reader.h.
Status loadGltfScene(const std::string& path, Scene* scene);

}  // namespace apparent
