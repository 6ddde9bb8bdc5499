#include "pipeline/trace/figure.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <ostream>
#include <sstream>

#include <tbb/task_arena.h>

#include "exporters/video.h"
#include "pipeline/run/distribute.h"
#include "pipeline/stage/framing.h"
#include "pipeline/stage/view_hints.h"

namespace apparent {

using mesh4d::Vec3;

std::vector<long long> figureFrames(const Scene& scene, int columns) {
    const long long total = frameCount(scene.frames);
    std::vector<long long> frames;
    for (int j = 0; j < columns; ++j)
        frames.push_back(columns == 1 ? total / 2 : (long long)std::llround(double(j) * double(total - 1) / (columns - 1)));
    return frames;
}

bool framesAtTimes(const Scene& scene, const std::vector<double>& times, std::vector<long long>* frames,
                   std::string* error) {
    const long long total = frameCount(scene.frames);
    frames->clear();
    for (double t : times) {
        const double k = std::round((t - scene.frames.start) * scene.frames.fps);
        if (!(k >= 0 && k < double(total))) {
            std::ostringstream msg;
            msg << "--times: t = " << t << " s is outside the scene's frames (" << scene.frames.start << " to "
                << frameTime(scene.frames, total - 1) << " s)";
            *error = msg.str();
            return false;
        }
        frames->push_back((long long)k);
    }
    return true;
}

TimePrefix cameraTimePrefix(const Scene& scene) {
    const double last = frameTime(scene.frames, std::max(0LL, frameCount(scene.frames) - 1));
    return timePrefixFor(std::max(std::fabs(scene.frames.start), std::fabs(last)));
}

std::string cameraTimeLabel(const Scene& scene, long long k) {
    // As many decimals as the frame rate needs in the prefix's unit (10 fps: one), so labels keep
    // their width in a video.
    const TimePrefix prefix = cameraTimePrefix(scene);
    const double rate = scene.frames.fps * prefix.seconds;
    const int decimals = rate <= 1 ? 0 : std::min(6, int(std::ceil(std::log10(rate) - 1e-9)));
    return "t = " + timeText(frameTime(scene.frames, k), prefix, decimals);
}

namespace {

// Under mpirun (pipeline/run/distribute.h) a figure's pictures are shared as raytrace's frames are:
// picture i (a panel of the sheet, or a frame of the video) is traced by rank i mod N, which
// sends it to rank 0; rank 0 places or encodes them in order and writes the one output.
// The group's side of a figure: `fail` ends the ranks' loop with a code (rank 0), `picture`
// makes picture i here or receives it from its rank (false: failed, the code returned).
struct FigureGroup {
    FrameGroup& group = frameGroup();
    bool sender = group.rank() > 0;
    bool receiver = group.rank() == 0 && group.size() > 1;
    FrameSplit split{group.rank(), group.size()};
    std::ostream* err = nullptr;

