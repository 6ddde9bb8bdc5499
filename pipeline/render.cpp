#include "pipeline/render.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>

#include "exporters/obj.h"
#include "exporters/ply.h"
#include "pipeline/mesh_check.h"

namespace apparent {

namespace {

// One output format: its --format name and how its sink is made for a model. `base` is
// DIR/<model>: the folder of per-frame files and the stem of a file per sequence. A new format is
// one more entry here and one sink in exporters/ (README "Adding a motion model, a format, a command").
struct OutputFormat {
    std::string name;
    std::function<std::unique_ptr<FrameSink>(const RenderSettings&, const std::string& base)> make;
};

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
        return n;
    }();
    return names;
}

int render(const RenderSettings& settings, std::ostream& log, std::ostream& err) {
    // Step: the stage: scene, models, frames, meshes, mirrors.
    Stage stage;
    std::string error;
    StageOptions stage_options = settings.stage;
    stage_options.quiet = settings.quiet;
    if (!loadStage(stage_options, &stage, err, &error)) {
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
    std::filesystem::create_directories(settings.out_dir, ec);
    if (ec) {
        err << "error: " << settings.out_dir << ": cannot create output folder: " << ec.message() << "\n";
        return kExitOutputError;
    }

    // Step: per model, the frame loop into one sink per format; the budget spans the whole run.
    OutputBudget budget(settings.max_output_bytes);
    FrameLoopSettings loop;
    loop.threads = settings.threads;
    loop.max_frame_triangles =
        settings.max_frame_triangles > 0 ? settings.max_frame_triangles : defaultFrameTriangleBudget(stage);
    loop.cull_view = settings.cull_view;
    loop.progress = !settings.quiet;
    loop.models_left = (long long)stage.models.size();
    std::vector<std::string> created;  // DIR/<model> folders of per-frame files that did not exist
    for (Model model : stage.models) {
        const std::string folder = (std::filesystem::path(settings.out_dir) / modelName(model)).string();
        if (!std::filesystem::exists(folder, ec)) created.push_back(folder);
    }
    for (Model model : stage.models) {
        const std::string name = modelName(model);
        const std::string base = (std::filesystem::path(settings.out_dir) / name).string();
        std::vector<std::unique_ptr<FrameSink>> owned;
        std::vector<FrameSink*> sinks;
        for (const OutputFormat& f : formatTable()) {
            if (std::find(settings.formats.begin(), settings.formats.end(), f.name) == settings.formats.end()) continue;
            owned.push_back(f.make(settings, base));
            sinks.push_back(owned.back().get());
        }
        FrameLoopResult result;
        const bool ran = runFrameLoop(stage, model, loop, sinks, &budget, err, &result, &error);
        --loop.models_left;
        if (!ran) {
            owned.clear();  // the sinks remove their temporaries
            // Folders this run created and left empty go too (remove() takes only empty ones).
            for (const std::string& folder : created) std::filesystem::remove(folder, ec);
            if (!had_folder) std::filesystem::remove(settings.out_dir, ec);
            err << "error: " << error << "\n";
            return result.over_budget ? kExitBadInput : kExitOutputError;
        }
        // Step: the summary: the sinks' warnings and files, and the refinement limit if reached.
        std::string summary;
        for (const SinkSummary& s : result.summaries) {
            summary += s.text;
            if (!settings.quiet)
                for (const std::string& w : s.warnings) err << "warning: " << w << "\n";
        }
        if (result.limited_triangles > 0 && !settings.quiet)
            err << "warning: " << name << ": " << result.limited_triangles
                << " triangle-frames reached the refinement limit of " << result.max_segments
                << " segments; the tolerance " << stage.scene.tolerance
                << " ls is not met there (a coarser tolerance or a finer input mesh helps)\n";
        if (!settings.quiet)
            log << name << ": " << (stage.last_excl - stage.first) << " frames, up to " << result.max_triangles
                << " triangles" << summary << "\n";
    }
    return kExitOk;
}

}  // namespace apparent
