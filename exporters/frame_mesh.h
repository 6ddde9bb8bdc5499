// What the exporters receive: one frame of apparent geometry, all objects merged. Exporters make
// no geometric decisions; they convert and write.
#pragma once

#include <string>
#include <vector>

#include "mesh4d/slice.h"

namespace apparent {

struct ExportFrame {
    long long index = 0;          // global frame number (file names use it)
    double t_c = 0;               // camera time of the frame
    mesh4d::ApparentMesh mesh;    // positions in lab coordinates, emission times, triangles
};

struct SequenceInfo {
    std::string model;            // instant, finite, relativistic, contracted
    double tolerance = 0;         // requested tolerance (light-seconds)
    double fps = 1;
    std::string scene_path;
};

}  // namespace apparent
