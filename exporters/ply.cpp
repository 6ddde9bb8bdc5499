#include "exporters/ply.h"

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
    if (!OpenMesh::IO::write_mesh(om, out.tempPath(), opt)) {
        *error = path + ": OpenMesh could not write the PLY file";
        return false;
    }
    return out.commit(error);
}

}  // namespace apparent
