#include "pipeline/frame_loop.h"

#include "pipeline/scene_fields.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>

#include <unistd.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "mesh4d/check.h"

namespace apparent {

namespace {

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
        std::ostringstream line;  // its own formatting: the stream's stays as it was
        line << "\r" << label_ << ": frame " << done << "/" << total_ << std::fixed << std::setprecision(1) << " ("
             << rate << " frames/s, " << (rate > 0 ? double(total_ - done) / rate : 0) << " s left)   ";
        if (done == total_) line << "\n";
        err_ << line.str() << std::flush;
    }

private:
    std::ostream& err_;
    bool enabled_;
    std::string label_;
    long long total_;
    std::chrono::steady_clock::time_point start_;
    double last_ = -1;
};

}  // namespace

bool OutputBudget::fitsEstimate(double estimate, long long measured, long long total, std::string* error) const {
    if (limit_ <= 0 || double(written_) + estimate <= double(limit_)) return true;
    const double whole = double(written_) + estimate;
    std::ostringstream size;
    size << std::fixed << std::setprecision(1) << whole / double(1LL << 20) << " MiB";
    *error = "--max-output-bytes: this run would write about " + std::to_string((long long)whole) + " bytes (" +
             size.str() + ", estimated from " + std::to_string(measured) + " of " + std::to_string(total) +
             " frames), more than the limit of " + std::to_string(limit_) + "; " +
             (written_ ? "nothing more was written (the files written are complete)" : "nothing was written") +
             ": use a coarser --tolerance (e.g. 1e-2x), fewer --frames, --compress draco, or raise it with "
             "--max-output-bytes (0: no limit)";
    return false;
}

bool OutputBudget::fits(long long more, const std::string& what, std::string* error) const {
    if (limit_ <= 0 || written_ + more <= limit_) return true;
    *error = "--max-output-bytes: " + what + (more ? " would bring" : " brought") + " the output to " +
             std::to_string(written_ + more) + " bytes, more than the limit of " + std::to_string(limit_) + " (" +
             std::to_string(written_) + " bytes written, every written file is complete; raise it with --max-output-bytes)";
    return false;
}

bool OutputBudget::count(const std::string& path, std::string* error) {
    std::error_code ec;
    const auto n = std::filesystem::file_size(path, ec);
    if (!ec) written_ += (long long)n;
    return fits(0, path, error);
}

SequenceInfo sequenceInfo(const Stage& stage, Model model) {
    const Scene& scene = stage.scene;
    SequenceInfo info;
    info.model = modelName(model);
    info.tolerance = scene.tolerance;
    info.fps = scene.frames.fps;
    info.scene_path = scene.path;
    for (size_t i = 0; i < stage.objects.size(); ++i) {
        ExportObject o;
        o.name = stage.objects[i].spec.name;
        o.base_color = objectBaseColor(stage.objects, i);
        info.objects.push_back(o);
    }
    info.camera.position = scene.camera.position;
    info.camera.look_at = scene.camera.look_at;
    info.camera.up = scene.camera.up;
    info.camera.fov_deg = scene.camera.fov_deg;
    return info;
}

