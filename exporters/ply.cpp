#include "exporters/ply.h"

#include <sstream>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "exporters/atomic_file.h"
#include "exporters/openmesh_frame.h"

namespace apparent {

bool writePly(const std::string& path, const ExportFrame& frame, std::string* error) {
    FrameTriMesh om;
    toOpenMesh(frame, &om);
    omlog().disable();
    AtomicOutput out(path);
    const OpenMesh::IO::Options opt(OpenMesh::IO::Options::Binary | OpenMesh::IO::Options::LSB |
                                    OpenMesh::IO::Options::Custom);
    // Serialized in memory, then written with every error checked (OpenMesh's file writer cannot
    // report a failed final flush, such as a full disk).
    std::ostringstream os;
    if (!OpenMesh::IO::write_mesh(om, os, ".ply", opt)) {
        *error = path + ": OpenMesh could not write the PLY file";
        return false;
    }
    return out.commitBytes(os.str(), error);
}

}  // namespace apparent
