// The files a mesh's look names beside it (an OBJ's material libraries and their map_Kd images, a
// PLY's `comment TextureFile` image), read under the same rules whatever the format names them
// (docs/HOSTILE_INPUT.md): a file is read only when its resolved path (".." and symlinks followed)
// lies inside the mesh file's folder, the scene file's folder (MeshLimits::scene_path) or the
// working folder, or anywhere with MeshLimits::allow_outside. A file outside, or missing: one
// warning, not opened; a file that is not regular or is larger than max_file_bytes: refused (an
// error), as for the mesh itself. Images are PNG or JPEG, recognised by their first bytes.
#pragma once

#include <string>
#include <vector>

#include "pipeline/input/mesh_input.h"
#include "pipeline/input/status.h"

namespace apparent {

// "image/png" or "image/jpeg" from a file's first bytes; empty for anything else.
std::string sniffImage(const std::string& bytes);

// Where the files a mesh's look names may be read from (above).
class LookFolders {
public:
    LookFolders(const std::string& mesh_path, const MeshLimits& limits);
    bool allows(const std::string& path) const;

private:
    bool allow_outside_;
    std::vector<std::string> roots_;
};

// `name` as written in `from_file` (a mesh or a .mtl), resolved against that file's folder ('\' read as '/').
std::string besideFile(const std::string& from_file, std::string name);

// Reads a library or an image `file` named at `where` if the rules allow: `*read` false (with one
// warning, "WHERE: WHAT FILE not found") when it lies outside the allowed folders or does not
// exist; refused (an error) when it is not a regular file or is larger than the limit.
Status readConfined(const std::string& where, const std::string& what, const std::string& file, const LookFolders& folders,
                    const MeshLimits& limits, MeshWarnings* warnings, std::string* bytes, bool* read);

}  // namespace apparent
