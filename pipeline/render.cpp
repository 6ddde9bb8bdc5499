#include "pipeline/render.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <map>
#include <memory>
#include <ostream>
#include <sstream>

#include <unistd.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "exporters/gltf.h"
#include "exporters/obj.h"
#include "exporters/ply.h"
#include "pipeline/mesh_check.h"
#include "pipeline/mirror.h"

namespace apparent {

using mesh4d::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Rotation by Euler angles in degrees, applied about X, then Y, then Z (fixed axes).
Vec3 rotateXYZ(const Vec3& p, const Vec3& deg) {
    const double ax = deg.x * kPi / 180, ay = deg.y * kPi / 180, az = deg.z * kPi / 180;
    Vec3 r = p;
    r = {r.x, std::cos(ax) * r.y - std::sin(ax) * r.z, std::sin(ax) * r.y + std::cos(ax) * r.z};
    r = {std::cos(ay) * r.x + std::sin(ay) * r.z, r.y, -std::sin(ay) * r.x + std::cos(ay) * r.z};
    r = {std::cos(az) * r.x - std::sin(az) * r.y, std::sin(az) * r.x + std::cos(az) * r.y, r.z};
    return r;
}

mesh4d::Kinematics kinematicsOf(Model m) {
    return (m == Model::Relativistic || m == Model::Contracted) ? mesh4d::Kinematics::Lorentz
                                                                 : mesh4d::Kinematics::Galilean;
}

std::string humanBytes(size_t n) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(1);
    if (n >= 1 << 20) os << double(n) / (1 << 20) << " MiB";
    else if (n >= 1 << 10) os << double(n) / (1 << 10) << " KiB";
    else os << n << " B";
    return os.str();
}

// Progress on a terminal: frames done, rate, time left. Silent when stderr is not a terminal.
class Progress {
public:
    Progress(std::ostream& err, bool enabled, std::string label, long long total)
        : err_(err), enabled_(enabled && ::isatty(2)), label_(std::move(label)), total_(total),
          start_(std::chrono::steady_clock::now()) {}

    void update(long long done) {
        if (!enabled_) return;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        if (done < total_ && elapsed - last_ < 0.2) return;  // at most 5 updates a second
        last_ = elapsed;
        const double rate = elapsed > 0 ? double(done) / elapsed : 0;
        err_ << "\r" << label_ << ": frame " << done << "/" << total_ << std::fixed << std::setprecision(1)
             << " (" << rate << " frames/s, " << (rate > 0 ? double(total_ - done) / rate : 0) << " s left)   "
             << std::flush;
        if (done == total_) err_ << "\n";
    }

private:
    std::ostream& err_;
    bool enabled_;
    std::string label_;
    long long total_;
    std::chrono::steady_clock::time_point start_;
    double last_ = -1;
};

std::string frameFileName(long long k, const char* ext) { return frameName(k) + "." + ext; }

// Distinct base colours for objects without their own (linear RGB, roughly equal lightness).
constexpr std::array<std::array<double, 4>, 6> kPalette = {{{0.85, 0.45, 0.10, 1.0},
                                                            {0.10, 0.45, 0.85, 1.0},
                                                            {0.55, 0.55, 0.55, 1.0},
                                                            {0.20, 0.70, 0.25, 1.0},
                                                            {0.75, 0.20, 0.60, 1.0},
                                                            {0.85, 0.75, 0.15, 1.0}}};

SequenceInfo sequenceInfo(const Scene& scene, const std::vector<PreparedObject>& objects, const std::string& model) {
    SequenceInfo info;
    info.model = model;
    info.tolerance = scene.tolerance;
    info.fps = scene.frames.fps;
    info.scene_path = scene.path;
    for (size_t i = 0; i < objects.size(); ++i) {
        ExportObject o;
        o.name = objects[i].spec.name;
        o.base_color = objectBaseColor(objects, i);
        info.objects.push_back(o);
    }
    info.camera.position = scene.camera.position;
    info.camera.look_at = scene.camera.look_at;
    info.camera.up = scene.camera.up;
    info.camera.fov_deg = scene.camera.fov_deg;
    return info;
}

}  // namespace

std::array<double, 4> objectBaseColor(const std::vector<PreparedObject>& objects, size_t i) {
    return objects[i].has_color ? objects[i].color : kPalette[i % kPalette.size()];
}