bool runFrameLoop(const Stage& stage, Model model, const FrameLoopSettings& settings,
                  const std::vector<FrameSink*>& sinks, OutputBudget* budget, std::ostream& progress_out,
                  FrameLoopResult* result, std::string* error) {
    const Scene& scene = stage.scene;
    const long long first = stage.first, last_excl = stage.last_excl;
    // Step: the static 4D worlds and the mirrors' reflections, once per model.
    const std::vector<mesh4d::World4D> worlds = buildWorlds(stage.objects, model, scene, first, last_excl - 1);
    const MirrorReflections reflections(scene, stage.objects, stage.mirrors, model, first, last_excl - 1);
    SequenceInfo info = sequenceInfo(stage, model);
    reflections.describe(&info);
    for (FrameSink* sink : sinks)
        if (!sink->begin(info, error)) return false;

    // Step: per frame, cut every world with the view surface (refined to the tolerance), then deliver.
    mesh4d::SliceSettings slice_settings;
    slice_settings.tolerance = scene.tolerance;
    slice_settings.max_triangles = size_t(settings.max_frame_triangles);
    result->max_segments = slice_settings.max_segments;
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    Progress progress(progress_out, settings.progress, info.model, last_excl - first);
    // Frames are independent given the static worlds: cut a batch in parallel (TBB), then deliver
    // it in frame order, so files are byte-identical whatever the thread count.
    const long long batch = std::max<long long>(1, 4 * (long long)arena.max_concurrency());
    for (long long b0 = first; b0 < last_excl; b0 += batch) {
        const long long b1 = std::min(last_excl, b0 + batch);
        std::vector<ExportFrame> cut(size_t(b1 - b0));
        // prepared[frame][sink]: each sink's conversion of the frame, made on the worker too.
        std::vector<std::vector<std::shared_ptr<const PreparedFrame>>> prepared(size_t(b1 - b0));
        arena.execute([&] {
            tbb::parallel_for(b0, b1, [&](long long k) {
                ExportFrame& frame = cut[size_t(k - b0)];
                frame.index = k;
                frame.t_c = frameTime(scene.frames, k);
                const mesh4d::ViewSurface view = viewForFrame(scene, model, k);
                // Objects in parallel too (a short range of frames of a many-object scene), each
                // into its own slot: the result does not depend on the scheduling.
                frame.objects.resize(worlds.size());
                tbb::parallel_for(size_t(0), worlds.size(), [&](size_t o) {
                    const mesh4d::World4D& w = worlds[o];
                    // --cull-view: an object wholly outside the camera's view is left empty.
                    if (settings.cull_view && !inCameraView(scene.camera, mesh4d::apparentBound(w, view))) return;
                    mesh4d::SliceSettings own = slice_settings;
                    own.tolerance = stage.tolerances[o];  // each object's (pipeline/stage.h)
                    frame.objects[o] = mesh4d::sliceWorld(w, view, own);
                });
                // Mirrors add their retarded reflections as further objects (pipeline/mirror.h).
                reflections.append(view, slice_settings, &frame.objects, &stage.tolerances);
                APPARENT_CHECK(frame.objects.size(), ==, info.objects.size());
                for (const FrameSink* sink : sinks) prepared[size_t(k - b0)].push_back(sink->prepare(frame));
            });
        });
        // Before the first write: the first batch's estimate, scaled to the whole run.
        // (A frame past --max-triangles is reported below instead.)
        if (b0 == first) {
            double bytes = 0;
            bool too_many = false;
            for (const ExportFrame& frame : cut) {
                too_many = too_many || frame.triangleCount() > size_t(settings.max_frame_triangles) ||
                           std::any_of(frame.objects.begin(), frame.objects.end(),
                                       [](const mesh4d::ApparentMesh& o) { return o.over_budget; });
                for (const FrameSink* sink : sinks) bytes += double(sink->estimate(frame));
            }
            if (too_many) bytes = 0;
            const double whole = bytes / double(cut.size()) * double(last_excl - first) * double(settings.models_left);
            if (!budget->fitsEstimate(whole, (long long)cut.size(), last_excl - first, error)) return false;
        }
        for (size_t i = 0; i < cut.size(); ++i) {
            const ExportFrame& frame = cut[i];
            const bool stopped = std::any_of(frame.objects.begin(), frame.objects.end(),
                                             [](const mesh4d::ApparentMesh& o) { return o.over_budget; });
            if (stopped || frame.triangleCount() > size_t(settings.max_frame_triangles)) {
                result->over_budget = true;
                *error = scene.path + ": frame " + std::to_string(frame.index) + ": tolerance " +
                         formatNumber(scene.tolerance) + " makes more than " + std::to_string(settings.max_frame_triangles) +
                         " triangles (--max-triangles); use a coarser --tolerance or raise --max-triangles";
                return false;
            }
            result->max_triangles = std::max(result->max_triangles, frame.triangleCount());
            for (const auto& o : frame.objects) result->limited_triangles += o.limited_triangles;
            for (size_t s = 0; s < sinks.size(); ++s) {
                // Refused before writing beyond the limit; every completed file counted after.
                const PendingOutput pending = sinks[s]->pending(frame);
                if (!budget->fits(pending.bytes, pending.name, error)) return false;
                std::vector<std::string> completed;
                if (!sinks[s]->add(frame, prepared[i][s].get(), &completed, error)) return false;
                for (const std::string& path : completed)
                    if (!budget->count(path, error)) return false;
            }
            progress.update(frame.index - first + 1);
        }
    }

    // Step: what needs the whole sequence (the .glb is assembled here).
    result->summaries.assign(sinks.size(), {});
    for (size_t s = 0; s < sinks.size(); ++s) {
        sinks[s]->setFinishCheck([budget](long long bytes, const std::string& name, std::string* e) {
            return budget->fits(bytes, name, e);
        });
        if (!sinks[s]->finish(&result->summaries[s], error)) return false;
        for (const std::string& path : result->summaries[s].completed)
            if (!budget->count(path, error)) return false;
    }
    return true;
}

}  // namespace apparent
