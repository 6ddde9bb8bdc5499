#include "pipeline/run/frame_loop.h"

#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/frame_cut.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>

#include <time.h>
#include <unistd.h>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "mesh4d/check.h"

namespace apparent {

namespace {

// A frame over the per-frame budget: an object's refinement stopped at it, or all the frame's
// objects together hold more.
bool overBudget(const ExportFrame& frame, long long max_frame_triangles) {
    return frame.triangleCount() > size_t(max_frame_triangles) ||
           std::any_of(frame.objects.begin(), frame.objects.end(),
                       [](const mesh4d::ApparentMesh& o) { return o.over_budget; });
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

// CPU time of the calling thread, seconds (user and system).
double threadCpuSeconds() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Adds the wall and CPU time of its scope to the loop's write time (FrameLoopResult), and with
// `received` (work on a frame of another rank) also to its received time, however the scope is left.
class WriteTime {
public:
    explicit WriteTime(FrameLoopResult* r, bool received = false) : r_(r), received_(received) {}
    ~WriteTime() {
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        const double cpu = threadCpuSeconds() - cpu_;
        r_->write_seconds += seconds;
        r_->write_cpu_seconds += cpu;
        if (!received_) return;
        r_->received_seconds += seconds;
        r_->received_cpu_seconds += cpu;
    }
    WriteTime(const WriteTime&) = delete;
    WriteTime& operator=(const WriteTime&) = delete;

private:
    FrameLoopResult* r_;
    bool received_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
    double cpu_ = threadCpuSeconds();
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

namespace {

// runFrameLoop; with `take` (stage.objects itself, for the stage's last model) the rest meshes
// are handed to the worlds when no mirror needs them afterwards.
bool runLoop(const Stage& stage, std::vector<PreparedObject>* take, Model model, const FrameLoopSettings& settings,
             const std::vector<FrameSink*>& sinks, OutputBudget* budget, std::ostream& progress_out,
             FrameLoopResult* result, std::string* error) {
    const Scene& scene = stage.scene;
    const long long first = stage.first, last_excl = stage.last_excl;
    using Clock = std::chrono::steady_clock;
    const Clock::time_point loop_start = Clock::now();
    auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
    std::atomic<long long> cut_ns{0}, cut_cpu_ns{0};
    // Frames across processes (pipeline/run/distribute.h): a rank other than 0 only cuts and sends.
    FrameGroup& group = frameGroup();
    const bool sender = settings.distributed && group.rank() > 0;
    const bool receiver = settings.distributed && group.rank() == 0 && group.size() > 1;
    const FrameSplit split = settings.split;
    // Step: the static 4D worlds and the mirrors' reflections, once per model (what the sinks are
    // told first: the worlds may take the rest meshes it copies for the objects' looks).
    SequenceInfo info = sequenceInfo(stage, model);
    const std::vector<mesh4d::World4D> worlds = take && stage.mirrors.empty()
                                                    ? takeWorlds(take, model, scene, first, last_excl - 1)
                                                    : buildWorlds(stage.objects, model, scene, first, last_excl - 1);
    const MirrorReflections reflections(scene, stage.objects, stage.mirrors, model, first, last_excl - 1);
    reflections.describe(&info);
    for (FrameSink* sink : sinks)
        if (!(sender ? sink->beginEncoding(info, error) : sink->begin(info, error))) {
            if (receiver) {
                group.endFrames(kExitOutputError);
                for (FrameSink* other : sinks) other->dropEncoded(first, last_excl);
            }
            return false;
        }

    // Step: per frame, cut every world with the view surface (refined to the tolerance), then deliver.
    // The light factors only when a sink reads them (the same sinks on every process of the run,
    // so every rank or shard computes what the writing one needs).
    bool light_factors = false;
    for (const FrameSink* sink : sinks) light_factors = light_factors || sink->readsLightFactors();
    bool rest_points = false;
    for (const FrameSink* sink : sinks) rest_points = rest_points || sink->readsRestPoints();
    mesh4d::SliceSettings slice_settings;
    slice_settings.tolerance = scene.tolerance;
    slice_settings.max_triangles = size_t(settings.max_frame_triangles);
    result->max_segments = slice_settings.max_segments;
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    // Frames this process delivers: all of the range on MPI's rank 0, else its part.
    const long long delivered_total = settings.distributed ? last_excl - first : split.count(first, last_excl);
    Progress progress(progress_out, settings.progress && !sender, info.model, delivered_total);
    long long delivered = 0;
    // Frames are independent given the static worlds: a TBB pipeline cuts them in parallel and
    // delivers them in frame order, so files are byte-identical whatever the thread count. At most
    // `tokens` frames (cut meshes and the sinks' conversions) are held at once (and the first
    // kEstimateFrames, held back for the size estimate below), so the memory of a run is bounded by
    // about (tokens + kEstimateFrames) x the per-frame budget, also for a run the budget stops.
    // With MPI each frame is encoded on the worker that cut it (FrameSink::encode), and frames of
    // other ranks arrive encoded (`frame` then holds only its number).
    struct Work {
        ExportFrame frame;
        bool over_budget = false;
        std::vector<std::shared_ptr<const PreparedFrame>> prepared;  // per sink, made on the worker
        std::unique_ptr<EncodedFrame> encoded;                       // with MPI
        bool received = false;                                       // MPI rank 0: cut by another rank
    };
    using WorkPtr = std::shared_ptr<Work>;
    const size_t tokens = size_t(arena.max_concurrency()) + 1;
    long long next = first;
    while (next < last_excl && !split.owns(next, first)) ++next;
    std::atomic<bool> stop{false};  // set by the in-order stage on an error: later frames are skipped
    int failed_code = 0;            // with MPI: the code of a failure reported by another rank

    // Source, in order: the next frame number (of this process's part).
    auto source = [&](tbb::flow_control& fc) -> WorkPtr {
        if (stop || next >= last_excl) {
            fc.stop();
            return nullptr;
        }
        auto w = std::make_shared<Work>();
        w->frame.index = next;
        next += split.parts;
        ++result->frames_cut;
        return w;
    };
    // Frame k cut: every world with the frame's view surface (refined to the tolerance).
    auto cutOne = [&](long long k, ExportFrame* frame) {
        frame->t_c = frameTime(scene.frames, k);
        cutFrameAt(stage, worlds, reflections, viewForFrame(scene, model, k), slice_settings, settings.cull_view,
                   light_factors, frame);
        APPARENT_CHECK(frame->objects.size(), ==, info.objects.size());
    };
    // In parallel: cut every world with the frame's view surface, then each sink's conversion.
    auto cutFrame = [&](WorkPtr w) -> WorkPtr {
        if (stop) return w;
        const Clock::time_point cut_start = Clock::now();
        const double cpu_start = threadCpuSeconds();
        ExportFrame& frame = w->frame;
        const long long k = frame.index;
        cutOne(k, &frame);
        w->over_budget = overBudget(frame, settings.max_frame_triangles);
        if (!w->over_budget)
            for (const FrameSink* sink : sinks) w->prepared.push_back(sink->prepare(frame));
        // What no sink reads is released here, before the frame waits for its turn (FrameSink::readsRestPoints).
        if (!rest_points)
            for (mesh4d::ApparentMesh& o : frame.objects) {
                std::vector<mesh4d::Vec3>().swap(o.rest_points);
                std::vector<uint32_t>().swap(o.source_triangles);
            }
        if (settings.distributed) {
            // The frame as it travels; the cut mesh and the conversions are released here.
            auto e = std::make_unique<EncodedFrame>();
            e->index = k;
            e->triangles = frame.triangleCount();
            for (const auto& o : frame.objects) e->limited_triangles += o.limited_triangles;
            e->over_budget = w->over_budget;
            // A sink that encodes frame k against frame k - 1 (FrameSink::encodesAfterPrevious)
            // gets it cut here again: the frame before belongs to another part.
            ExportFrame before;
            bool wanted = false;
            for (size_t s = 0; !w->over_budget && k > first && s < sinks.size(); ++s)
                wanted = wanted || sinks[s]->encodesAfterPrevious();
            if (wanted) {
                before.index = k - 1;
                cutOne(k - 1, &before);
            }
            const bool have_before = wanted && !overBudget(before, settings.max_frame_triangles);
            for (size_t s = 0; !w->over_budget && s < sinks.size(); ++s)
                e->sinks.push_back(have_before && sinks[s]->encodesAfterPrevious()
                                       ? sinks[s]->encodeAfter(frame, w->prepared[s].get(), &before)
                                       : sinks[s]->encode(frame, w->prepared[s].get()));
            w->prepared.clear();
            frame.objects.clear();
            frame.objects.shrink_to_fit();
            w->encoded = std::move(e);
        }
        cut_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - cut_start).count();
        cut_cpu_ns += (long long)(1e9 * (threadCpuSeconds() - cpu_start));
        return w;
    };
    // Sink, in order: the budget checks, then every sink gets the frame.
    auto deliverOne = [&](const WorkPtr& w) {
        if (stop) return;
        const WriteTime timed(result, w->received);
        const ExportFrame& frame = w->frame;
        const EncodedFrame* e = w->encoded.get();
        if (w->over_budget) {
            result->over_budget = true;
            *error = scene.path + ": frame " + std::to_string(frame.index) + ": tolerance " +
                     formatNumber(scene.tolerance) + " makes more than " + std::to_string(settings.max_frame_triangles) +
                     " triangles (--max-triangles); use a coarser --tolerance or raise --max-triangles";
            stop = true;
            return;
        }
        result->max_triangles = std::max(result->max_triangles, e ? size_t(e->triangles) : frame.triangleCount());
        if (e)
            result->limited_triangles += size_t(e->limited_triangles);
        else
            for (const auto& o : frame.objects) result->limited_triangles += o.limited_triangles;
        for (size_t s = 0; s < sinks.size(); ++s) {
            // Refused before writing beyond the limit; every completed file counted after.
            const PendingOutput pending = e ? sinks[s]->pendingEncoded(frame.index, e->sinks[s]) : sinks[s]->pending(frame);
            std::vector<std::string> completed;
            bool done = budget->fits(pending.bytes, pending.name, error) &&
                        (e ? sinks[s]->addEncoded(frame.index, e->sinks[s], &completed, error)
                           : sinks[s]->add(frame, w->prepared[s].get(), &completed, error));
            for (size_t c = 0; done && c < completed.size(); ++c) done = budget->count(completed[c], error);
            if (!done) {
                stop = true;
                return;
            }
        }
        if (w->received) ++result->frames_received;
        progress.update(++delivered);
    };
    // Before the first file appears: the output size estimated from the first kEstimateFrames
    // frames, scaled to the whole run. When every sink can hold its commits (FrameSink::
    // canHoldCommits) and the frames are this process's own, those frames are taken as they come,
    // their files left under temporary names until the estimate fits, so that none waits whole in
    // memory and each reuses the buffers of the one before; otherwise they are held back whole
    // until then. A frame past --max-triangles is reported by deliverOne instead.
    constexpr size_t kEstimateFrames = 4;
    struct Held {
        WorkPtr work;  // held back whole; null: taken, its commits held
        long long index = 0;
        double estimate = 0;
        std::vector<PendingOutput> pending;  // per sink, as pending() said before add()
    };
    std::vector<Held> held;
    bool estimated = false;
    const bool hold_commits = !settings.distributed && std::all_of(sinks.begin(), sinks.end(), [](const FrameSink* s) {
                                  return s->canHoldCommits();
                              });
    struct EndHolding {
        const std::vector<FrameSink*>& sinks;
        bool on;
        ~EndHolding() {
            for (FrameSink* s : sinks)
                if (on) s->holdCommits(false);  // what was never committed goes
        }
    } end_holding{sinks, hold_commits};
    for (FrameSink* s : sinks)
        if (hold_commits) s->holdCommits(true);
    // A frame taken with its commits held: add() now, the budget's checks at commitOne().
    auto takeOne = [&](const WorkPtr& w, Held* h) {
        const WriteTime timed(result);
        const ExportFrame& frame = w->frame;
        result->max_triangles = std::max(result->max_triangles, frame.triangleCount());
        for (const auto& o : frame.objects) result->limited_triangles += o.limited_triangles;
        for (size_t s = 0; s < sinks.size(); ++s) {
            std::vector<std::string> none;  // holding: nothing completes
            h->pending.push_back(sinks[s]->pending(frame));
            if (!sinks[s]->add(frame, w->prepared[s].get(), &none, error)) {
                stop = true;
                return;
            }
        }
    };
    auto commitOne = [&](const Held& h) {
        if (stop) return;
        const WriteTime timed(result);
        for (size_t s = 0; s < sinks.size(); ++s) {
            std::vector<std::string> completed;
            bool done = budget->fits(h.pending[s].bytes, h.pending[s].name, error) &&
                        sinks[s]->commitHeld(h.index, &completed, error);
            for (size_t c = 0; done && c < completed.size(); ++c) done = budget->count(completed[c], error);
            if (!done) {
                stop = true;
                return;
            }
        }
        progress.update(++delivered);
    };
    auto deliver = [&](WorkPtr w) {
        if (stop) return;
        // A frame past the budget ends the run at once (nothing held is written).
        if (estimated || w->over_budget) return deliverOne(w);
        Held& h = held.emplace_back();
        h.index = w->frame.index;
        for (size_t s = 0; s < sinks.size(); ++s)
            h.estimate += double(w->encoded ? w->encoded->sinks[s].estimate : sinks[s]->estimate(w->frame));
        if (hold_commits && !w->encoded) takeOne(w, &h);
        else h.work = std::move(w);
        if (stop) return;
        if (held.size() < kEstimateFrames && held.size() < size_t(delivered_total)) return;
        estimated = true;
        double bytes = 0;
        for (const Held& k : held) bytes += k.estimate;
        const double whole = bytes / double(held.size()) * double(delivered_total) * double(settings.models_left);
        if (!budget->fitsEstimate(whole, (long long)held.size(), delivered_total, error)) {
            stop = true;
            return;
        }
        for (const Held& k : held) k.work ? deliverOne(k.work) : commitOne(k);
        held.clear();
        for (FrameSink* s : sinks)
            if (hold_commits) s->holdCommits(false);
    };
    // MPI rank 0: the frames of other ranks before frame `until`, received in order and delivered.
    long long remote_next = first;
    auto receiveUpTo = [&](long long until) {
        for (; !stop && remote_next < until; ++remote_next) {
            const int from = FrameSplit{0, group.size()}.partOf(remote_next, first);
            if (from == 0) continue;
            std::vector<std::string> parts;
            auto w = std::make_shared<Work>();
            w->encoded = std::make_unique<EncodedFrame>();
            const Clock::time_point wait_start = Clock::now();
            group.awaitFrame(from);
            result->wait_seconds += since(wait_start);
            // Receiving and unpacking the frame that came are rank 0's work on it: counted with its writing.
            bool unpacked = false;
            {
                const WriteTime timed(result, true);
                unpacked = group.receiveParts(from, &parts, &failed_code, error) &&
                           frameFromParts(&parts, w->encoded.get(), error);
            }
            if (!unpacked) {
                if (!failed_code) failed_code = 1;
                stop = true;
                return;
            }
            if (w->encoded->index != remote_next || w->encoded->sinks.size() != (w->encoded->over_budget ? 0 : sinks.size())) {
                *error = "internal: rank " + std::to_string(from) + " sent frame " + std::to_string(w->encoded->index) +
                         " where frame " + std::to_string(remote_next) + " was due";
                failed_code = 1;
                stop = true;
                return;
            }
            w->frame.index = remote_next;
            w->received = true;
            w->over_budget = w->encoded->over_budget;
            deliver(std::move(w));
        }
    };
    // The in-order stage: deliver (rank 0: after the frames of other ranks before it), or send.
    auto inOrder = [&](WorkPtr w) {
        if (sender) {
            if (stop || (stop = group.stopRequested())) return;
            for (size_t s = 0; s < w->encoded->sinks.size(); ++s)
                sinks[s]->beforeSending(w->frame.index, &w->encoded->sinks[s]);
            const std::string header = frameHeader(*w->encoded);
            group.sendParts(frameParts(*w->encoded, header));
            return;
        }
        if (receiver) {
            receiveUpTo(w->frame.index);
            remote_next = w->frame.index + 1;
        }
        deliver(std::move(w));
    };
    auto run = [&] {
        // Where the time went (FrameLoopResult), whichever way the loop ends.
        struct Account {
            FrameLoopResult* r;
            const std::atomic<long long>& cut;
            const std::atomic<long long>& cut_cpu;
            const long long& written;
            Clock::time_point start;
            ~Account() {
                r->cut_seconds = double(cut) * 1e-9;
                r->cut_cpu_seconds = double(cut_cpu) * 1e-9;
                r->frames_written = written;
                r->loop_seconds = std::chrono::duration<double>(Clock::now() - start).count();
            }
        } account{result, cut_ns, cut_cpu_ns, delivered, loop_start};
        arena.execute([&] {
            tbb::parallel_pipeline(tokens, tbb::make_filter<void, WorkPtr>(tbb::filter_mode::serial_in_order, source) &
                                               tbb::make_filter<WorkPtr, WorkPtr>(tbb::filter_mode::parallel, cutFrame) &
                                               tbb::make_filter<WorkPtr, void>(tbb::filter_mode::serial_in_order, inOrder));
        });
        if (receiver) receiveUpTo(last_excl);
    };
    if (sender) {
        // A failure here goes to rank 0 as this rank's ERROR; every rank then leaves with rank 0's code.
        try {
            run();
        } catch (const std::bad_alloc&) {
            group.sendError(kExitOutputError, "out of memory on rank " + std::to_string(group.rank()) +
                                                  " (try a coarser --tolerance, fewer frames or more ranks)");
        } catch (const std::exception& e) {
            group.sendError(1, std::string("internal: rank ") + std::to_string(group.rank()) + ": " + e.what());
        }
        result->group_code = group.finishSending();
        return result->group_code == 0;
    }
    // Rank 0 with MPI: tell the other ranks how this loop ended (after the sinks are done).
    auto fail = [&](int code) {
        if (receiver) {
            group.endFrames(code);
            for (FrameSink* sink : sinks) sink->dropEncoded(first, last_excl);
        }
        result->group_code = code;
        return false;
    };
    run();
    if (stop) return fail(failed_code ? failed_code : result->over_budget ? kExitBadInput : kExitOutputError);

    // Step: what needs the whole sequence (the .glb is assembled here).
    const Clock::time_point finish_start = Clock::now();
    const double finish_cpu = threadCpuSeconds();
    result->summaries.assign(sinks.size(), {});
    for (size_t s = 0; s < sinks.size(); ++s) {
        sinks[s]->setFinishCheck([budget](long long bytes, const std::string& name, std::string* e) {
            return budget->fits(bytes, name, e);
        });
        if (!sinks[s]->finish(&result->summaries[s], error)) return fail(kExitOutputError);
        for (const std::string& path : result->summaries[s].completed)
            if (!budget->count(path, error)) return fail(kExitOutputError);
    }
    result->finish_seconds = since(finish_start);
    result->finish_cpu_seconds = threadCpuSeconds() - finish_cpu;
    result->write_seconds += result->finish_seconds;
    result->write_cpu_seconds += result->finish_cpu_seconds;
    result->loop_seconds = since(loop_start);
    if (receiver) group.endFrames(0);
    return true;
}

}  // namespace

bool runFrameLoop(const Stage& stage, Model model, const FrameLoopSettings& settings,
                  const std::vector<FrameSink*>& sinks, OutputBudget* budget, std::ostream& progress_out,
                  FrameLoopResult* result, std::string* error) {
    return runLoop(stage, nullptr, model, settings, sinks, budget, progress_out, result, error);
}

bool runLastFrameLoop(Stage* stage, Model model, const FrameLoopSettings& settings,
                      const std::vector<FrameSink*>& sinks, OutputBudget* budget, std::ostream& progress_out,
                      FrameLoopResult* result, std::string* error) {
    return runLoop(*stage, &stage->objects, model, settings, sinks, budget, progress_out, result, error);
}

}  // namespace apparent