    int fail(int code, const std::string& message) {
        if (receiver) group.endFrames(code);
        *err << "error: " << message << "\n";
        return code;
    }
    // Rank 0: picture i of `width` x `height` into *image, made by `make` here or received; the
    // progress counts a received picture's rows (`rows` of them).
    template <typename Make>
    int picture(long long i, int width, int height, long long rows, TraceProgress* progress, RgbImage* image,
                const Make& make) {
        const int from = split.partOf(i, 0);
        if (from == 0) {
            *image = make(progress);
            return kExitOk;
        }
        std::string bytes, error;
        int remote = 0;
        if (!group.receiveFrame(from, &bytes, &remote, &error)) return fail(remote ? remote : 1, error);
        *image = RgbImage(width, height);
        if (bytes.size() != image->rgb.size())
            return fail(1, "internal: rank " + std::to_string(from) + " sent a picture of " + std::to_string(bytes.size()) +
                               " bytes for picture " + std::to_string(i));
        std::copy(bytes.begin(), bytes.end(), image->rgb.begin());
        for (long long row = 0; row < rows; ++row) progress->rowDone();
        return kExitOk;
    }
    // Rank r > 0: picture i made and sent when it is this rank's; false once rank 0 said END.
    template <typename Make>
    bool send(long long i, const Make& make) {
        if (!split.owns(i, 0)) return true;
        if (group.stopRequested()) return false;
        const RgbImage image = make(nullptr);
        group.sendFrame(std::string(image.rgb.begin(), image.rgb.end()));
        return true;
    }
};

// The side-by-side video of `figure --video`: one video frame per scene frame in the stage's range,
// the models in columns under their names, the camera time (after the title) above.
// The summary line's shared end, each part after `sep`: samples per pixel, the framing, the processes.
void summaryTail(std::ostream& log, const char* sep, int side, const FigureSettings& settings, const Scene& scene,
                 const FigureGroup& fg) {
    if (side > 1) log << sep << side * side << " samples a pixel";
    if (settings.frame_objects) {
        const Vec3 at = scene.camera.look_at * unitsPerLightSecond(scene.units);  // in the scene's units
        log << sep << "framed: camera.look_at [" << at.x << ", " << at.y << ", " << at.z << "], camera.fov_deg "
            << scene.camera.fov_deg;
    }
    if (fg.receiver) log << sep << fg.group.size() << " processes shared the frames";
    log << "\n";
}

int figureVideo(const FigureSettings& settings, const Stage& stage, const TextPainter* painter, FigureGroup& fg,
                std::ostream& log, std::ostream& err) {
    const Scene& scene = stage.scene;
    std::string error;
    SheetText base_text;
    if (painter)
        for (size_t m = 0; m < stage.models.size(); ++m)
            base_text.column_labels.push_back(settings.row_labels.empty() ? modelName(stage.models[m]) : settings.row_labels[m]);
    base_text.title = "t";  // a title band for the time, filled per frame
    const auto title_at = [&](long long k) {
        return (settings.title.empty() ? "" : settings.title + "   ") + cameraTimeLabel(scene, k);
    };
    SheetLayout base(1, int(stage.models.size()), settings.width, settings.height, base_text, painter != nullptr);
    // Step: the title band as high as the longest title of any frame wraps to (one size for the video).
    if (painter)
        for (long long k = stage.first; k < stage.last_excl; ++k)
            base.min_title_lines = std::max(base.min_title_lines,
                                            int(wrapText(*painter, title_at(k), base.title_px, base.width - 2 * base.pad).size()));
    const int extra_lines = painter ? base.min_title_lines - 1 : 0;
    const int sheet_width = base.width, sheet_height = base.height + extra_lines * base.titleStep();
    const int side = samplesSide(settings.samples > 0 ? settings.samples : kDefaultRaytraceSamples);
    std::vector<std::unique_ptr<SceneTracer>> tracers;
    for (Model m : stage.models) {
        TracerOptions options;  // the models' tracers at once share the budget
        options.window_prisms = slabPrismLimit(settings.max_slab_memory / (long long)stage.models.size());
        tracers.push_back(
            std::make_unique<SceneTracer>(scene, stage.objects, stage.mirrors, m, stage.first, stage.last_excl - 1, options));
        tracers.back()->setShadeDoppler(settings.shade_doppler);
        tracers.back()->setSamplesSide(side);
        tracers.back()->setGate(settings.gate);
    }
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    // Video frame k: the title band with its time, then every model's panel.
    long long k = stage.first;
    auto make = [&](TraceProgress* progress) {
        SheetText text = base_text;
        text.title = title_at(k);
        SheetLayout layout = base;
        RgbImage sheet = drawSheet(text, painter, &layout);
        for (size_t m = 0; m < tracers.size(); ++m) {
            if (progress) progress->setLabel(std::string(modelName(stage.models[m])) + " frame " + std::to_string(k));
            TracedFrame frame;
            arena.execute([&] { frame = tracers[m]->traceFrame(k, settings.width, settings.height, progress); });
            placePanel(&sheet, layout, 0, int(m), frame.image);
        }
        return sheet;
    };
    if (fg.sender) {
        for (; k < stage.last_excl && fg.send(k - stage.first, make); ++k) {}
        return fg.group.finishSending();
    }
    VideoWriter writer;
    if (!writer.open(settings.video_path, sheet_width, sheet_height, scene.frames.fps, &error))
        return fg.fail(kExitOutputError, error);
    TraceProgress progress(err, !settings.quiet,
                           (long long)stage.models.size() * (stage.last_excl - stage.first) * settings.height * side);
    for (; k < stage.last_excl; ++k) {
        RgbImage sheet;
        if (const int code = fg.picture(k - stage.first, sheet_width, sheet_height,
                                        (long long)stage.models.size() * settings.height * side, &progress, &sheet, make))
            return code;
        if (!writer.addFrame(sheet, &error)) return fg.fail(kExitOutputError, error);
    }
    if (!writer.finish(&error)) return fg.fail(kExitOutputError, error);
    if (fg.receiver) fg.group.endFrames(0);
    progress.finish();
    if (!settings.quiet) {
        log << settings.video_path << ": " << writer.frames() << " frames of " << sheet_width << "x" << sheet_height
            << " at " << scene.frames.fps << " fps (H.264), frames " << stage.first << ".." << stage.last_excl - 1;
        summaryTail(log, ", ", side, settings, scene, fg);
    }
    return kExitOk;
}

}  // namespace

int figure(const FigureSettings& settings, std::ostream& log_out, std::ostream& err_out) {
    // Under mpirun the ranks share the pictures (FigureGroup above); the others print nothing.
    FigureGroup fg;
    std::ostringstream silent;
    std::ostream& log = fg.sender ? silent : log_out;
    std::ostream& err = fg.sender ? silent : err_out;
    fg.err = &err;
    // Step: the stage, for the rows' models (instant, finite, relativistic unless --models) and
    // all frames (a video: the --frames range).
    const bool video = !settings.video_path.empty();
    Stage stage;
    StageOptions stage_options = settings.stage;
    stage_options.models = settings.models.empty() ? std::vector<Model>{Model::Instant, Model::Finite, Model::Relativistic}
                                                   : settings.models;
    stage_options.all_models = false;
    stage_options.frame_from = video && settings.frame_from >= 0 ? settings.frame_from : 0;
    stage_options.frame_to = video && settings.frame_from >= 0 ? settings.frame_to : -1;
    stage_options.quiet = settings.quiet || fg.sender;
    std::string error;
    int code = loadStage(stage_options, &stage, err, &error) ? kExitOk : kExitBadInput;
    if (!code) {
        const long long memory = video ? settings.max_slab_memory / (long long)stage.models.size() : settings.max_slab_memory;
        if (Status s = checkTracedStage(stage, memory, settings.gate, settings.quiet, err); !s.ok) {
            error = s.message;
            code = kExitBadInput;
        }
    }
    const Scene& scene = stage.scene;
    const std::vector<Model>& rows = stage.models;
    // Step: the columns: --times, --frames A:B, or --columns evenly spaced.
    std::vector<long long> frames;
    if (!code && !video) {
        if (!settings.times.empty()) {
            if (!framesAtTimes(scene, settings.times, &frames, &error)) code = kExitBadInput;
        } else if (settings.frame_from >= 0) {
            const long long total = frameCount(scene.frames);
            const long long to = settings.frame_to < 0 ? total : settings.frame_to;
            if (settings.frame_from >= total || to > total) {
                error = "--frames: " + std::to_string(settings.frame_from) + ":" + std::to_string(to) +
                        " is outside the scene's " + std::to_string(total) + " frames";
                code = kExitBadInput;
            } else if (to - settings.frame_from > kMaxFigureColumns) {
                error = "--frames: " + std::to_string(to - settings.frame_from) + " columns, more than " +
                        std::to_string(kMaxFigureColumns);
                code = kExitBadInput;
            }
            for (long long k = settings.frame_from; !code && k < to; ++k) frames.push_back(k);
        } else {
            frames = figureFrames(scene, settings.columns);
        }
    }
    // Step: the labels given for the rows and columns, one each.
    if (!code && !settings.row_labels.empty() && settings.row_labels.size() != rows.size()) {
        error = "--row-labels: " + std::to_string(settings.row_labels.size()) + " labels for " +
                std::to_string(rows.size()) + " models";
        code = kExitBadInput;
    }
    if (!code && !settings.column_labels.empty() && settings.column_labels.size() != frames.size()) {
        error = "--column-labels: " + std::to_string(settings.column_labels.size()) + " labels for " +
                std::to_string(frames.size()) + " columns";
        code = kExitBadInput;
    }
    // Step: --frame-objects: the camera aimed and its view fitted to the objects in these frames.
    if (!code && settings.frame_objects) {
        std::vector<long long> framed = frames;
        for (long long k = stage.first; video && k < stage.last_excl; ++k) framed.push_back(k);
        if (Status s = frameObjects(stage, rows, framed, settings.width, settings.height, &stage.scene.camera); !s.ok) {
            error = s.message;
            code = kExitBadInput;
        }
    }
    // Step: the font (labels and title) and ffmpeg (video), before any tracing.
    TextPainter painter;
    const bool with_text = settings.labels || !settings.title.empty();
    if (!code && with_text && !painter.open(kLabelFontPath, &error)) code = kExitBadInput;
    if (!code && !fg.sender && video && findInPath("ffmpeg").empty()) {
        error = ffmpegMissingMessage("--video");
        code = kExitBadInput;
    }
    if ((code = fg.group.agree(code, &error))) {
        err << "error: " << error << "\n";
        return code;
    }
    if (video) return figureVideo(settings, stage, with_text ? &painter : nullptr, fg, log, err);
    // Step: lay out the sheet: a row per model, a column per frame, labels in bands left and above.
    SheetText text;
    text.title = settings.title;
    if (settings.labels) {
        text.row_labels = settings.row_labels;
        text.column_labels = settings.column_labels;
        for (size_t r = 0; settings.row_labels.empty() && r < rows.size(); ++r) text.row_labels.push_back(modelName(rows[r]));
        for (size_t c = 0; settings.column_labels.empty() && c < frames.size(); ++c)
            text.column_labels.push_back(cameraTimeLabel(scene, frames[c]));
    }
    SheetLayout layout(int(rows.size()), int(frames.size()), settings.width, settings.height, text, with_text);
    RgbImage sheet = fg.sender ? RgbImage() : drawSheet(text, with_text ? &painter : nullptr, &layout);
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    const int side = samplesSide(settings.samples > 0 ? settings.samples : kDefaultFigureSamples);
    TraceProgress progress(err, !settings.quiet && !fg.sender,
                           (long long)rows.size() * (long long)frames.size() * settings.height * side);
    // Panel i = r * columns + c: row r's model at column c's frame.
    const auto [lo, hi] = std::minmax_element(frames.begin(), frames.end());
    for (size_t r = 0; r < rows.size(); ++r) {
        // Hints instead of an empty row: an object no column shows in the camera's view (view_hints.h).
        if (!settings.quiet && !fg.sender)
            for (const std::string& w : outOfViewWarnings(stage, rows[r], frames)) err << "warning: " << w << "\n";
        TracerOptions options;
        options.window_prisms = slabPrismLimit(settings.max_slab_memory);
        SceneTracer tracer(scene, stage.objects, stage.mirrors, rows[r], *lo, *hi, options);
        tracer.setShadeDoppler(settings.shade_doppler);
        tracer.setSamplesSide(side);
        tracer.setGate(settings.gate);
        for (size_t c = 0; c < frames.size(); ++c) {
            auto make = [&](TraceProgress* p) {
                if (p) p->setLabel(std::string(modelName(rows[r])) + " frame " + std::to_string(frames[c]));
                TracedFrame frame;
                arena.execute([&] { frame = tracer.traceFrame(frames[c], settings.width, settings.height, p); });
                return frame.image;
            };
            const long long i = (long long)(r * frames.size() + c);
            if (fg.sender) {
                if (!fg.send(i, make)) return fg.group.finishSending();
                continue;
            }
            RgbImage panel;
            if (const int failed = fg.picture(i, settings.width, settings.height, (long long)settings.height * side, &progress, &panel, make))
                return failed;
            placePanel(&sheet, layout, int(r), int(c), panel);
        }
    }
    if (fg.sender) return fg.group.finishSending();
    progress.finish();
    const std::filesystem::path parent = std::filesystem::path(settings.out_path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (ec || !writePng(settings.out_path, sheet, &error))
        return fg.fail(kExitOutputError, ec ? settings.out_path + ": cannot create folder: " + ec.message() : error);
    if (fg.receiver) fg.group.endFrames(0);
    if (!settings.quiet) {
        log << settings.out_path << ": " << sheet.width << "x" << sheet.height << ", rows";
        for (Model m : rows) log << " " << modelName(m);
        log << "; frames";
        const TimePrefix prefix = cameraTimePrefix(scene);
        for (long long k : frames)
            log << " " << k << " (t = " << frameTime(scene.frames, k) / prefix.seconds << " " << prefix.name << ")";
        summaryTail(log, "; ", side, settings, scene, fg);
    }
    return kExitOk;
}

}  // namespace apparent