Status prepareObjects(const Scene& scene, const MeshLimits& limits, std::vector<PreparedObject>* objects,
                      std::ostream& log, bool quiet) {
    std::map<std::string, LoadedMesh> cache;  // one read per mesh file
    for (const ObjectSpec& spec : scene.objects) {
        // Step: the mesh path must stay where the scene may read (README "Hostile input").
        if (!limits.allow_outside)
            if (Status s = checkMeshInside(scene.path, spec.field_path + ".mesh",
                                           spec.mesh_text.empty() ? spec.mesh_path : spec.mesh_text, spec.mesh_path);
                !s.ok)
                return s;
        auto it = cache.find(spec.mesh_path);
        if (it == cache.end()) {
            LoadedMesh mesh;
            MeshWarnings warnings;
            if (Status s = readMesh(spec.mesh_path, limits, &mesh, &warnings); !s.ok) return s;
            if (!quiet)
                for (const std::string& w : warnings.lines()) log << "warning: " << spec.mesh_path << ": " << w << "\n";
            it = cache.emplace(spec.mesh_path, std::move(mesh)).first;
        }
        PreparedObject obj;
        obj.spec = spec;
        obj.rest = it->second.mesh;
        obj.has_color = it->second.has_color;
        obj.color = it->second.color;
        const auto& L = spec.linear;  // column-major
        for (Vec3& p : obj.rest.positions) {
            const Vec3 r = rotateXYZ({p.x * spec.scale.x, p.y * spec.scale.y, p.z * spec.scale.z}, spec.rotation_deg);
            p = {L[0] * r.x + L[3] * r.y + L[6] * r.z, L[1] * r.x + L[4] * r.y + L[7] * r.z,
                 L[2] * r.x + L[5] * r.y + L[8] * r.z};
        }
        // A mirroring map (negative determinant) flips the winding: flip triangles back.
        const double det_linear = L[0] * (L[4] * L[8] - L[7] * L[5]) - L[3] * (L[1] * L[8] - L[7] * L[2]) +
                                  L[6] * (L[1] * L[5] - L[4] * L[2]);
        if (spec.scale.x * spec.scale.y * spec.scale.z * det_linear < 0)
            for (auto& t : obj.rest.triangles) std::swap(t[1], t[2]);
        objects->push_back(std::move(obj));
    }
    return Status::success();
}

bool inCameraView(const CameraSpec& camera, const mesh4d::BoundingSphere& bound) {
    const Vec3 d = bound.center - camera.position;
    const double dist = mesh4d::norm(d);
    if (!(dist > bound.radius)) return true;  // the camera is inside the sphere (or NaN: keep it)
    const Vec3 f = camera.look_at - camera.position;
    const double cos_angle = std::clamp(mesh4d::dot(d, f) / (dist * mesh4d::norm(f)), -1.0, 1.0);
    const double angle = std::acos(cos_angle);                  // centre off the view axis
    const double angular_radius = std::asin(bound.radius / dist);
    const double half_fov = 0.5 * camera.fov_deg * kPi / 180.0;
    const double half_diagonal = std::atan(std::tan(half_fov) * std::sqrt(1 + kCullAspect * kCullAspect));
    return angle - angular_radius <= half_diagonal;
}

mesh4d::ViewSurface viewForFrame(const Scene& scene, Model model, long long k) {
    return viewAt(scene, model, frameTime(scene.frames, k));
}

mesh4d::ViewSurface viewAt(const Scene& scene, Model model, double t_c) {
    mesh4d::ViewSurface view;
    view.kind = (model == Model::Finite || model == Model::Relativistic) ? mesh4d::ViewKind::PastCone
                                                                         : mesh4d::ViewKind::Hyperplane;
    view.t_c = t_c;
    // The hyperplane models may look back by the stage's light delay (scene camera.instant_delay).
    if (view.kind == mesh4d::ViewKind::Hyperplane) view.t_c -= scene.camera.instant_delay;
    view.apex = scene.camera.position;
    return view;
}

