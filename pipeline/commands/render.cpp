#include "pipeline/commands/render.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "exporters/obj.h"
#include "exporters/ply.h"
#include "pipeline/commands/command.h"
#include "pipeline/input/json_limits.h"
#include "pipeline/input/mesh_check.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/run/shard_header.h"
#include "pipeline/run/shards.h"
#include "pipeline/run/web_file.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/view_hints.h"

namespace apparent {

namespace {

// One output format: its --format name and how its sink is made for a model. `base` is
// DIR/<model>: the folder of per-frame files and the stem of a file per sequence. A new format is
// one more entry here and one sink in exporters/ (CONTRIBUTING.md "Adding a motion model, a format, a command").
struct OutputFormat {
    std::string name;
    std::function<std::unique_ptr<FrameSink>(const RenderSettings&, const std::string& base)> make;
};

// Every setting that changes an output, as text: part of a shard's fingerprint (pipeline/run/shards.h).
std::string outputSettings(const RenderSettings& s, const Stage& stage) {
    std::ostringstream os;
    os.precision(17);
    os << "models";
    for (Model m : stage.models) os << " " << modelName(m);
    os << "\nformats";
    for (const std::string& f : s.formats) os << " " << f;
    os << "\nframes " << stage.first << " " << stage.last_excl << "\ntolerance " << stage.scene.tolerance;
    for (double t : stage.tolerances) os << " " << t;
    if (std::any_of(stage.attribute_tolerances.begin(), stage.attribute_tolerances.end(),
                    [](double t) { return t < INFINITY; })) {
        os << "\nattribute-tolerance";
        for (double t : stage.attribute_tolerances) os << " " << t;
    }
    const GlbOptions& g = s.glb;
    os << "\nglb " << g.draco << " " << g.position_bits << " " << g.normal_bits << " " << g.meshopt << " "
       << g.meshopt_bits << " " << g.doppler << " " << g.proper_time << " " << g.shade_doppler << "\ncull "
       << s.cull_view << "\nmax-triangles " << s.max_frame_triangles << "\nscene " << stage.scene.path << "\n";
    if (g.texcoord_bits != GlbOptions().texcoord_bits) os << "draco-texcoord-bits " << g.texcoord_bits << "\n";
    return os.str();
}

// The files a run reads: the scene and every mesh (a glTF node reference without its "#node").
std::vector<std::string> inputFiles(const Stage& stage) {
    std::vector<std::string> files = {stage.scene.path};
    for (const PreparedObject& o : stage.objects) {
        std::string mesh = o.spec.mesh_path;
        std::error_code ec;
        if (const auto hash = mesh.rfind('#'); hash != std::string::npos && !std::filesystem::exists(mesh, ec))
            mesh.resize(hash);
        if (!mesh.empty() && std::find(files.begin(), files.end(), mesh) == files.end()) files.push_back(mesh);
    }
    return files;
}

std::string hex(uint64_t v) {
    std::ostringstream os;
    os << std::hex << v;
    return os.str();
}

// Under mpirun, before any frame: every rank's scene bytes, mesh bytes and output settings (the
// shard fingerprint's parts) compared with rank 0's. The code of the first rank that differs (2)
// and, on rank 0, its line naming what differs; 0 when all agree.
int ranksAgree(FrameGroup& group, const RenderSettings& settings, const Stage& stage, std::string* error) {
    const std::vector<std::string> files = inputFiles(stage);
    const std::vector<std::string> meshes(files.begin() + 1, files.end());
    const std::string options = outputSettings(settings, stage);
    uint64_t scene_print = 0, mesh_print = 0;
    std::string problem;
    bool ok = runFingerprint({files.front()}, "", &scene_print, &problem) &&
              runFingerprint(meshes, "", &mesh_print, &problem);
    const std::string mine = hex(scene_print) + "\n" + hex(mesh_print) + "\n" + options;
    const std::string zero = group.broadcast(mine);
    if (ok && mine != zero) {
        const std::string rank = "rank " + std::to_string(group.rank());
        std::istringstream a(mine), b(zero);
        std::string line_a, line_b;
        std::getline(a, line_a);
        std::getline(b, line_b);
        if (line_a != line_b) {
            problem = rank + " read another scene than rank 0: " + files.front() + " differs (fingerprint " + line_a +
                      ", rank 0 " + line_b + ")";
        } else if (std::getline(a, line_a), std::getline(b, line_b), line_a != line_b) {
            problem = rank + " read other meshes than rank 0 (fingerprint " + line_a + ", rank 0 " + line_b + ")";
        } else {
            while (std::getline(a, line_a) && std::getline(b, line_b) && line_a == line_b) {}
            problem = rank + " has another output option than rank 0: '" + printable(line_a, 80) + "', rank 0 '" +
                      printable(line_b, 80) + "'";
        }
        problem += "; every rank must read the same scene and meshes and get the same options";
        ok = false;
    }
    *error = problem;
    return group.agree(ok ? kExitOk : kExitBadInput, error) != 0 ? kExitBadInput : kExitOk;
}

// In the order the sinks take each frame (the byte budget checks them in this order too).
const std::vector<OutputFormat>& formatTable() {
    static const std::vector<OutputFormat> table = {
        {"ply", [](const RenderSettings&, const std::string& base) { return plySink(base); }},
        {"obj", [](const RenderSettings&, const std::string& base) { return objSink(base); }},
        {"glb",
         [](const RenderSettings& s, const std::string& base) -> std::unique_ptr<FrameSink> {
             return std::make_unique<GlbSink>(base + ".glb", s.glb, s.verbose);
         }},
    };
    return table;
}

}  // namespace

const std::vector<std::string>& outputFormats() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const OutputFormat& f : formatTable()) n.push_back(f.name);
        n.push_back("web");  // not a frame sink: one file for the whole scene (writeWebFile)
        return n;
    }();
    return names;
}

