#include "pipeline/stage/prepared_object.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <utility>

#include "mesh4d/angles.h"
#include "pipeline/input/gltf_document.h"

namespace apparent {

using mesh4d::kPi;
using mesh4d::Vec3;

namespace {

// Rotation by Euler angles in degrees, applied about X, then Y, then Z (fixed axes); the sines
// and cosines computed once per object.
struct RotationXYZ {
    double cx, sx, cy, sy, cz, sz;
    explicit RotationXYZ(const Vec3& deg)
        : cx(std::cos(deg.x * kPi / 180)), sx(std::sin(deg.x * kPi / 180)), cy(std::cos(deg.y * kPi / 180)),
          sy(std::sin(deg.y * kPi / 180)), cz(std::cos(deg.z * kPi / 180)), sz(std::sin(deg.z * kPi / 180)) {}
    Vec3 operator()(const Vec3& p) const {
        Vec3 r = p;
        r = {r.x, cx * r.y - sx * r.z, sx * r.y + cx * r.z};
        r = {cy * r.x + sy * r.z, r.y, -sy * r.x + cy * r.z};
        r = {cz * r.x - sz * r.y, sz * r.x + cz * r.y, r.z};
        return r;
    }
};

// Distinct base colours for objects without their own (linear RGB, roughly equal lightness).
constexpr std::array<std::array<double, 4>, 6> kPalette = {{{0.85, 0.45, 0.10, 1.0},
                                                            {0.10, 0.45, 0.85, 1.0},
                                                            {0.55, 0.55, 0.55, 1.0},
                                                            {0.20, 0.70, 0.25, 1.0},
                                                            {0.75, 0.20, 0.60, 1.0},
                                                            {0.85, 0.75, 0.15, 1.0}}};

}  // namespace

std::array<double, 4> objectBaseColor(const std::vector<PreparedObject>& objects, size_t i) {
    return objects[i].has_color ? objects[i].color : kPalette[i % kPalette.size()];
}

Status prepareObjects(const Scene& scene, const MeshLimits& limits, std::vector<PreparedObject>* objects,
                      std::ostream& log, bool quiet) {
    std::map<std::string, LoadedMesh> cache;  // one read per mesh file
    for (const ObjectSpec& spec : scene.objects) {
        // Step: the mesh path must stay where the scene may read (docs/HOSTILE_INPUT.md).
        if (!limits.allow_outside)
            if (Status s = checkMeshInside(scene.path, spec.field_path + ".mesh",
                                           spec.mesh_text.empty() ? spec.mesh_path : spec.mesh_text, spec.mesh_path);
                !s.ok)
                return s;
        auto it = cache.find(spec.mesh_path);
        if (it == cache.end()) {
            // A misspelt path: name the field that gave it ("cannot open" would not say which).
            std::error_code ec;
            std::string file = spec.mesh_path;  // without a glTF "#Node" suffix
            if (const auto h = file.rfind('#'); h != std::string::npos && isGltfPath(file.substr(0, h))) file.resize(h);
            if (!std::filesystem::exists(file, ec) && !ec)
                return Status::failure(scene.path + ": " + spec.field_path + ".mesh: \"" +
                                       (spec.mesh_text.empty() ? spec.mesh_path : spec.mesh_text) + "\" not found (" + file + ")");
            LoadedMesh mesh;
            MeshWarnings warnings;
            MeshLimits mesh_limits = limits;
            mesh_limits.scene_path = scene.path;  // where an OBJ's libraries may also lie
            if (Status s = readMesh(spec.mesh_path, mesh_limits, &mesh, &warnings); !s.ok) return s;
            if (!quiet)
                for (const std::string& w : warnings.lines()) log << "warning: " << spec.mesh_path << ": " << w << "\n";
            it = cache.emplace(spec.mesh_path, std::move(mesh)).first;
        }
        PreparedObject obj;
        obj.spec = spec;
        obj.rest = it->second.mesh;
        obj.has_color = it->second.has_color;
        obj.color = it->second.color;
        obj.look = it->second.look;
        // Step: the scene's own colour or material replaces the file's (and its materials).
        if (spec.material.given) {
            if (obj.look && !obj.look->materials.empty() && !quiet)
                log << "warning: " << scene.path << ": " << spec.field_path << ": the scene's "
                    << "color/material replaces the " << obj.look->materials.size() << " material(s) of " << spec.mesh_path << "\n";
            obj.has_color = true;
            obj.color = spec.material.base_color;
            obj.look = nullptr;
        }
        const auto& L = spec.linear;  // column-major
        const RotationXYZ rotate(spec.rotation_deg);
        for (Vec3& p : obj.rest.positions) {
            const Vec3 r = rotate({p.x * spec.scale.x, p.y * spec.scale.y, p.z * spec.scale.z});
            p = {L[0] * r.x + L[3] * r.y + L[6] * r.z, L[1] * r.x + L[4] * r.y + L[7] * r.z,
                 L[2] * r.x + L[5] * r.y + L[8] * r.z};
        }
        // A mirroring map (negative determinant) flips the winding: flip triangles back.
        const double det_linear = L[0] * (L[4] * L[8] - L[7] * L[5]) - L[3] * (L[1] * L[8] - L[7] * L[2]) +
                                  L[6] * (L[1] * L[5] - L[4] * L[2]);
        if (spec.scale.x * spec.scale.y * spec.scale.z * det_linear < 0)
            for (auto& t : obj.rest.triangles) std::swap(t[1], t[2]);
        for (const Vec3& p : obj.rest.positions) obj.radius = std::max(obj.radius, mesh4d::norm(p));
        objects->push_back(std::move(obj));
    }
    clearGltfCache();  // the meshes are read: parsed glTF documents are not needed any more
    return Status::success();
}

}  // namespace apparent