mesh4d::World4D buildWorld(const PreparedObject& object, Model model, const Scene& scene, long long first_frame,
                           long long last_frame) {
    const ObjectSpec& s = object.spec;
    const mesh4d::Kinematics kin = kinematicsOf(model);
    const mesh4d::Motion motion =
        s.speed == ObjectSpec::Speed::Gamma      ? mesh4d::makeMotionFromGamma(kin, s.t0, s.position, s.direction, s.gamma)
        : s.speed == ObjectSpec::Speed::Rapidity ? mesh4d::makeMotionFromRapidity(kin, s.t0, s.position, s.direction, s.rapidity)
                                                 : mesh4d::makeMotion(kin, s.t0, s.position, s.velocity);
    // Step: the proper-time span the requested frames can see, padded by the object's own light
    // crossing time so that rounding in the vertex crossings never reaches an artificial cap.
    const mesh4d::ProperTimeSpan seen = mesh4d::spanSeen(object.rest, motion, viewForFrame(scene, model, first_frame),
                                                         viewForFrame(scene, model, last_frame));
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (const Vec3& p : object.rest.positions) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    // Interior points of a triangle can emit up to diag (1 + b) / (1 - b^2) = diag / (1 - b) later or
    // earlier than its vertices (the crossing time's slope along the surface is at most 1/(1 - b)).
    const double diag = mesh4d::norm(hi - lo);
    const double pad = diag * (1 + motion.beta) / motion.one_minus_beta2 +
                       1e-9 * std::max(std::fabs(seen.lo), std::fabs(seen.hi));
    const double open_a = seen.lo - pad, open_b = seen.hi + pad;
    // Step: clip the span to the object's existence; only those ends are real caps.
    const bool cap_a_real = s.exists_from > open_a;
    const bool cap_b_real = s.exists_to < open_b;
    const double tau_a = cap_a_real ? s.exists_from : open_a;
    const double tau_b = cap_b_real ? s.exists_to : open_b;
    if (!(tau_a < tau_b)) {
        mesh4d::World4D empty;
        empty.motion = motion;
        return empty;
    }
    return mesh4d::extrude(object.rest, motion, tau_a, tau_b, cap_a_real, cap_b_real);
}

