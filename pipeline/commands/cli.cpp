#include "pipeline/commands/cli.h"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "pipeline/commands/measure.h"
#include "pipeline/commands/render.h"
#include "pipeline/commands/trade.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/run/shards.h"
#include "pipeline/trace/figure.h"
#include "pipeline/trace/raytrace.h"

namespace apparent {

namespace {

constexpr const char* kDescription =
    "apparent: what objects moving near the speed of light look like, as 3D geometry.\n"
    "Extrudes meshes of moving objects (uniform, spinning or rolling, accelerated, keyframed; the\n"
    "camera at rest or moving) into 4D histories, cuts them with the camera's past lightcone for\n"
    "every frame and exports the apparent shapes (Black et al., Am. J. Phys. 2007).\n"
    "Units: light-seconds and seconds, c = 1.";

constexpr const char* kRenderFooter =
    "Models:\n"
    "  instant       infinite light speed: every object where it is at the frame time\n"
    "  finite        finite light speed, Galilean objects (classical aberration only)\n"
    "  relativistic  finite light speed, Lorentz-boosted objects (what special relativity shows)\n"
    "  contracted    the Lorentz-contracted shape at the frame time (measured, never seen)\n"
    "Outputs in DIR:\n"
    "  <model>.glb                      one animated glTF holding every frame (STEP scale channels)\n"
    "  <model>/frame_NNNNN.ply|.obj     per frame, all objects; PLY vertex 'quality' = emission time\n"
    "Exit codes: 0 success, 1 internal error, 2 bad usage or bad input, 3 output could not be written.";

bool parseFrames(const std::string& text, long long* from, long long* to) {
    const auto colon = text.find(':');
    if (colon == std::string::npos) return false;
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    try {
        size_t used = 0;
        *from = a.empty() ? 0 : std::stoll(a, &used);
        if (!a.empty() && used != a.size()) return false;
        *to = b.empty() ? -1 : std::stoll(b, &used);
        if (!b.empty() && used != b.size()) return false;
    } catch (const std::exception&) {
        return false;
    }
    return *from >= 0 && (*to < 0 || *to > *from);
}

// "WxH" with 1 <= W, H <= 16384.
bool parseSize(const std::string& text, int* width, int* height) {
    const auto x = text.find('x');
    if (x == std::string::npos) return false;
    try {
        size_t used_w = 0, used_h = 0;
        const long w = std::stol(text.substr(0, x), &used_w), h = std::stol(text.substr(x + 1), &used_h);
        if (used_w != x || used_h != text.size() - x - 1 || w < 1 || h < 1 || w > 16384 || h > 16384) return false;
        *width = int(w);
        *height = int(h);
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

// --samples N refused: N is not a square of 1..16.
std::string samplesProblem(int samples) {
    return "--samples: " + std::to_string(samples) + " is not a square from 1 to 256 (1, 4, 9, 16, ...)";
}

// --row-labels, --column-labels: a comma list; "\," is a comma within a label.
std::vector<std::string> splitLabels(const std::string& text) {
    std::vector<std::string> labels;
    if (text.empty()) return labels;
    labels.emplace_back();
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\\' && i + 1 < text.size() && text[i + 1] == ',') {
            labels.back() += ',';
            ++i;
        } else if (text[i] == ',') {
            labels.emplace_back();
        } else {
            labels.back() += text[i];
        }
    }
    return labels;
}

// --model: a comma list of models ("relativistic", "finite,instant", "all"), for every command
// that takes one; false with the message for an unknown name.
bool parseModelList(const std::string& text, StageOptions* options, std::string* error) {
    std::stringstream ss(text);
    std::string item;
    while (!text.empty() && std::getline(ss, item, ',')) {
        Model m;
        if (item == "all") {
            options->all_models = true;
        } else if (parseModel(item, &m)) {
            options->models.push_back(m);
        } else {
            *error = "--model: unknown model '" + item + "' (instant, finite, relativistic, contracted, all)";
            return false;
        }
    }
    return true;
}

// The limits of every command that loads a scene (pipeline/stage/stage.h).
void addStageLimits(CLI::App* command, StageOptions* stage) {
    command->add_option("--max-frames", stage->max_frames, "Refuse scenes with more frames")->capture_default_str();
    command->add_option("--max-object-frames", stage->max_object_frames,
                        "Refuse runs whose objects (mirror reflections included) times frames exceed this")
        ->capture_default_str();
    command->add_flag("--allow-outside", stage->limits.allow_outside,
                      "Let scene mesh paths leave the scene's folder and the working folder");
}

// Worker threads a command may ask for: TBB fails on far more (10 000 000 crashed it).
constexpr int kMaxThreads = 1024;

std::string threadsProblem(long long n) {
    return "--threads: " + std::to_string(n) + " is outside 0 (all cores) .. " + std::to_string(kMaxThreads);
}

}  // namespace

// Runs a command; what it cannot handle itself becomes one line: out of memory (exit 3) or a broken
// invariant (exit 1), never std::terminate.
template <class Command>
int guarded(Command command, std::ostream& err) {
    try {
        return command();
    } catch (const std::bad_alloc&) {
        err << "error: out of memory (try a coarser --tolerance, fewer frames or a smaller --size)\n";
        return kExitOutputError;
    } catch (const std::exception& e) {
        err << "error: internal: " << e.what() << "\n";
        return 1;
    }
}

int runCommandLine(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app(kDescription, "apparent");
    app.set_version_flag("--version", "apparent 0.1.0");
    app.require_subcommand(1);

    RenderSettings rs;
    std::string model_text, format_text = "glb", frames_text, tolerance_text;
    long long max_vertices = (long long)rs.stage.limits.max_vertices, max_faces = (long long)rs.stage.limits.max_faces;
    CLI::App* render_cmd = app.add_subcommand("render", "Render a scene's apparent shapes into DIR");
    render_cmd->add_option("scene", rs.stage.scene_path,
                           "Scene file: JSON (.json, README 'Scene format') or glTF (.gltf or .glb with object "
                           "fields in node extras, README 'Scenes in glTF')")
        ->required();
    render_cmd->add_option("--out", rs.out_dir, "Output folder (created if missing)")->capture_default_str();
    render_cmd->add_option("--model", model_text,
                           "instant|finite|relativistic|contracted|all, or a comma list (default: the scene's model)");
    render_cmd->add_option("--format", format_text, "Comma list of glb, ply, obj")->capture_default_str();
    render_cmd->add_option("--tolerance", tolerance_text,
                           "Largest distance between output and exact apparent surface (overrides the scene's): "
                           "T light-seconds; Fx, F times each object's bounding-box diagonal (default 1e-3x); "
                           "or 'vertex': exact vertices joined by straight edges, no refinement");
    std::string attribute_tolerance_text;
    render_cmd->add_option("--attribute-tolerance", attribute_tolerance_text,
                           "Also bound the parametric error, each output point against the exact image of its own "
                           "rest point (where a texture or an emission time lands): A light-seconds or Fx; default: "
                           "none, only the distance --tolerance is bounded (faces that contain the velocity stay "
                           "coarse inside)");
    render_cmd->add_option("--frames", frames_text, "A:B renders global frames A..B-1 (either end may be omitted)");
    std::string compress_text;
    render_cmd->add_option("--compress", compress_text,
                           "Compression of the .glb's frame meshes: draco (KHR_draco_mesh_compression; Blender reads "
                           "it), meshopt (EXT_meshopt_compression + KHR_mesh_quantization, smallest; web viewers) or "
                           "none (default)");
    render_cmd->add_flag("--draco", rs.glb.draco, "Same as --compress draco");
    render_cmd->add_option("--meshopt-bits", rs.glb.meshopt_bits,
                           "meshopt position bits over each frame's extent (2-16; default: a step following the "
                           "tolerance, 14 bits in vertex mode)");
    std::string attributes_text;
    render_cmd->add_option("--attributes", attributes_text,
                           "Comma list of extra per-vertex .glb attributes: doppler (_DOPPLER, received over emitted "
                           "frequency), proper_time (_PROPER_TIME, the object's clock at emission); PLY frames always "
                           "hold both");
    std::string shade_text;
    render_cmd->add_option("--shade", shade_text,
                           "plain (default: each material's colour) or doppler (COLOR_0 per vertex: the base colour "
                           "shifted by the Doppler factor and brightened by the searchlight factor; README 'Doppler "
                           "colours')");
    render_cmd->add_option("--draco-bits", rs.glb.position_bits, "Draco position quantization bits (1-30)")
        ->capture_default_str();
    render_cmd->add_option("--draco-texcoord-bits", rs.glb.texcoord_bits,
                           "Draco texture-coordinate quantization bits (1-30; input glTF TEXCOORD_0)")
        ->capture_default_str();
    render_cmd->add_option("--threads", rs.threads, "Worker threads for the frame loop (0: all cores); "
                           "output is byte-identical for any count")->capture_default_str();
    render_cmd->add_flag("--cull-view", rs.cull_view,
                         "Leave objects wholly outside the camera's view empty in that frame (faster; "
                         "the files then show only what the camera sees)");
    render_cmd->add_flag("--quiet,-q", rs.quiet, "No progress or summary");
    render_cmd->add_flag("--verbose,-v", rs.verbose, "Mesh topology and export precision");
    render_cmd->add_option("--max-vertices", max_vertices, "Refuse meshes with more vertices")->capture_default_str();
    render_cmd->add_option("--max-faces", max_faces, "Refuse meshes with more faces")->capture_default_str();
    long long max_file_bytes = (long long)rs.stage.limits.max_file_bytes;
    render_cmd->add_option("--max-file-bytes", max_file_bytes, "Refuse mesh files (and glTF buffers) larger than this")
        ->capture_default_str();
    render_cmd->add_option("--max-triangles", rs.max_frame_triangles,
                           "Stop with exit code 2 when one frame's refinement would make more triangles than this "
                           "(a --tolerance too fine for the scene); default: 4 x the scene's input triangles "
                           "(objects x (1 + mirrors)), at least " + std::to_string(kMinFrameTriangleBudget));
    render_cmd->add_option("--max-output-bytes", rs.max_output_bytes,
                           "Stop with exit code 3 before the outputs would exceed this many bytes in all "
                           "(estimated from the first frames before writing anything; 0: no limit)")
        ->capture_default_str();
    std::string shard_text;
    render_cmd->add_option("--shard", shard_text,
                           "I/N: render part I (0..N-1) of N of the frames, as one task of a job array: frames k "
                           "with k - first = I mod N; PLY/OBJ frames to their final names, the .glb's frames into "
                           "DIR/shards/<model>.I-of-N.shard for 'apparent merge DIR'");
    addStageLimits(render_cmd, &rs.stage);
    render_cmd->footer(kRenderFooter);


    // `raytrace` and `figure`: the paper's 4D raytracer as a reference (pipeline/trace/raytrace.h, pipeline/trace/figure.h).
    RaytraceSettings ts;
    std::string trace_model_text, trace_size_text, trace_frames_text;
    CLI::App* raytrace_cmd = app.add_subcommand("raytrace", "Ray-trace the 4D histories into PNG frames DIR/<model>/frame_NNNNN.png and/or an MP4 video");
    raytrace_cmd->add_option("scene", ts.stage.scene_path, "Scene file (JSON or glTF)")->required();
    raytrace_cmd->add_option("--out", ts.out_dir, "Output folder (created if missing)")->capture_default_str();
    raytrace_cmd->add_option("--model", trace_model_text, "instant|finite|relativistic|contracted|all, or a comma list");
    raytrace_cmd->add_option("--size", trace_size_text, "Image size WxH (default 480x270)");
    raytrace_cmd->add_option("--frames", trace_frames_text, "A:B traces global frames A..B-1");
    raytrace_cmd->add_option("--threads", ts.threads, "Worker threads (0: all cores)")->capture_default_str();
    raytrace_cmd->add_option("--video", ts.video_path,
                             "Also (or, without --out, only) an H.264 MP4 of the frames at the scene's fps, one model; needs ffmpeg");
    std::string trace_shade_text;
    raytrace_cmd->add_option("--shade", trace_shade_text,
                             "plain (default) or doppler: colours shifted by the Doppler factor and scaled by the "
                             "searchlight factor, as render --shade doppler bakes them");
    raytrace_cmd->add_option("--samples", ts.samples,
                             "Rays per pixel, a square (1, 4, 9, ..., 256): the centres of a grid of equal strata, "
                             "averaged in linear light; 1: one ray through the pixel centre")
        ->capture_default_str();
    raytrace_cmd->add_option("--gate", ts.gate,
                             "The Vienna experiment's gated camera (finite, relativistic): exposures of light-path slices "
                             "DEPTH deep (scene units), each showing the objects at its own time");
    raytrace_cmd->add_flag("--quiet,-q", ts.quiet, "No summary, no progress");
    addStageLimits(raytrace_cmd, &ts.stage);
    raytrace_cmd->add_option("--max-slab-memory", ts.max_slab_memory,
                             "Memory for one window of time slabs (spinning, accelerated, keyframed objects), bytes; "
                             "a frame that needs more is refused before they are built")
        ->capture_default_str();
    FigureSettings fs;
    std::string figure_size_text, figure_times_text, figure_frames_text, figure_models_text;
    bool figure_no_labels = false;
    CLI::App* figure_cmd = app.add_subcommand(
        "figure", "The paper's comparison sheet: a row per model, a column per frame, labelled; or a side-by-side video");
    figure_cmd->add_option("scene", fs.stage.scene_path, "Scene file (JSON or glTF)")->required();
    figure_cmd->add_option("--out", fs.out_path, "Output PNG")->capture_default_str();
    figure_cmd->add_option("--columns", fs.columns, "Frames per row, evenly spaced, first and last included")
        ->capture_default_str();
    figure_cmd->add_option("--times", figure_times_text, "Comma list of camera times, one column each (nearest frame)");
    figure_cmd->add_option("--frames", figure_frames_text, "A:B: columns are frames A..B-1 (with --video: the video's frames)");
    figure_cmd->add_option("--models", figure_models_text, "Comma list of models, one row each (default instant,finite,relativistic)");
    figure_cmd->add_option("--title", fs.title, "A title above the sheet (wrapped onto more lines when wider than the sheet)");
    figure_cmd->add_flag("--no-labels", figure_no_labels, "No model names and camera times around the panels");
    std::string figure_row_labels_text, figure_column_labels_text;
    figure_cmd->add_option("--row-labels", figure_row_labels_text,
                           "Comma list, one label per model instead of its name (the rows; with --video the columns); "
                           "\\, for a comma in a label");
    figure_cmd->add_option("--column-labels", figure_column_labels_text,
                           "Comma list, one label per column instead of its camera time (not with --video)");
    figure_cmd->add_flag("--frame-objects", fs.frame_objects,
                         "Aim the camera and fit its field of view to the moving objects' apparent shapes over the "
                         "figure's frames and models (every object when none moves)");
    figure_cmd->add_option("--samples", fs.samples,
                           "Rays per pixel, a square, as raytrace's (default " + std::to_string(kDefaultFigureSamples) +
                               "; with --video " + std::to_string(kDefaultRaytraceSamples) + ")");
    std::string figure_shade_text;
    figure_cmd->add_option("--shade", figure_shade_text, "plain (default) or doppler, as raytrace --shade");
    figure_cmd->add_option("--video", fs.video_path, "Instead of the sheet: an H.264 MP4, the models side by side, every frame; needs ffmpeg");
    figure_cmd->add_option("--size", figure_size_text, "Panel size WxH (default 320x180)");
    figure_cmd->add_option("--threads", fs.threads, "Worker threads (0: all cores)")->capture_default_str();
    figure_cmd->add_option("--gate", fs.gate, "As raytrace --gate: the gated camera's light-path slices, DEPTH deep");
    figure_cmd->add_flag("--quiet,-q", fs.quiet, "No summary, no progress");
    addStageLimits(figure_cmd, &fs.stage);
    figure_cmd->add_option("--max-slab-memory", fs.max_slab_memory,
                           "As raytrace's (with --video the models share it)")
        ->capture_default_str();
    figure_cmd->footer(
        "Examples:\n"
        "  apparent figure data/scenes/flanges.json --out sheet.png --times 4,7,8.5,10,13,16 --title \"Flanges at 0.866c\"\n"
        "  apparent figure data/scenes/terrell_cube.json --models contracted,relativistic --video cube.mp4\n"
        "Labels and titles use DejaVu Sans (Debian fonts-dejavu-core); --video needs the ffmpeg program in PATH.");
    raytrace_cmd->footer(
        "Examples:\n"
        "  apparent raytrace data/scenes/flanges.json --out frames --model all --frames 80:120\n"
        "  apparent raytrace data/scenes/terrell_cube.json --model relativistic --video cube.mp4\n"
        "--video needs the ffmpeg program in PATH. Progress goes to stderr unless --quiet.");

    // `trade`: the speed-accuracy trade measured on the user's scene (pipeline/commands/trade.h).
    TradeSettings trs;
    std::string trade_model_text, trade_frames_text, trade_tolerances_text;
    CLI::App* trade_cmd = app.add_subcommand(
        "trade", "Measure error against time and size on a scene: vertex mode, uniform subdivision, a ladder of tolerances");
    trade_cmd->add_option("scene", trs.stage.scene_path, "Scene file (JSON or glTF)")->required();
    trade_cmd->add_option("--out", trs.out_dir, "Folder for trade.csv, trade.png and trade.gp (created if missing)")
        ->capture_default_str();
    trade_cmd->add_option("--model", trade_model_text, "finite|relativistic (default: the scene's model)");
    trade_cmd->add_option("--frames", trade_frames_text, "A:B measures frames A..B-1 (default: 5 frames spread over the scene)");
    trade_cmd->add_option("--levels", trs.levels, "Uniform subdivision levels 1..N to compare")->capture_default_str();
    trade_cmd->add_option("--tolerances", trade_tolerances_text,
                          "Comma list of tolerances relative to the largest moving object's size (default 1e-1,3e-2,...,1e-4)");
    trade_cmd->add_option("--max-triangles", trs.max_triangles, "Skip rows with more output triangles per frame")
        ->capture_default_str();
    trade_cmd->add_flag("--quiet,-q", trs.quiet, "Only the table");
    addStageLimits(trade_cmd, &trs.stage);
    trade_cmd->footer(
        "Prints, for each row: the measured two-sided error to the exact apparent surface (sampled as the tests do),\n"
        "output triangles per frame, cut and .glb-conversion time per frame (one thread, its CPU time) and .glb bytes\n"
        "per frame; "
        "writes DIR/trade.csv and, with gnuplot, DIR/trade.png. Names the tolerance with the least time for vertex\n"
        "mode's error and for a tenth of it. Size: the largest moving object's bounding-box diagonal.");

    // `measure`: what the pictures show, as numbers (pipeline/commands/measure.h).
    MeasureSettings mss;
    std::string measure_model_text, measure_frames_text;
    CLI::App* measure_cmd = app.add_subcommand(
        "measure", "Measure the apparent shapes: extent, the rotation of faces about the view's up axis, outline roundness");
    measure_cmd->add_option("scene", mss.stage.scene_path, "Scene file (JSON or glTF)")->required();
    measure_cmd->add_option("--model", measure_model_text, "Model, comma list or all (default: the scene's model)");
    measure_cmd->add_option("--frames", measure_frames_text, "A:B measures frames A..B-1 (default: 5 frames spread over the scene)");
    measure_cmd->add_option("--marker", mss.marker, "An object whose apparent position is given relative to the others' outlines");
    measure_cmd->add_flag("--quiet,-q", mss.quiet, "Only the table");
    addStageLimits(measure_cmd, &mss.stage);
    measure_cmd->footer(
        "Prints per model, frame and object (tab-separated): apparent points, the image extent (orthographic: scene\n"
        "units on the image plane; perspective: the tangent plane at distance 1), the lab bounding box, the rotation\n"
        "about the view's up axis fitted to the projected areas of the faces (degrees; residual; scale, 1 for a pure\n"
        "turn), the outline's largest radius (rim) and roundness (largest over smallest radius). With --marker NAME,\n"
        "NAME's position as a fraction of each other object's rim radius. docs/PICTURES.md, \"Measuring a picture\".");

    // `merge`: the .glb of every model from the job-array shards in DIR/shards (pipeline/run/shards.h).
    MergeSettings ms;
    CLI::App* merge_cmd = app.add_subcommand(
        "merge", "Assemble DIR/<model>.glb from the shards of 'render --shard I/N --out DIR' (byte-identical to one process)");
    merge_cmd->add_option("dir", ms.out_dir, "The --out folder of the shards (reads DIR/shards)")->required();
    merge_cmd->add_option("--max-output-bytes", ms.max_output_bytes,
                          "Stop with exit code 3 before the .glb files would exceed this many bytes in all (0: no limit)")
        ->capture_default_str();
    merge_cmd->add_flag("--quiet,-q", ms.quiet, "No summary");
    merge_cmd->add_flag("--verbose,-v", ms.verbose, "Export precision, as render --verbose");
    merge_cmd->footer(
        "Refuses (exit code 2, one line) a shard that is missing, duplicated, incomplete, or made from another scene,\n"
        "other meshes or other output options (each shard holds a fingerprint of them). The shards stay in DIR/shards.");

    // An unknown command: CLI11 would say only "A subcommand is required"; name the nearest.
    if (argc > 1 && argv[1][0] != '-') {
        std::vector<std::string> names;
        for (const CLI::App* c : app.get_subcommands({})) names.push_back(c->get_name());
        if (std::find(names.begin(), names.end(), argv[1]) == names.end()) {
            const std::string near = nearestField(argv[1], names);
            err << "error: unknown command '" << argv[1] << "'"
                << (near.empty() ? "" : "; did you mean " + near + "?") << " (commands: " << fieldList(names)
                << "; run 'apparent --help')\n";
            return kExitBadInput;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kExitOk;
    } catch (const CLI::CallForAllHelp&) {
        out << app.help("", CLI::AppFormatMode::All);
        return kExitOk;
    } catch (const CLI::CallForVersion&) {
        out << "apparent 0.1.0\n";
        return kExitOk;
    } catch (const CLI::ParseError& e) {
        // CLI11 throws the subcommand's help as CallForHelp too; everything else is bad usage.
        err << "error: " << e.what() << "\n" << "Run 'apparent --help' or 'apparent render --help'.\n";
        return kExitBadInput;
    }
    // Step: turn the option strings into settings, one clear line per problem.
    auto usage = [&](const std::string& msg) {
        err << "error: " << msg << "\n";
        return kExitBadInput;
    };
    if (raytrace_cmd->parsed()) {
        if (std::string message; !parseModelList(trace_model_text, &ts.stage, &message)) return usage(message);
        if (!trace_size_text.empty() && !parseSize(trace_size_text, &ts.width, &ts.height))
            return usage("--size: '" + trace_size_text + "' is not WxH with W and H in 1..16384");
        if (!trace_frames_text.empty() && !parseFrames(trace_frames_text, &ts.stage.frame_from, &ts.stage.frame_to))
            return usage("--frames: '" + trace_frames_text + "' is not A:B with 0 <= A < B");
        if (!trace_shade_text.empty() && trace_shade_text != "plain" && trace_shade_text != "doppler")
            return usage("--shade: unknown shading '" + trace_shade_text + "' (plain, doppler)");
        ts.shade_doppler = trace_shade_text == "doppler";
        if (samplesSide(ts.samples) == 0) return usage(samplesProblem(ts.samples));
        if (ts.threads < 0 || ts.threads > kMaxThreads) return usage(threadsProblem(ts.threads));
        if (ts.stage.max_frames <= 0) return usage("--max-frames: must be positive");
        if (ts.max_slab_memory < kTraceBytesPerPrism)
            return usage("--max-slab-memory: " + std::to_string(ts.max_slab_memory) + " bytes, less than one prism's " +
                         std::to_string(kTraceBytesPerPrism));
        ts.write_png = ts.video_path.empty() || raytrace_cmd->count("--out") > 0;
        return guarded([&] { return raytrace(ts, out, err); }, err);
    }
    if (figure_cmd->parsed()) {
        if (!figure_size_text.empty() && !parseSize(figure_size_text, &fs.width, &fs.height))
            return usage("--size: '" + figure_size_text + "' is not WxH with W and H in 1..16384");
        if (fs.columns < 1 || fs.columns > 64) return usage("--columns: must be in 1..64");
        if (fs.threads < 0 || fs.threads > kMaxThreads) return usage(threadsProblem(fs.threads));
        if (fs.stage.max_frames <= 0) return usage("--max-frames: must be positive");
        if (!figure_frames_text.empty() && !parseFrames(figure_frames_text, &fs.frame_from, &fs.frame_to))
            return usage("--frames: '" + figure_frames_text + "' is not A:B with 0 <= A < B");
        if (!figure_times_text.empty() && !figure_frames_text.empty()) return usage("--times: give --times or --frames, not both");
        if (!fs.video_path.empty() && !figure_times_text.empty())
            return usage("--times: not with --video (a video shows every frame of --frames)");
        if (!fs.video_path.empty() && figure_cmd->count("--columns") > 0)
            return usage("--columns: not with --video (a video shows every frame of --frames)");
        std::stringstream times(figure_times_text);
        for (std::string item; !figure_times_text.empty() && std::getline(times, item, ',');) {
            size_t used = 0;
            double t = NAN;
            try {
                t = std::stod(item, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used == 0 || used != item.size() || !std::isfinite(t)) return usage("--times: '" + item + "' is not a number");
            fs.times.push_back(t);
        }
        if (fs.times.size() > size_t(kMaxFigureColumns))
            return usage("--times: more than " + std::to_string(kMaxFigureColumns) + " columns");
        StageOptions figure_models;
        if (std::string message; !parseModelList(figure_models_text, &figure_models, &message))
            return usage("--models" + message.substr(std::string("--model").size()));
        if (figure_models.all_models) fs.models = {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted};
        for (Model m : figure_models.models) fs.models.push_back(m);
        fs.labels = !figure_no_labels;
        if (fs.samples != 0 && samplesSide(fs.samples) == 0) return usage(samplesProblem(fs.samples));
        if (figure_cmd->count("--samples") > 0 && fs.samples == 0) return usage(samplesProblem(0));
        fs.row_labels = splitLabels(figure_row_labels_text);
        fs.column_labels = splitLabels(figure_column_labels_text);
        if (figure_no_labels && !(fs.row_labels.empty() && fs.column_labels.empty()))
            return usage("--no-labels: not with --row-labels or --column-labels");
        if (!fs.video_path.empty() && !fs.column_labels.empty())
            return usage("--column-labels: not with --video (its columns are the models: --row-labels)");
        if (!figure_shade_text.empty() && figure_shade_text != "plain" && figure_shade_text != "doppler")
            return usage("--shade: unknown shading '" + figure_shade_text + "' (plain, doppler)");
        fs.shade_doppler = figure_shade_text == "doppler";
        if (fs.max_slab_memory < kTraceBytesPerPrism)
            return usage("--max-slab-memory: " + std::to_string(fs.max_slab_memory) + " bytes, less than one prism's " +
                         std::to_string(kTraceBytesPerPrism));
        return guarded([&] { return figure(fs, out, err); }, err);
    }
    if (trade_cmd->parsed()) {
        if (std::string message; !parseModelList(trade_model_text, &trs.stage, &message)) return usage(message);
        if (!trade_frames_text.empty() && !parseFrames(trade_frames_text, &trs.stage.frame_from, &trs.stage.frame_to))
            return usage("--frames: '" + trade_frames_text + "' is not A:B with 0 <= A < B");
        trs.has_frames = !trade_frames_text.empty();
        trs.stage.quiet = trs.quiet;
        if (trs.levels < 0 || trs.levels > 8) return usage("--levels: must be in 0..8");
        if (trs.max_triangles <= 0) return usage("--max-triangles: must be positive");
        std::stringstream ss(trade_tolerances_text);
        std::string item;
        while (!trade_tolerances_text.empty() && std::getline(ss, item, ',')) {
            size_t used = 0;
            double t = 0;
            try {
                t = std::stod(item, &used);
            } catch (...) {
                used = 0;
            }
            if (used != item.size() || !(t > 0) || !(t < 1e3))
                return usage("--tolerances: '" + item + "' is not a positive number (a fraction of the object size)");
            trs.tolerances_rel.push_back(t);
        }
        return guarded([&] { return trade(trs, out, err); }, err);
    }
    if (measure_cmd->parsed()) {
        if (std::string message; !parseModelList(measure_model_text, &mss.stage, &message)) return usage(message);
        if (!measure_frames_text.empty() && !parseFrames(measure_frames_text, &mss.stage.frame_from, &mss.stage.frame_to))
            return usage("--frames: '" + measure_frames_text + "' is not A:B with 0 <= A < B");
        mss.has_frames = !measure_frames_text.empty();
        mss.stage.quiet = mss.quiet;
        return guarded([&] { return measure(mss, out, err); }, err);
    }
    if (merge_cmd->parsed()) {
        if (ms.max_output_bytes < 0) return usage("--max-output-bytes: must be positive, or 0 for no limit");
        return guarded([&] { return merge(ms, out, err); }, err);
    }
    if (!render_cmd->parsed()) return kExitBadInput;
    if (!shard_text.empty()) {
        if (!parseShard(shard_text, &rs.shard))
            return usage("--shard: '" + shard_text + "' is not I/N with 0 <= I < N <= " + std::to_string(kMaxShards));
        rs.sharded = true;
    }
    if (std::string message; !parseModelList(model_text, &rs.stage, &message)) return usage(message);
    rs.formats.clear();
    {
        const std::vector<std::string>& known = outputFormats();
        std::string names;  // "ply, obj, glb"
        for (const std::string& n : known) names += (names.empty() ? "" : ", ") + n;
        std::stringstream ss(format_text);
        std::string item;
        while (std::getline(ss, item, ',')) {
            if (std::find(known.begin(), known.end(), item) == known.end())
                return usage("--format: unknown format '" + item + "' (" + names + ")");
            if (std::find(rs.formats.begin(), rs.formats.end(), item) == rs.formats.end()) rs.formats.push_back(item);
        }
        if (rs.formats.empty()) return usage("--format: no format given (" + names + ")");
    }
    if (!tolerance_text.empty()) {
        if (!parseTolerance(tolerance_text, &rs.stage.tolerance, &rs.stage.tolerance_relative))
            return usage("--tolerance: '" + tolerance_text +
                         "' is neither a positive number of light-seconds, a fraction of each object's size such as "
                         "1e-3x, nor 'vertex'");
        rs.stage.has_tolerance = true;
    }
    if (!attribute_tolerance_text.empty() &&
        (!parseTolerance(attribute_tolerance_text, &rs.stage.attribute_tolerance, &rs.stage.attribute_tolerance_relative) ||
         (rs.stage.attribute_tolerance <= 0 && rs.stage.attribute_tolerance_relative <= 0)))
        return usage("--attribute-tolerance: '" + attribute_tolerance_text +
                     "' is neither a positive number of light-seconds nor a fraction of each object's size such as 1e-3x");
    if (!frames_text.empty() && !parseFrames(frames_text, &rs.stage.frame_from, &rs.stage.frame_to))
        return usage("--frames: '" + frames_text + "' is not A:B with 0 <= A < B");
    if (!compress_text.empty()) {
        if (compress_text != "draco" && compress_text != "meshopt" && compress_text != "none")
            return usage("--compress: unknown compression '" + compress_text + "' (draco, meshopt, none)");
        if (rs.glb.draco && compress_text != "draco")
            return usage("--draco and --compress " + compress_text + " contradict each other");
        rs.glb.draco = compress_text == "draco";
        rs.glb.meshopt = compress_text == "meshopt";
    }
    if (!attributes_text.empty()) {
        std::stringstream ss(attributes_text);
        std::string item;
        while (std::getline(ss, item, ',')) {
            if (item == "doppler") rs.glb.doppler = true;
            else if (item == "proper_time") rs.glb.proper_time = true;
            else return usage("--attributes: unknown attribute '" + item + "' (doppler, proper_time)");
        }
    }
    if (!shade_text.empty()) {
        if (shade_text != "plain" && shade_text != "doppler")
            return usage("--shade: unknown shading '" + shade_text + "' (plain, doppler)");
        rs.glb.shade_doppler = shade_text == "doppler";
        if (rs.glb.shade_doppler && std::find(rs.formats.begin(), rs.formats.end(), "glb") == rs.formats.end())
            return usage("--shade doppler: colours go into the .glb only (add glb to --format; the PLY frames hold "
                         "the doppler factor itself)");
    }
    if (rs.glb.meshopt_bits != 0 && (rs.glb.meshopt_bits < 2 || rs.glb.meshopt_bits > 16))
        return usage("--meshopt-bits: " + std::to_string(rs.glb.meshopt_bits) + " is outside 2..16");
    if (rs.glb.meshopt_bits != 0 && !rs.glb.meshopt) return usage("--meshopt-bits needs --compress meshopt");
    if (rs.glb.position_bits < 1 || rs.glb.position_bits > 30)
        return usage("--draco-bits: " + std::to_string(rs.glb.position_bits) + " is outside 1..30");
    if (rs.glb.texcoord_bits < 1 || rs.glb.texcoord_bits > 30)
        return usage("--draco-texcoord-bits: " + std::to_string(rs.glb.texcoord_bits) + " is outside 1..30");
    if (render_cmd->count("--draco-texcoord-bits") > 0 && !rs.glb.draco)
        return usage("--draco-texcoord-bits needs --compress draco");
    if (rs.threads < 0 || rs.threads > kMaxThreads) return usage(threadsProblem(rs.threads));
    if (rs.max_frame_triangles < 0) return usage("--max-triangles: must be 0 (the default budget) or positive");
    if (max_vertices <= 0 || max_faces <= 0 || rs.stage.max_frames <= 0 || max_file_bytes <= 0)
        return usage("--max-vertices, --max-faces, --max-frames and --max-file-bytes must be positive");
    if (rs.max_output_bytes < 0) return usage("--max-output-bytes: must be positive, or 0 for no limit");
    rs.stage.limits.max_vertices = size_t(max_vertices);
    rs.stage.limits.max_faces = size_t(max_faces);
    rs.stage.limits.max_file_bytes = size_t(max_file_bytes);
    return guarded([&] { return render(rs, out, err); }, err);
}

}  // namespace apparent