int render(const RenderSettings& settings, std::ostream& log_out, std::ostream& err_out) {
    // Under mpirun the ranks other than 0 print nothing: rank 0 speaks for the job.
    FrameGroup& group = frameGroup();
    const bool distributed = group.size() > 1;
    std::ostringstream silent;
    std::ostream& log = group.rank() == 0 ? log_out : silent;
    std::ostream& err = group.rank() == 0 ? err_out : silent;
    if (distributed && settings.sharded) {
        err << "error: --shard: not under mpirun with " << group.size()
            << " processes (the ranks already share the frames); run each shard as its own process\n";
        return kExitBadInput;
    }
    // Step: the stage: scene, models, frames, meshes, mirrors (every rank loads it; all agree).
    Stage stage;
    std::string error;
    StageOptions stage_options = settings.stage;
    stage_options.quiet = settings.quiet || group.rank() > 0;
    const bool loaded = loadStage(stage_options, &stage, err, &error);
    if (const int code = group.agree(loaded ? kExitOk : kExitBadInput, &error)) {
        err << "error: " << error << "\n";
        return code;
    }
    if (distributed) {
        std::string problem;
        if (const int code = ranksAgree(group, settings, stage, &problem)) {
            err << "error: " << problem << "\n";
            return code;
        }
    }
    uint64_t fingerprint = 0;
    if (settings.sharded && !runFingerprint(inputFiles(stage), outputSettings(settings, stage), &fingerprint, &error)) {
        err << "error: " << error << "\n";
        return kExitBadInput;
    }
    if (settings.verbose) {
        for (const auto& o : stage.objects) {
            const Topology t = analyzeTopology(o.rest.positions, o.rest.triangles);
            log << o.spec.name << ": " << t.vertices << " vertices, " << t.faces << " triangles, "
                << (t.closed ? "closed" : (t.manifold ? "open" : "non-manifold")) << ", speed "
                << mesh4d::norm(o.spec.velocity) << " c\n";
        }
    }
    std::error_code ec;
    // A folder this run creates is removed again when the run stops before writing into it.
    const bool had_folder = std::filesystem::exists(settings.out_dir, ec);
    if (group.rank() == 0) std::filesystem::create_directories(settings.out_dir, ec);
    if (ec) {
        err << "error: " << settings.out_dir << ": cannot create output folder: " << ec.message() << "\n";
        return kExitOutputError;
    }

    // Step: the web file (pipeline/run/web_file.h): the scene once, whatever the frames.
    if (std::find(settings.formats.begin(), settings.formats.end(), "web") != settings.formats.end()) {
        if (distributed || settings.sharded) {
            err << "error: --format web: one file for the whole scene, written by one process (not under mpirun or --shard)\n";
            return kExitBadInput;
        }
        const std::string web = (std::filesystem::path(settings.out_dir) / "scene.web.glb").string();
        WebFileReport report;
        const Model model = stage.models.size() == 1 ? stage.models.front() : stage.scene.model;
        if (Status s = writeWebFile(stage.scene, model, settings.stage.limits, web, &report); !s.ok) {
            if (!had_folder) std::filesystem::remove(settings.out_dir, ec);
            err << "error: " << s.message << "\n";
            return report.write_failed ? kExitOutputError : kExitBadInput;
        }
        if (!settings.quiet) {
            for (const std::string& note : report.notes) err << "note: " << note << "\n";
            log << "web: " << web << ", " << report.bytes << " bytes\n";
        }
        if (settings.formats.size() == 1) return kExitOk;
    }

    // DIR/<model> folders of per-frame files that did not exist (seen before the ranks start: they
    // make them too, exporters/frame_files.h)
    std::vector<std::string> created, model_folders;
    for (Model model : stage.models) {
        if (settings.formats.size() == 1 && settings.formats.front() == "web") break;
        const std::string folder = (std::filesystem::path(settings.out_dir) / modelName(model)).string();
        if (!std::filesystem::exists(folder, ec)) created.push_back(folder);
        model_folders.push_back(folder);
    }
    if (settings.sharded) {
        const std::string shards = (std::filesystem::path(settings.out_dir) / "shards").string();
        if (!std::filesystem::exists(shards, ec)) created.push_back(shards);
    }
    // Step (MPI): the ranks write their frames' data (the .glb's) and files (PLY, OBJ) themselves
    // when rank 0 sees their files.
    const bool glb = std::find(settings.formats.begin(), settings.formats.end(), "glb") != settings.formats.end();
    if (distributed && !shareFrameSpills(settings.out_dir, model_folders, &error) && !settings.quiet)
        err << "warning: " << error << "; the " << (glb ? ".glb's frame data" : "frames' files")
            << " goes through rank 0 instead (slower)\n";

    // Step: per model, the frame loop into one sink per format; the budget spans the whole run.
    OutputBudget budget(settings.max_output_bytes);
    FrameLoopSettings loop;
    loop.threads = settings.threads;
    loop.max_frame_triangles =
        settings.max_frame_triangles > 0 ? settings.max_frame_triangles : defaultFrameTriangleBudget(stage);
    loop.cull_view = settings.cull_view;
    loop.progress = !settings.quiet;
    loop.models_left = (long long)stage.models.size();
    loop.distributed = distributed;
    if (distributed) loop.split = FrameSplit{group.rank(), group.size()};
    if (settings.sharded) loop.split = settings.shard;
    for (Model model : stage.models) {
        const std::string name = modelName(model);
        const std::string base = (std::filesystem::path(settings.out_dir) / name).string();
        std::vector<std::unique_ptr<FrameSink>> owned;
        std::vector<FrameSink*> sinks;
        for (const OutputFormat& f : formatTable()) {
            if (std::find(settings.formats.begin(), settings.formats.end(), f.name) == settings.formats.end()) continue;
            if (settings.sharded && f.name == "glb")
                owned.push_back(glbShardSink(settings.out_dir, name, settings.glb, settings.shard, fingerprint,
                                             stage.first, stage.last_excl));
            else
                owned.push_back(f.make(settings, base));
            sinks.push_back(owned.back().get());
        }
        FrameLoopResult result;
        // The last model needs the stage's meshes no more: its worlds take them (held once).
        const bool ran = loop.models_left == 1
                             ? runLastFrameLoop(&stage, model, loop, sinks, &budget, err, &result, &error)
                             : runFrameLoop(stage, model, loop, sinks, &budget, err, &result, &error);
        --loop.models_left;
        if (!ran && group.rank() > 0) return result.group_code;  // rank 0 reports it
        if (!ran) {
            owned.clear();  // the sinks remove their temporaries
            // Folders this run created and left empty go too (remove() takes only empty ones).
            for (const std::string& folder : created) std::filesystem::remove(folder, ec);
            if (!had_folder) std::filesystem::remove(settings.out_dir, ec);
            err << "error: " << error << "\n";
            if (result.group_code) return result.group_code;
            return result.over_budget ? kExitBadInput : kExitOutputError;
        }
        // Step: the summary: the sinks' warnings and files, and the refinement limit if reached.
        std::string summary;
        for (const SinkSummary& s : result.summaries) {
            summary += s.text;
            if (!settings.quiet)
                for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
        }
        // Hints instead of blanks: an object no frame shows in the camera's view (view_hints.h).
        if (!settings.quiet && !settings.sharded)
            for (const std::string& w : outOfViewWarnings(stage, model, frameRange(stage.first, stage.last_excl)))
                err << "warning: " << w << "\n";
        if (result.limited_triangles > 0 && !settings.quiet)
            err << "warning: " << name << ": " << result.limited_triangles
                << " triangle-frames reached the refinement limit of " << result.max_segments
                << " segments; the tolerance " << stage.scene.tolerance * unitsPerLightSecond(stage.scene.units) << " "
                << lengthName(stage.scene.units) << " is not met there (a coarser tolerance or a finer input mesh helps)\n";
        if (distributed) summary += ", " + std::to_string(group.size()) + " processes shared the frames";
        if (settings.verbose && !settings.quiet) {
            // Where the time went (FrameLoopResult): what decides how far more processes help.
            std::ostringstream t;
            t.setf(std::ios::fixed);
            t.precision(1);
            const double wall = result.loop_seconds > 0 ? result.loop_seconds : 1;
            auto perFrame = [](double seconds, long long frames) { return 1e3 * seconds / double(std::max(1LL, frames)); };
            t << name << ": loop " << result.loop_seconds << " s; per frame: cut and encode "
              << perFrame(result.cut_seconds, result.frames_cut) << " ms (CPU "
              << perFrame(result.cut_cpu_seconds, result.frames_cut) << " ms; " << result.frames_cut
              << " frames cut here), write " << perFrame(result.write_seconds, result.frames_written) << " ms (CPU "
              << perFrame(result.write_cpu_seconds, result.frames_written) << " ms; " << result.frames_written
              << " frames, " << 100 * result.write_seconds / wall << "% of the loop" << (distributed ? " on rank 0" : "")
              << ")";
            t << "; of the writing, the files' assembly " << 1e3 * result.finish_seconds << " ms (CPU "
              << 1e3 * result.finish_cpu_seconds << " ms)";
            if (distributed) t << "; rank 0 waited " << result.wait_seconds << " s for other ranks";
            if (result.frames_received > 0) {
                // Microseconds: rank 0's share of a frame it did not cut is far below a millisecond.
                const double n = double(result.frames_received);
                t.precision(0);
                t << "; of the writing, the frames of other ranks " << 1e6 * result.received_seconds / n
                  << " us each (CPU " << 1e6 * result.received_cpu_seconds / n << " us; " << result.frames_received
                  << " frames)";
            }
            log << t.str() << "\n";
        }
        if (!settings.quiet)
            log << name << ": " << (settings.sharded ? loop.split.count(stage.first, stage.last_excl) : stage.last_excl - stage.first)
                << " frames, up to " << result.max_triangles << " triangles" << summary << "\n";
    }
    return kExitOk;
}


