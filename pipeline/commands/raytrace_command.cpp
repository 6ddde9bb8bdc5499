// `apparent raytrace` (pipeline/trace/raytrace.h RaytraceSettings): the 4D raytracer's frames as PNG
// files and/or one video, shared between ranks under mpirun.
#include "pipeline/trace/raytrace.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <tbb/task_arena.h>

#include "exporters/video.h"
#include "pipeline/commands/command.h"
#include "pipeline/run/distribute.h"
#include "pipeline/stage/view_hints.h"

namespace apparent {

int raytrace(const RaytraceSettings& settings, std::ostream& log_out, std::ostream& err_out) {
    // Under mpirun the ranks share the frames as render's do (pipeline/run/distribute.h): rank r traces
    // frames k with k - first = r mod N and sends each picture to rank 0, which writes the PNG files
    // and the video in frame order; the other ranks print nothing.
    FrameGroup& group = frameGroup();
    const bool sender = group.rank() > 0, receiver = group.rank() == 0 && group.size() > 1;
    std::ostringstream silent;
    std::ostream& log = sender ? silent : log_out;
    std::ostream& err = sender ? silent : err_out;
    // Step: the stage: scene, models, frames, meshes, mirrors; then the video's one model and ffmpeg.
    Stage stage;
    StageOptions stage_options = settings.stage;
    stage_options.quiet = settings.quiet || sender;
    std::string error;
    int code = loadStage(stage_options, &stage, err, &error) ? kExitOk : kExitBadInput;
    if (!code)
        if (Status s = checkTracedStage(stage, settings.max_slab_memory, settings.gate, settings.quiet, err); !s.ok) {
            error = s.message;
            code = kExitBadInput;
        }
    const bool video = !settings.video_path.empty();
    if (!code && !sender && video && stage.models.size() != 1) {
        error = "--video: a video shows one model (" + std::to_string(stage.models.size()) +
                " asked); `apparent figure --video` shows several side by side";
        code = kExitBadInput;
    }
    if (!code && !sender && video && findInPath("ffmpeg").empty()) {
        error = ffmpegMissingMessage("--video");
        code = kExitBadInput;
    }
    if ((code = group.agree(code, &error))) {
        err << "error: " << error << "\n";
        return code;
    }
    const long long first = stage.first, last_excl = stage.last_excl;
    const FrameSplit split{group.rank(), group.size()};

    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    const int side = samplesSide(settings.samples);
    TraceProgress progress(err, !settings.quiet && !sender,
                           (long long)stage.models.size() * (last_excl - first) * settings.height * side);
    for (Model model : stage.models) {
        const auto start = std::chrono::steady_clock::now();
        TracerOptions options;
        options.window_prisms = slabPrismLimit(settings.max_slab_memory);
        SceneTracer tracer(stage.scene, stage.objects, stage.mirrors, model, first, last_excl - 1, options);
        tracer.setShadeDoppler(settings.shade_doppler);
        tracer.setSamplesSide(side);
        tracer.setGate(settings.gate);
        if (sender) {
            // Step (rank r > 0): trace this rank's frames and send each picture, until rank 0 says END.
            for (long long k = first + split.part; k < last_excl && !group.stopRequested(); k += split.parts) {
                TracedFrame frame;
                arena.execute([&] { frame = tracer.traceFrame(k, settings.width, settings.height, nullptr); });
                group.sendFrame(std::string(frame.image.rgb.begin(), frame.image.rgb.end()));
            }
            if (const int end = group.finishSending()) return end;
            continue;
        }
        // Rank 0 (or one process): a failure ends every rank's frames with its code.
        auto fail = [&](int c, const std::string& message) {
            if (receiver) group.endFrames(c);
            err << "error: " << message << "\n";
            return c;
        };
        // Hints instead of blanks: an object no frame shows in the camera's view (view_hints.h).
        if (!settings.quiet)
            for (const std::string& w : outOfViewWarnings(stage, model, frameRange(first, last_excl))) err << "warning: " << w << "\n";
        // Step: the folder, then the static worlds once per model, then every frame.
        const std::string dir = (std::filesystem::path(settings.out_dir) / modelName(model)).string();
        if (settings.write_png) {
            std::error_code ec;
            std::filesystem::create_directories(dir, ec);
            if (ec) return fail(kExitOutputError, dir + ": cannot create output folder: " + ec.message());
        }
        VideoWriter writer;
        if (video && !writer.open(settings.video_path, settings.width, settings.height, stage.scene.frames.fps, &error))
            return fail(kExitOutputError, error);
        for (long long k = first; k < last_excl; ++k) {
            progress.setLabel(std::string(modelName(model)) + " frame " + std::to_string(k));
            TracedFrame frame;
            if (split.partOf(k, first) == 0) {
                arena.execute([&] { frame = tracer.traceFrame(k, settings.width, settings.height, &progress); });
            } else {
                std::string bytes;
                int remote = 0;
                if (!group.receiveFrame(split.partOf(k, first), &bytes, &remote, &error))
                    return fail(remote ? remote : 1, error);
                frame.image = RgbImage(settings.width, settings.height);
                if (bytes.size() != frame.image.rgb.size())
                    return fail(1, "internal: rank " + std::to_string(split.partOf(k, first)) + " sent a picture of " +
                                       std::to_string(bytes.size()) + " bytes for frame " + std::to_string(k));
                std::copy(bytes.begin(), bytes.end(), frame.image.rgb.begin());
                for (int row = 0; row < settings.height * side; ++row) progress.rowDone();
            }
            if (settings.write_png &&
                !writePng((std::filesystem::path(dir) / (frameName(k) + ".png")).string(), frame.image, &error))
                return fail(kExitOutputError, error);
            if (video && !writer.addFrame(frame.image, &error)) return fail(kExitOutputError, error);
        }
        if (video && !writer.finish(&error)) return fail(kExitOutputError, error);
        if (receiver) group.endFrames(0);
        progress.finish();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!settings.quiet) {
            log << modelName(model) << ": " << (last_excl - first) << " frames of " << settings.width << "x"
                << settings.height << (side > 1 ? ", " + std::to_string(side * side) + " samples a pixel," : "") << " in "
                << std::fixed << std::setprecision(2) << seconds << " s" << std::defaultfloat << std::setprecision(6);
            if (settings.write_png) log << ", " << dir << "/";
            if (video) log << ", " << settings.video_path << " (H.264, " << stage.scene.frames.fps << " fps)";
            if (receiver) log << ", " << group.size() << " processes shared the frames";
            const SceneTracer::SlabCounts& slabs = tracer.slabCounts();
            if (slabs.windows == 1 && slabs.built > 0) log << ", " << slabs.built << " time slabs";
            if (slabs.windows > 1)
                log << ", " << slabs.built << " time slabs in " << slabs.windows << " windows of frames (at most "
                    << slabs.most << " at once)";
            log << "\n";
        }
    }
    return kExitOk;
}


