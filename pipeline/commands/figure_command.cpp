// `apparent figure`: its options, checked into FigureSettings, then the sheet or video of
// pipeline/trace/figure.h.
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "pipeline/commands/command.h"
#include "pipeline/trace/figure.h"
#include "pipeline/trace/raytrace.h"

namespace apparent {

// ---- The command: `apparent figure` ----

namespace {

class FigureCommand : public Command {
public:
    CLI::App* add(CLI::App* app) override {
        cmd = app->add_subcommand(
            "figure", "The paper's comparison sheet: a row per model, a column per frame, labelled; or a side-by-side video");
        cmd->add_option("scene", fs.stage.scene_path, "Scene file (JSON or glTF)")->required();
        cmd->add_option("--out", fs.out_path, "Output PNG")->capture_default_str();
        cmd->add_option("--columns", fs.columns, "Frames per row, evenly spaced, first and last included")
            ->capture_default_str();
        cmd->add_option("--times", figure_times_text, "Comma list of camera times, one column each (nearest frame)");
        cmd->add_option("--frames", figure_frames_text, "A:B: columns are frames A..B-1 (with --video: the video's frames)");
        cmd->add_option("--models", figure_models_text, "Comma list of models, one row each (default instant,finite,relativistic)");
        cmd->add_option("--title", fs.title, "A title above the sheet (wrapped onto more lines when wider than the sheet)");
        cmd->add_flag("--no-labels", figure_no_labels, "No model names and camera times around the panels");
        cmd->add_option("--row-labels", figure_row_labels_text,
                        "Comma list, one label per model instead of its name (the rows; with --video the columns); "
                        "\\, for a comma in a label");
        cmd->add_option("--column-labels", figure_column_labels_text,
                        "Comma list, one label per column instead of its camera time (not with --video)");
        cmd->add_flag("--frame-objects", fs.frame_objects,
                      "Aim the camera and fit its field of view to the moving objects' apparent shapes over the "
                      "figure's frames and models (every object when none moves)");
        cmd->add_option("--samples", fs.samples,
                        "Rays per pixel, a square, as raytrace's (default " + std::to_string(kDefaultFigureSamples) +
                            "; with --video " + std::to_string(kDefaultRaytraceSamples) + ")");
        cmd->add_option("--shade", figure_shade_text, "plain (default) or doppler, as raytrace --shade");
        cmd->add_option("--video", fs.video_path, "Instead of the sheet: an H.264 MP4, the models side by side, every frame; needs ffmpeg");
        cmd->add_option("--size", figure_size_text, "Panel size WxH (default 320x180)");
        cmd->add_option("--threads", fs.threads, "Worker threads (0: all cores)")->capture_default_str();
        cmd->add_option("--gate", fs.gate, "As raytrace --gate: the gated camera's light-path slices, DEPTH deep");
        cmd->add_flag("--quiet,-q", fs.quiet, "No summary, no progress");
        addStageLimits(cmd, &fs.stage);
        cmd->add_option("--max-slab-memory", fs.max_slab_memory,
                        "As raytrace's (with --video the models share it)")
            ->capture_default_str();
        cmd->footer(
            "Examples:\n"
            "  apparent figure data/scenes/flanges.json --out sheet.png --times 4,7,8.5,10,13,16 --title \"Flanges at 0.866c\"\n"
            "  apparent figure data/scenes/terrell_cube.json --models contracted,relativistic --video cube.mp4\n"
            "Labels and titles use DejaVu Sans (Debian fonts-dejavu-core); --video needs the ffmpeg program in PATH.");
        return cmd;
    }

    int run(std::ostream& out, std::ostream& err) override {
        if (!figure_size_text.empty() && !parseSize(figure_size_text, &fs.width, &fs.height))
            return usageError(err, "--size: '" + figure_size_text + "' is not WxH with W and H in 1..16384");
        if (fs.columns < 1 || fs.columns > 64) return usageError(err, "--columns: must be in 1..64");
        if (fs.threads < 0 || fs.threads > kMaxThreads) return usageError(err, threadsProblem(fs.threads));
        if (fs.stage.max_frames <= 0) return usageError(err, "--max-frames: must be positive");
        if (!figure_frames_text.empty() && !parseFrames(figure_frames_text, &fs.frame_from, &fs.frame_to))
            return usageError(err, "--frames: '" + figure_frames_text + "' is not A:B with 0 <= A < B");
        if (!figure_times_text.empty() && !figure_frames_text.empty()) return usageError(err, "--times: give --times or --frames, not both");
        if (!fs.video_path.empty() && !figure_times_text.empty())
            return usageError(err, "--times: not with --video (a video shows every frame of --frames)");
        if (!fs.video_path.empty() && cmd->count("--columns") > 0)
            return usageError(err, "--columns: not with --video (a video shows every frame of --frames)");
        std::stringstream times(figure_times_text);
        for (std::string item; !figure_times_text.empty() && std::getline(times, item, ',');) {
            size_t used = 0;
            double t = NAN;
            try {
                t = std::stod(item, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used == 0 || used != item.size() || !std::isfinite(t)) return usageError(err, "--times: '" + item + "' is not a number");
            fs.times.push_back(t);
        }
        if (fs.times.size() > size_t(kMaxFigureColumns))
            return usageError(err, "--times: more than " + std::to_string(kMaxFigureColumns) + " columns");
        StageOptions figure_models;
        if (std::string message; !parseModelList(figure_models_text, &figure_models, &message))
            return usageError(err, "--models" + message.substr(std::string("--model").size()));
        if (figure_models.all_models) fs.models = {Model::Instant, Model::Finite, Model::Relativistic, Model::Contracted};
        for (Model m : figure_models.models) fs.models.push_back(m);
        fs.labels = !figure_no_labels;
        if (fs.samples != 0 && samplesSide(fs.samples) == 0) return usageError(err, samplesProblem(fs.samples));
        if (cmd->count("--samples") > 0 && fs.samples == 0) return usageError(err, samplesProblem(0));
        fs.row_labels = splitLabels(figure_row_labels_text);
        fs.column_labels = splitLabels(figure_column_labels_text);
        if (figure_no_labels && !(fs.row_labels.empty() && fs.column_labels.empty()))
            return usageError(err, "--no-labels: not with --row-labels or --column-labels");
        if (!fs.video_path.empty() && !fs.column_labels.empty())
            return usageError(err, "--column-labels: not with --video (its columns are the models: --row-labels)");
        if (!figure_shade_text.empty() && figure_shade_text != "plain" && figure_shade_text != "doppler")
            return usageError(err, "--shade: unknown shading '" + figure_shade_text + "' (plain, doppler)");
        fs.shade_doppler = figure_shade_text == "doppler";
        if (fs.max_slab_memory < kTraceBytesPerPrism)
            return usageError(err, "--max-slab-memory: " + std::to_string(fs.max_slab_memory) + " bytes, less than one prism's " +
                         std::to_string(kTraceBytesPerPrism));
        return guarded([&] { return figure(fs, out, err); }, err);
    }

private:
    FigureSettings fs;
    std::string figure_size_text, figure_times_text, figure_frames_text, figure_models_text,
        figure_row_labels_text, figure_column_labels_text, figure_shade_text;
    bool figure_no_labels = false;
    CLI::App* cmd = nullptr;
};

}  // namespace

std::unique_ptr<Command> figureCommand() { return std::make_unique<FigureCommand>(); }

}  // namespace apparent
