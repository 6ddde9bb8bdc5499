#include "pipeline/input/look_files.h"

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "pipeline/input/input_file.h"

namespace apparent {

std::string sniffImage(const std::string& b) {
    static const char png[8] = {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n'};
    if (b.size() >= 8 && std::memcmp(b.data(), png, 8) == 0) return "image/png";
    if (b.size() >= 3 && (unsigned char)b[0] == 0xff && (unsigned char)b[1] == 0xd8 && (unsigned char)b[2] == 0xff)
        return "image/jpeg";
    return "";
}

LookFolders::LookFolders(const std::string& mesh_path, const MeshLimits& limits) : allow_outside_(limits.allow_outside) {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const std::string& file : {mesh_path, limits.scene_path}) {
        if (file.empty()) continue;
        const fs::path folder = fs::path(file).parent_path();
        roots_.push_back((folder.empty() ? fs::path(".") : folder).string());
    }
    roots_.push_back(fs::current_path(ec).string());
}

bool LookFolders::allows(const std::string& path) const {
    return allow_outside_ || std::any_of(roots_.begin(), roots_.end(), [&](const std::string& r) { return resolvesInside(path, r); });
}

std::string besideFile(const std::string& from_file, std::string name) {
    std::replace(name.begin(), name.end(), '\\', '/');
    const std::filesystem::path folder = std::filesystem::path(from_file).parent_path();
    return (folder / name).string();
}

Status readConfined(const std::string& where, const std::string& what, const std::string& file, const LookFolders& folders,
                    const MeshLimits& limits, MeshWarnings* warnings, std::string* bytes, bool* read) {
    *read = false;
    std::error_code ec;
    if (!folders.allows(file)) {
        warnings->other.push_back(where + ": " + what + " " + file +
                                  " is outside the folders a mesh may be read from: not opened (allow with --allow-outside)");
        return Status::success();
    }
    if (!std::filesystem::exists(file, ec)) {
        warnings->other.push_back(where + ": " + what + " " + file + " not found");
        return Status::success();
    }
    if (Status s = readRegularFile(file, limits.max_file_bytes, bytes, what.c_str()); !s.ok) return s;
    *read = true;
    return Status::success();
}

}  // namespace apparent