// ---- The command: `apparent raytrace` ----

namespace {

class RaytraceCommand : public Command {
public:
    CLI::App* add(CLI::App* app) override {
        cmd = app->add_subcommand("raytrace", "Ray-trace the 4D histories into PNG frames DIR/<model>/frame_NNNNN.png and/or an MP4 video");
        cmd->add_option("scene", ts.stage.scene_path, "Scene file (JSON or glTF)")->required();
        cmd->add_option("--out", ts.out_dir, "Output folder (created if missing)")->capture_default_str();
        cmd->add_option("--model", trace_model_text, "instant|finite|relativistic|contracted|all, or a comma list");
        cmd->add_option("--size", trace_size_text, "Image size WxH (default 480x270)");
        cmd->add_option("--frames", trace_frames_text, "A:B traces global frames A..B-1");
        cmd->add_option("--threads", ts.threads, "Worker threads (0: all cores)")->capture_default_str();
        cmd->add_option("--video", ts.video_path,
                        "Also (or, without --out, only) an H.264 MP4 of the frames at the scene's fps, one model; needs ffmpeg");
        cmd->add_option("--shade", trace_shade_text,
                        "plain (default) or doppler: colours shifted by the Doppler factor and scaled by the "
                        "searchlight factor, as render --shade doppler bakes them");
        cmd->add_option("--samples", ts.samples,
                        "Rays per pixel, a square (1, 4, 9, ..., 256): the centres of a grid of equal strata, "
                        "averaged in linear light; 1: one ray through the pixel centre")
            ->capture_default_str();
        cmd->add_option("--gate", ts.gate,
                        "The Vienna experiment's gated camera (finite, relativistic): exposures of light-path slices "
                        "DEPTH deep (scene units), each showing the objects at its own time");
        cmd->add_flag("--quiet,-q", ts.quiet, "No summary, no progress");
        addStageLimits(cmd, &ts.stage);
        cmd->add_option("--max-slab-memory", ts.max_slab_memory,
                        "Memory for one window of time slabs (spinning, accelerated, keyframed objects), bytes; "
                        "a frame that needs more is refused before they are built")
            ->capture_default_str();
        cmd->footer(
            "Examples:\n"
            "  apparent raytrace data/scenes/flanges.json --out frames --model all --frames 80:120\n"
            "  apparent raytrace data/scenes/terrell_cube.json --model relativistic --video cube.mp4\n"
            "--video needs the ffmpeg program in PATH. Progress goes to stderr unless --quiet.");
        return cmd;
    }

    int run(std::ostream& out, std::ostream& err) override {
        if (std::string message; !parseModelList(trace_model_text, &ts.stage, &message)) return usageError(err, message);
        if (!trace_size_text.empty() && !parseSize(trace_size_text, &ts.width, &ts.height))
            return usageError(err, "--size: '" + trace_size_text + "' is not WxH with W and H in 1..16384");
        if (!trace_frames_text.empty() && !parseFrames(trace_frames_text, &ts.stage.frame_from, &ts.stage.frame_to))
            return usageError(err, "--frames: '" + trace_frames_text + "' is not A:B with 0 <= A < B");
        if (!trace_shade_text.empty() && trace_shade_text != "plain" && trace_shade_text != "doppler")
            return usageError(err, "--shade: unknown shading '" + trace_shade_text + "' (plain, doppler)");
        ts.shade_doppler = trace_shade_text == "doppler";
        if (samplesSide(ts.samples) == 0) return usageError(err, samplesProblem(ts.samples));
        if (ts.threads < 0 || ts.threads > kMaxThreads) return usageError(err, threadsProblem(ts.threads));
        if (ts.stage.max_frames <= 0) return usageError(err, "--max-frames: must be positive");
        if (ts.max_slab_memory < kTraceBytesPerPrism)
            return usageError(err, "--max-slab-memory: " + std::to_string(ts.max_slab_memory) + " bytes, less than one prism's " +
                         std::to_string(kTraceBytesPerPrism));
        ts.write_png = ts.video_path.empty() || cmd->count("--out") > 0;
        return guarded([&] { return raytrace(ts, out, err); }, err);
    }

private:
    RaytraceSettings ts;
    std::string trace_model_text, trace_size_text, trace_frames_text, trace_shade_text;
    CLI::App* cmd = nullptr;
};

}  // namespace

std::unique_ptr<Command> raytraceCommand() { return std::make_unique<RaytraceCommand>(); }

}  // namespace apparent