// ---- The command: `apparent render` ----

namespace {

constexpr const char* kRenderFooter =
    "Models:\n"
    "  instant       infinite light speed: every object where it is at the frame time\n"
    "  finite        finite light speed, Galilean objects (classical aberration only)\n"
    "  relativistic  finite light speed, Lorentz-boosted objects (what special relativity shows)\n"
    "  contracted    the Lorentz-contracted shape at the frame time (measured, never seen)\n"
    "Outputs in DIR:\n"
    "  <model>.glb                      one animated glTF holding every frame (STEP scale channels)\n"
    "  <model>/frame_NNNNN.ply|.obj     per frame, all objects; PLY vertex 'quality' = emission time\n"
    "  scene.web.glb                    --format web: the scene as a glTF scene (docs/GLTF.md)\n"
    "Exit codes: 0 success, 1 internal error, 2 bad usage or bad input, 3 output could not be written.";

class RenderCommand : public Command {
public:
    CLI::App* add(CLI::App* app) override {
        cmd = app->add_subcommand("render", "Render a scene's apparent shapes into DIR");
        cmd->add_option("scene", rs.stage.scene_path,
                        "Scene file: JSON (.json, README 'Scene format') or glTF (.gltf or .glb with object "
                        "fields in node extras, README 'Scenes in glTF')")
            ->required();
        cmd->add_option("--out", rs.out_dir, "Output folder (created if missing)")->capture_default_str();
        cmd->add_option("--model", model_text,
                        "instant|finite|relativistic|contracted|all, or a comma list (default: the scene's model)");
        cmd->add_option("--format", format_text, "Comma list of glb, ply, obj, web (DIR/scene.web.glb: the scene "
                        "itself, rest meshes, motions, camera and light, for a viewer that cuts live; its size does "
                        "not grow with the frames)")->capture_default_str();
        cmd->add_option("--tolerance", tolerance_text,
                        "Largest distance between output and exact apparent surface (overrides the scene's): "
                        "T light-seconds; Fx, F times each object's bounding-box diagonal (default 1e-3x); "
                        "or 'vertex': exact vertices joined by straight edges, no refinement");
        cmd->add_option("--attribute-tolerance", attribute_tolerance_text,
                        "Also bound the parametric error, each output point against the exact image of its own "
                        "rest point (where a texture or an emission time lands): A light-seconds or Fx; default: "
                        "none, only the distance --tolerance is bounded (faces that contain the velocity stay "
                        "coarse inside)");
        cmd->add_option("--frames", frames_text, "A:B renders global frames A..B-1 (either end may be omitted)");
        cmd->add_option("--compress", compress_text,
                        "Compression of the .glb's frame meshes: draco (KHR_draco_mesh_compression; Blender reads "
                        "it), meshopt (EXT_meshopt_compression + KHR_mesh_quantization, smallest; web viewers) or "
                        "none (default)");
        cmd->add_flag("--draco", rs.glb.draco, "Same as --compress draco");
        cmd->add_option("--meshopt-bits", rs.glb.meshopt_bits,
                        "meshopt position bits over each frame's extent (2-16; default: a step following the "
                        "tolerance, 14 bits in vertex mode)");
        cmd->add_option("--attributes", attributes_text,
                        "Comma list of extra per-vertex .glb attributes: doppler (_DOPPLER, received over emitted "
                        "frequency), proper_time (_PROPER_TIME, the object's clock at emission); PLY frames always "
                        "hold both");
        cmd->add_option("--shade", shade_text,
                        "plain (default: each material's colour) or doppler (COLOR_0 per vertex: the base colour "
                        "shifted by the Doppler factor and brightened by the searchlight factor; README 'Doppler "
                        "colours')");
        cmd->add_option("--draco-bits", rs.glb.position_bits, "Draco position quantization bits (1-30)")
            ->capture_default_str();
        cmd->add_option("--draco-texcoord-bits", rs.glb.texcoord_bits,
                        "Draco texture-coordinate quantization bits (1-30; input glTF TEXCOORD_0)")
            ->capture_default_str();
        cmd->add_option("--threads", rs.threads, "Worker threads for the frame loop (0: all cores); "
                        "output is byte-identical for any count")->capture_default_str();
        cmd->add_flag("--cull-view", rs.cull_view,
                      "Leave objects wholly outside the camera's view empty in that frame (faster; "
                      "the files then show only what the camera sees)");
        cmd->add_flag("--quiet,-q", rs.quiet, "No progress or summary");
        cmd->add_flag("--verbose,-v", rs.verbose, "Mesh topology and export precision");
        cmd->add_option("--max-vertices", max_vertices, "Refuse meshes with more vertices")->capture_default_str();
        cmd->add_option("--max-faces", max_faces, "Refuse meshes with more faces")->capture_default_str();
        cmd->add_option("--max-file-bytes", max_file_bytes, "Refuse mesh files (and glTF buffers) larger than this")
            ->capture_default_str();
        cmd->add_option("--max-triangles", rs.max_frame_triangles,
                        "Stop with exit code 2 when one frame's refinement would make more triangles than this "
                        "(a --tolerance too fine for the scene); default: 4 x the scene's input triangles "
                        "(objects x (1 + mirrors)), at least " + std::to_string(kMinFrameTriangleBudget));
        cmd->add_option("--max-output-bytes", rs.max_output_bytes,
                        "Stop with exit code 3 before the outputs would exceed this many bytes in all "
                        "(estimated from the first frames before writing anything; 0: no limit)")
            ->capture_default_str();
        cmd->add_option("--shard", shard_text,
                        "I/N: render part I (0..N-1) of N of the frames, as one task of a job array: frames k "
                        "with k - first = I mod N; PLY/OBJ frames to their final names, the .glb's frames into "
                        "DIR/shards/<model>.I-of-N.shard for 'apparent merge DIR'");
        addStageLimits(cmd, &rs.stage);
        cmd->footer(kRenderFooter);
        return cmd;
    }

