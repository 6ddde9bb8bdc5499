#include "exporters/obj.h"

#include <sstream>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "exporters/atomic_file.h"
#include "exporters/openmesh_frame.h"

namespace apparent {

bool writeObj(const std::string& path, const ExportFrame& frame, std::string* error) {
    FrameTriMesh om;
    toOpenMesh(frame, &om);
    omlog().disable();
    AtomicOutput out(path);
    // 17 significant digits: a double survives the text round trip exactly.
    std::ostringstream os;  // in memory, then written with every error checked (see ply.cpp)
    if (!OpenMesh::IO::write_mesh(om, os, ".obj", OpenMesh::IO::Options(), 17)) {
        *error = path + ": OpenMesh could not write the OBJ file";
        return false;
    }
    return out.commitBytes(os.str(), error);
}

}  // namespace apparent