int render(const RenderSettings& settings, std::ostream& log, std::ostream& err) {
    // Step: load and validate the scene.
    Scene scene;
    if (Status s = loadScene(settings.scene_path, &scene); !s.ok) {
        err << "error: " << s.message << "\n";
        return kExitBadInput;
    }
    if (settings.has_tolerance) scene.tolerance = settings.tolerance;
    std::vector<Model> models = settings.models;
    if (settings.all_models) models = {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted};
    if (models.empty()) models = {scene.model};
    for (Model m : models) {
        if (Status s = checkSceneForModel(scene, m); !s.ok) {
            err << "error: " << s.message << "\n";
            return kExitBadInput;
        }
    }
    const long long total_frames = frameCount(scene.frames);
    if (total_frames > settings.max_frames) {
        err << "error: " << scene.path << ": frames: " << total_frames << " frames requested, more than the limit of "
            << settings.max_frames << " (raise it with --max-frames)\n";
        return kExitBadInput;
    }
    const long long first = settings.frame_from;
    const long long last_excl = settings.frame_to < 0 ? total_frames : settings.frame_to;
    if (!(first >= 0 && first < last_excl && last_excl <= total_frames)) {
        err << "error: --frames: " << first << ":" << last_excl << " is outside the scene's frames 0:" << total_frames
            << "\n";
        return kExitBadInput;
    }

    // Step: load the meshes (once each) and apply rotation and scale.
    std::vector<PreparedObject> objects;
    if (Status s = prepareObjects(scene, settings.limits, &objects, err, settings.quiet); !s.ok) {
        err << "error: " << s.message << "\n";
        return kExitBadInput;
    }
    std::vector<MirrorPlane> mirrors;
    if (Status s = findMirrors(objects, scene.path, &mirrors); !s.ok) {
        err << "error: " << s.message << "\n";
        return kExitBadInput;
    }
    if (settings.verbose) {
        for (const auto& o : objects) {
            const Topology t = analyzeTopology(o.rest.positions, o.rest.triangles);
            log << o.spec.name << ": " << t.vertices << " vertices, " << t.faces << " triangles, "
                << (t.closed ? "closed" : (t.manifold ? "open" : "non-manifold")) << ", speed "
                << mesh4d::norm(o.spec.velocity) << " c\n";
        }
    }

    std::error_code ec;
    std::filesystem::create_directories(settings.out_dir, ec);
    if (ec) {
        err << "error: " << settings.out_dir << ": cannot create output folder: " << ec.message() << "\n";
        return kExitOutputError;
    }

    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    // Bytes written by this run, and a check before each write against --max-output-bytes: files
    // already written stay complete, nothing is written past the limit.
    long long written = 0;
    auto overLimit = [&](long long more, const std::string& what) {
        if (written + more <= settings.max_output_bytes) return false;
        err << "error: --max-output-bytes: " << what << (more ? " would bring" : " brought") << " the output to " << (written + more)
            << " bytes, more than the limit of " << settings.max_output_bytes << " (" << written
            << " bytes written, every written file is complete; raise it with --max-output-bytes)\n";
        return true;
    };
    // Counts a written file; false (with the message) once the total is over the limit.
    auto addWritten = [&](const std::string& path) {
        std::error_code size_ec;
        const auto n = std::filesystem::file_size(path, size_ec);
        if (!size_ec) written += (long long)n;
        return !overLimit(0, path);
    };
    for (Model model : models) {
        const std::string name = modelName(model);
        // Step: build the static 4D world once per model.
        std::vector<mesh4d::World4D> worlds;
        for (const auto& o : objects) worlds.push_back(buildWorld(o, model, scene, first, last_excl - 1));
        const MirrorReflections reflections(scene, objects, mirrors, model, first, last_excl - 1);
        const std::string frame_dir = (std::filesystem::path(settings.out_dir) / name).string();
        if (settings.write_ply || settings.write_obj) {
            std::filesystem::create_directories(frame_dir, ec);
            if (ec) {
                err << "error: " << frame_dir << ": cannot create output folder: " << ec.message() << "\n";
                return kExitOutputError;
            }
        }

        // Step: per frame, cut every world with the view surface (refined to the tolerance), then export.
        mesh4d::SliceSettings slice_settings;
        slice_settings.tolerance = scene.tolerance;
        // The .glb streams: each frame's data leaves memory as soon as it is cut (GlbSequenceWriter).
        const std::string glb = (std::filesystem::path(settings.out_dir) / (name + ".glb")).string();
        std::unique_ptr<GlbSequenceWriter> glb_writer;
        if (settings.write_glb) {
            SequenceInfo info = sequenceInfo(scene, objects, name);
            reflections.describe(&info);
            glb_writer = std::make_unique<GlbSequenceWriter>(glb, info, settings.glb);
        }
        long long glb_min = 0;  // least size of the .glb without Draco (positions and indices alone)
        Progress progress(err, !settings.quiet, name, last_excl - first);
        size_t max_triangles = 0, limited = 0;
        // Frames are independent given the static worlds: cut a batch in parallel (TBB), then
        // export it in frame order, so files are byte-identical whatever the thread count.
        const long long batch = std::max<long long>(1, 4 * (long long)arena.max_concurrency());
        for (long long b0 = first; b0 < last_excl; b0 += batch) {
            const long long b1 = std::min(last_excl, b0 + batch);
            std::vector<ExportFrame> cut(size_t(b1 - b0));
            std::vector<std::shared_ptr<GlbFrameData>> glb_data(size_t(b1 - b0));
            arena.execute([&] {
                tbb::parallel_for(b0, b1, [&](long long k) {
                    ExportFrame& frame = cut[size_t(k - b0)];
                    frame.index = k;
                    frame.t_c = frameTime(scene.frames, k);
                    const mesh4d::ViewSurface view = viewForFrame(scene, model, k);
                    // Objects in parallel too (a short range of frames of a many-object scene),
                    // each into its own slot: the result does not depend on the scheduling.
                    frame.objects.resize(worlds.size());
                    tbb::parallel_for(size_t(0), worlds.size(), [&](size_t o) {
                        const mesh4d::World4D& w = worlds[o];
                        // --cull-view: an object wholly outside the camera's view is left empty.
                        if (settings.cull_view && !inCameraView(scene.camera, mesh4d::apparentBound(w, view))) return;
                        frame.objects[o] = mesh4d::sliceWorld(w, view, slice_settings);
                    });
                    // Mirrors add their retarded reflections as further objects (pipeline/mirror.h).
                    reflections.append(view, slice_settings, &frame.objects);
                    // The .glb's conversion of the frame (normals, float32) here too, in parallel.
                    if (glb_writer) glb_data[size_t(k - b0)] = glb_writer->prepare(frame);
                });
            });
            for (ExportFrame& frame : cut) {
                const long long k = frame.index;
                max_triangles = std::max(max_triangles, frame.triangleCount());
                for (const auto& o : frame.objects) limited += o.limited_triangles;
                std::string error;
                // A frame file holds at least 12 bytes per vertex and 12 per triangle, and the
                // .glb as much again (NORMAL adds 12 per vertex): refuse before writing beyond the limit.
                size_t frame_vertices = 0;
                for (const auto& o : frame.objects) frame_vertices += o.positions.size();
                const long long frame_min = 12 * (long long)frame_vertices + 12 * (long long)frame.triangleCount();
                const std::string ply_path = (std::filesystem::path(frame_dir) / frameFileName(k, "ply")).string();
                const std::string obj_path = (std::filesystem::path(frame_dir) / frameFileName(k, "obj")).string();
                if (settings.write_ply && overLimit(frame_min, ply_path)) return kExitOutputError;
                if (settings.write_ply && !writePly(ply_path, frame, &error)) {
                    err << "error: " << error << "\n";
                    return kExitOutputError;
                }
                if (settings.write_ply && !addWritten(ply_path)) return kExitOutputError;
                if (settings.write_obj && overLimit(frame_min, obj_path)) return kExitOutputError;
                if (settings.write_obj && !writeObj(obj_path, frame, &error)) {
                    err << "error: " << error << "\n";
                    return kExitOutputError;
                }
                if (settings.write_obj && !addWritten(obj_path)) return kExitOutputError;
                if (settings.write_glb && !settings.glb.draco) glb_min += frame_min;
                if (settings.write_glb && overLimit(glb_min, name + ".glb")) return kExitOutputError;
                if (glb_writer && !glb_writer->add(frame, *glb_data[size_t(k - b0)], &error)) {
                    err << "error: " << error << "\n";
                    return kExitOutputError;
                }
                progress.update(k - first + 1);
            }
        }

        // Step: the animated sequence.
        std::string summary;
        if (settings.write_glb) {
            GlbStats stats;
            std::string error;
            if (!glb_writer->finish(&stats, &error)) {
                err << "error: " << error << "\n";
                return kExitOutputError;
            }
            if (!addWritten(glb)) return kExitOutputError;
            summary = ", " + glb + " (" + humanBytes(stats.bytes);
            if (settings.glb.draco) summary += " with Draco, " + humanBytes(stats.bytes_without_draco) + " without";
            summary += ")";
            std::ostringstream os;
            os << std::setprecision(3);
            if (settings.verbose) os << "; float32 position error <= " << stats.max_float_error << " ls";
            if (settings.glb.draco && settings.verbose)
                os << "; Draco " << settings.glb.position_bits << "-bit position error <= " << stats.max_quantization_error
                   << " ls";
            summary += os.str();
            // Warn when Draco's quantization is coarser than the accuracy asked for (gltfpack warns
            // the same way about position bits).
            if (settings.glb.draco && scene.tolerance > 0 && stats.max_quantization_error > scene.tolerance &&
                !settings.quiet) {
                std::ostringstream w;
                w << std::setprecision(3) << "warning: " << glb << ": Draco position error up to "
                  << stats.max_quantization_error << " ls exceeds the tolerance " << scene.tolerance
                  << " ls; consider more bits (--draco-bits " << std::min(30, settings.glb.position_bits + 2) << ")\n";
                err << w.str();
            }
        }
        if (limited > 0 && !settings.quiet)
            err << "warning: " << name << ": " << limited << " triangle-frames reached the refinement limit of "
                << slice_settings.max_segments << " segments; the tolerance " << scene.tolerance
                << " ls is not met there (a coarser tolerance or a finer input mesh helps)\n";
        if (!settings.quiet)
            log << name << ": " << (last_excl - first) << " frames, up to " << max_triangles << " triangles"
                << summary << "\n";
    }
    return kExitOk;
}

}  // namespace apparent