    int run(std::ostream& out, std::ostream& err) override {
        if (!shard_text.empty()) {
            if (!parseShard(shard_text, &rs.shard))
                return usageError(err, "--shard: '" + shard_text + "' is not I/N with 0 <= I < N <= " + std::to_string(kMaxShards));
            rs.sharded = true;
        }
        if (std::string message; !parseModelList(model_text, &rs.stage, &message)) return usageError(err, message);
        rs.formats.clear();
        {
            const std::vector<std::string>& known = outputFormats();
            std::string names;  // "ply, obj, glb"
            for (const std::string& n : known) names += (names.empty() ? "" : ", ") + n;
            std::stringstream ss(format_text);
            std::string item;
            while (std::getline(ss, item, ',')) {
                if (std::find(known.begin(), known.end(), item) == known.end())
                    return usageError(err, "--format: unknown format '" + item + "' (" + names + ")");
                if (std::find(rs.formats.begin(), rs.formats.end(), item) == rs.formats.end()) rs.formats.push_back(item);
            }
            if (rs.formats.empty()) return usageError(err, "--format: no format given (" + names + ")");
        }
        if (!tolerance_text.empty()) {
            if (!parseTolerance(tolerance_text, &rs.stage.tolerance, &rs.stage.tolerance_relative))
                return usageError(err, "--tolerance: '" + tolerance_text +
                             "' is neither a positive number of light-seconds, a fraction of each object's size such as "
                             "1e-3x, nor 'vertex'");
            rs.stage.has_tolerance = true;
        }
        if (!attribute_tolerance_text.empty() &&
            (!parseTolerance(attribute_tolerance_text, &rs.stage.attribute_tolerance, &rs.stage.attribute_tolerance_relative) ||
             (rs.stage.attribute_tolerance <= 0 && rs.stage.attribute_tolerance_relative <= 0)))
            return usageError(err, "--attribute-tolerance: '" + attribute_tolerance_text +
                         "' is neither a positive number of light-seconds nor a fraction of each object's size such as 1e-3x");
        if (!frames_text.empty() && !parseFrames(frames_text, &rs.stage.frame_from, &rs.stage.frame_to))
            return usageError(err, "--frames: '" + frames_text + "' is not A:B with 0 <= A < B");
        if (!compress_text.empty()) {
            if (compress_text != "draco" && compress_text != "meshopt" && compress_text != "none")
                return usageError(err, "--compress: unknown compression '" + compress_text + "' (draco, meshopt, none)");
            if (rs.glb.draco && compress_text != "draco")
                return usageError(err, "--draco and --compress " + compress_text + " contradict each other");
            rs.glb.draco = compress_text == "draco";
            rs.glb.meshopt = compress_text == "meshopt";
        }
        if (!attributes_text.empty()) {
            std::stringstream ss(attributes_text);
            std::string item;
            while (std::getline(ss, item, ',')) {
                if (item == "doppler") rs.glb.doppler = true;
                else if (item == "proper_time") rs.glb.proper_time = true;
                else return usageError(err, "--attributes: unknown attribute '" + item + "' (doppler, proper_time)");
            }
        }
        if (!shade_text.empty()) {
            if (shade_text != "plain" && shade_text != "doppler")
                return usageError(err, "--shade: unknown shading '" + shade_text + "' (plain, doppler)");
            rs.glb.shade_doppler = shade_text == "doppler";
            if (rs.glb.shade_doppler && std::find(rs.formats.begin(), rs.formats.end(), "glb") == rs.formats.end())
                return usageError(err, "--shade doppler: colours go into the .glb only (add glb to --format; the PLY frames hold "
                             "the doppler factor itself)");
        }
        if (rs.glb.meshopt_bits != 0 && (rs.glb.meshopt_bits < 2 || rs.glb.meshopt_bits > 16))
            return usageError(err, "--meshopt-bits: " + std::to_string(rs.glb.meshopt_bits) + " is outside 2..16");
        if (rs.glb.meshopt_bits != 0 && !rs.glb.meshopt) return usageError(err, "--meshopt-bits needs --compress meshopt");
        if (rs.glb.position_bits < 1 || rs.glb.position_bits > 30)
            return usageError(err, "--draco-bits: " + std::to_string(rs.glb.position_bits) + " is outside 1..30");
        if (rs.glb.texcoord_bits < 1 || rs.glb.texcoord_bits > 30)
            return usageError(err, "--draco-texcoord-bits: " + std::to_string(rs.glb.texcoord_bits) + " is outside 1..30");
        if (cmd->count("--draco-texcoord-bits") > 0 && !rs.glb.draco)
            return usageError(err, "--draco-texcoord-bits needs --compress draco");
        if (rs.threads < 0 || rs.threads > kMaxThreads) return usageError(err, threadsProblem(rs.threads));
        if (rs.max_frame_triangles < 0) return usageError(err, "--max-triangles: must be 0 (the default budget) or positive");
        if (max_vertices <= 0 || max_faces <= 0 || rs.stage.max_frames <= 0 || max_file_bytes <= 0)
            return usageError(err, "--max-vertices, --max-faces, --max-frames and --max-file-bytes must be positive");
        if (rs.max_output_bytes < 0) return usageError(err, "--max-output-bytes: must be positive, or 0 for no limit");
        rs.stage.limits.max_vertices = size_t(max_vertices);
        rs.stage.limits.max_faces = size_t(max_faces);
        rs.stage.limits.max_file_bytes = size_t(max_file_bytes);
        return guarded([&] { return render(rs, out, err); }, err);
    }

private:
    RenderSettings rs;
    std::string model_text, format_text = "glb", frames_text, tolerance_text, attribute_tolerance_text, compress_text,
        attributes_text, shade_text, shard_text;
    long long max_vertices = (long long)rs.stage.limits.max_vertices, max_faces = (long long)rs.stage.limits.max_faces,
              max_file_bytes = (long long)rs.stage.limits.max_file_bytes;
    CLI::App* cmd = nullptr;
};

}  // namespace

std::unique_ptr<Command> renderCommand() { return std::make_unique<RenderCommand>(); }

}  // namespace apparent
