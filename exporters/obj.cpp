#include "exporters/obj.h"

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
    if (!OpenMesh::IO::write_mesh(om, out.tempPath(), OpenMesh::IO::Options(), 17)) {
        *error = path + ": OpenMesh could not write the OBJ file";
        return false;
    }
    return out.commit(error);
}

}  // namespace apparent
