#include "pipeline/commands/trade.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "exporters/atomic_file.h"
#include "exporters/gltf.h"
#include "mesh4d/box.h"
#include "mesh4d/motion/worldline.h"
#include "mesh4d/refine/measure.h"
#include "mesh4d/refine/subdivide.h"
#include "pipeline/commands/command.h"
#include "pipeline/run/frame_loop.h"
#include "pipeline/stage/physics.h"
#include "pipeline/stage/worlds.h"

namespace apparent {

namespace {

// Times are the calling thread's CPU time, not wall time: on a shared machine the wall clock also
// counts the time the thread waits for a core, which hits a long configuration more often than a
// short one and so skews the ratios between rows.
double threadSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// The bounding-box diagonal of a rest mesh.
double restSize(const mesh4d::RestMesh& m) {
    mesh4d::EventBox box;
    for (const auto& p : m.positions) box.addPoint(p);
    return m.positions.empty() ? 0.0 : box.diagonal();
}

std::string formatG(double x, int digits = 3) {
    std::ostringstream s;
    s << std::setprecision(digits) << x;
    return s.str();
}

// Measures one configuration: `objects` (already subdivided for the uniform family) at
// `tolerance` over `frames`.
TradeRow measure(const Stage& stage, const std::vector<PreparedObject>& objects, Model model,
                 const std::vector<long long>& frames, double tolerance, long long max_triangles,
                 const std::string& glb_path, bool* too_large) {
    const Scene& scene = stage.scene;
    TradeRow row;
    const long long first = frames.front(), last = frames.back();
    std::vector<mesh4d::World4D> worlds;
    worlds.reserve(objects.size());
    for (const auto& o : objects) worlds.push_back(buildWorld(o, model, scene, first, last));
    mesh4d::SliceSettings settings;  // as `apparent render` cuts (frame_loop.cpp)
    settings.tolerance = tolerance;
    std::vector<ExportFrame> exported;
    double seconds = 0, triangles = 0;
    *too_large = false;
    for (long long k : frames) {
        const mesh4d::ViewSurface view = viewForFrame(scene, model, k);
        ExportFrame frame;
        frame.index = k;
        frame.t_c = frameTime(scene.frames, k);
        // Timed over repeats until at least 2 ms, so that small frames are measured above the clock's grain.
        int repeats = 0;
        double spent = 0;
        do {
            frame.objects.clear();
            const double t0 = threadSeconds();
            for (const auto& w : worlds) frame.objects.push_back(mesh4d::sliceWorld(w, view, settings));
            spent += threadSeconds() - t0;
            ++repeats;
        } while (spent < 2e-3 && repeats < 1000);
        seconds += spent / repeats;
        const size_t n = frame.triangleCount();
        triangles += double(n);
        if ((long long)n > max_triangles) {
            *too_large = true;
            return row;
        }
        for (size_t i = 0; i < worlds.size(); ++i) {
            row.error = std::max(row.error, mesh4d::measure::twoSided(worlds[i], view, frame.objects[i]));
            row.geometric_error =
                std::max(row.geometric_error, mesh4d::measure::geometricTwoSided(worlds[i], view, frame.objects[i]));
        }
        exported.push_back(std::move(frame));
    }
    // The .glb of these frames, written by the real writer (its size is what a viewer downloads).
    SequenceInfo info = sequenceInfo(stage, model);
    info.tolerance = tolerance;
    // Export time: the per-frame conversion (crease split, normals, float32: GlbSequenceWriter::prepare),
    // timed like the cut; the file's fixed costs (open, sync, rename) are left out.
    GlbSequenceWriter writer(glb_path, info, GlbOptions{});
    std::string error;
    bool ok = true;
    for (const ExportFrame& frame : exported) {
        int repeats = 0;
        double spent = 0;
        std::shared_ptr<GlbFrameData> prepared;
        do {
            const double t0 = threadSeconds();
            prepared = writer.prepare(frame);
            spent += threadSeconds() - t0;
            ++repeats;
        } while (spent < 2e-3 && repeats < 1000);
        row.export_seconds += spent / repeats / double(frames.size());
        ok = ok && writer.add(frame, *prepared, &error);
    }
    GlbStats stats;
    if (ok && writer.finish(&stats, &error)) row.glb_bytes = double(stats.bytes) / double(frames.size());
    std::error_code ec;
    std::filesystem::remove(glb_path, ec);
    row.seconds = seconds / double(frames.size());
    row.triangles = triangles / double(frames.size());
    return row;
}

// A whole file written under a temporary name and renamed into place (exporters/atomic_file.h).
bool writeFile(const std::string& path, const std::string& bytes, std::ostream& err) {
    AtomicOutput file(path);
    std::string error;
    if (file.fd() < 0) error = file.openError();
    else if (file.commitBytes(bytes, &error)) return true;
    err << "error: " << error << "\n";
    return false;
}

// Writes DIR/trade.dat and DIR/trade.gp and runs gnuplot on them, when gnuplot is installed.
bool plot(const std::string& dir, const std::vector<TradeRow>& rows, double size, std::ostream& err) {
    const std::string dat = dir + "/trade.dat", gp = dir + "/trade.gp", png = dir + "/trade.png";
    {
        std::ostringstream d;
        for (const char* family : {"vertex", "uniform", "tolerance"}) {
            d << "# " << family << "\n";
            for (const auto& r : rows)
                if (r.family == family && !r.skipped) d << r.total() * 1e3 << " " << r.error / size << "\n";
            d << "\n\n";
        }
        if (!writeFile(dat, d.str(), err)) return false;
    }
    {
        std::ostringstream g;
        g << "set terminal pngcairo size 900,560 font ',11' noenhanced\n"
          << "set output 'trade.png'\n"
          << "set logscale xy\n"
          << "set xlabel 'time per frame, cut and .glb export, one thread (milliseconds)'\n"
          << "set ylabel 'measured two-sided error / largest object size'\n"
          << "set grid\nset key top right\n"
          << "set title 'apparent trade: error against time'\n"
          << "plot 'trade.dat' index 0 using 1:2 with points pt 7 ps 2 title 'vertex mode', \\\n"
          << "     'trade.dat' index 1 using 1:2 with linespoints lw 2 pt 5 title 'uniform subdivision (levels 1..k)', \\\n"
          << "     'trade.dat' index 2 using 1:2 with linespoints lw 2 pt 9 title '--tolerance T (adaptive)'\n";
        if (!writeFile(gp, g.str(), err)) return false;
    }
    const std::string cmd = "cd '" + dir + "' && gnuplot trade.gp 2>&1";
    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
        err << "note: gnuplot is not installed: " << png << " not drawn (" << gp << " draws it; Debian: gnuplot-nox)\n";
        return true;
    }
    if (std::system(cmd.c_str()) != 0) {
        err << "warning: gnuplot failed on " << gp << ": " << png << " not drawn\n";
    }
    return true;
}

}  // namespace

const TradeRow* cheapestWithin(const std::vector<TradeRow>& rows, double error) {
    const TradeRow* best = nullptr;
    for (const auto& r : rows)
        if (!r.skipped && r.error <= error && (!best || r.total() < best->total())) best = &r;
    return best;
}

int trade(const TradeSettings& settings, std::ostream& out, std::ostream& err) {
    // Step: the scene, its model and frames, and the objects' meshes (the stage every command loads).
    Stage stage;
    if (std::string error; !loadStage(settings.stage, &stage, err, &error)) {
        err << "error: " << error << "\n";
        return kExitBadInput;
    }
    if (stage.models.size() != 1) {
        err << "error: --model: trade measures one model at a time\n";
        return kExitBadInput;
    }
    const Model model = stage.models.front();
    const Scene& scene = stage.scene;
    // Motions beyond uniform (spin, rolling, acceleration, keyframed paths) take the tolerance
    // ladder only where `apparent render --tolerance` would (physics.h checkObjectMotion with a
    // tolerance: no real cap, no mirror).
    for (const auto& o : stage.objects)
        if (Status s = checkObjectMotion(o, model, scene, 1.0, stage.first, stage.last_excl - 1); !s.ok) {
            err << "error: " << s.message << " (`apparent trade` sweeps the tolerance)\n";
            return kExitBadInput;
        }
    const std::vector<long long> frames = sampledFrames(stage, settings.has_frames);
    const std::vector<PreparedObject>& objects = stage.objects;
    // Non-uniform: spinning, accelerated or keyframed (mesh4d/motion/motion.h).
    auto beyondUniform = [&](const ObjectSpec& s) { return !mesh4d::isUniform(motionOf(s, model)); };
    const bool any_beyond = std::any_of(objects.begin(), objects.end(), [&](const PreparedObject& o) { return beyondUniform(o.spec); });
    // The instant model cuts at one lab time, where every motion of worldline.h places the rest
    // mesh affinely (one object time s for all its points); the contracted model too for uniform
    // motion, but not for the others (s then varies over the body).
    // The orthographic camera's tilted hyperplane (physics.h viewAt) maps uniform motion, the
    // only motion it takes, affinely too.
    if (model == Model::Instant || (model == Model::Contracted && !any_beyond) || scene.camera.orthographic()) {
        out << "The " << modelName(model) << " model cuts the histories with a hyperplane: the map from the rest "
            << "mesh is affine, so vertex mode is exact (error 0) and no tolerance or subdivision changes it.\n";
        return kExitOk;
    }
    // The size tolerances are relative to: the largest moving object (objects at rest map affinely
    // and are never refined), or the largest object when none moves.
    double size = 0, size_any = 0;
    for (const auto& o : objects) {
        size_any = std::max(size_any, restSize(o.rest));
        if (mesh4d::norm(o.spec.velocity) > 0 || o.spec.speed != ObjectSpec::Speed::Velocity || beyondUniform(o.spec))
            size = std::max(size, restSize(o.rest));
    }
    if (size == 0) size = size_any;
    std::error_code ec;
    std::filesystem::create_directories(settings.out_dir, ec);
    if (ec) {
        err << "error: " << settings.out_dir << ": cannot create output folder: " << ec.message() << "\n";
        return kExitOutputError;
    }
    const std::string glb_tmp = settings.out_dir + "/.trade-" + std::to_string(getpid()) + ".glb";

    // Step: the three families.
    std::vector<TradeRow> rows;
    auto run = [&](const std::string& family, double parameter, const std::vector<PreparedObject>& objs, double tolerance) {
        bool too_large = false;
        TradeRow r = measure(stage, objs, model, frames, tolerance, settings.max_triangles, glb_tmp, &too_large);
        r.family = family;
        r.parameter = parameter;
        r.skipped = too_large;
        if (!settings.quiet)
            err << "trade: " << family << " " << formatG(parameter) << (too_large ? ": skipped (over --max-triangles)" : "")
                << "\n";
        rows.push_back(r);
        return !too_large;
    };
    run("vertex", 0, objects, 0);
    for (int level = 1; level <= settings.levels; ++level) {
        std::vector<PreparedObject> finer = objects;
        for (auto& o : finer) o.rest = mesh4d::subdivideUniform(o.rest, level);
        if (!run("uniform", level, finer, 0)) break;
    }
    std::vector<double> ladder = settings.tolerances_rel;
    if (ladder.empty()) ladder = {1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4};
    for (double rel : ladder)
        if (!run("tolerance", rel * size, objects, rel * size)) break;

    // Step: the table, the file and the plot.
    std::ostringstream table;
    table << "apparent trade: " << scene.path << ", model " << modelName(model) << ", " << frames.size()
          << " frames, largest moving object size " << formatG(size, 4) << " ls; one thread\n";
    table << std::left << std::setw(22) << "family" << std::right << std::setw(11) << "error (ls)" << std::setw(11)
          << "error/size" << std::setw(8) << "err/T" << std::setw(11) << "geometric" << std::setw(8) << "geo/T"
          << std::setw(11) << "triangles" << std::setw(10) << "cut ms"
          << std::setw(10) << "glb ms" << std::setw(10) << "total ms" << std::setw(12) << "glb B" << "   (per frame)\n";
    std::ostringstream csv;
    csv << "family,parameter,error_ls,error_rel,triangles_per_frame,cut_seconds_per_frame,export_seconds_per_frame,"
           "glb_bytes_per_frame,skipped,geometric_error_ls,geometric_error_rel\n";
    for (const auto& r : rows) {
        std::string name = r.family;
        if (r.family == "uniform") name += " level " + formatG(r.parameter);
        if (r.family == "tolerance") name = "T = " + formatG(r.parameter / size, 2) + " x size";
        csv << r.family << "," << std::setprecision(10) << r.parameter << "," << r.error << "," << r.error / size << ","
            << r.triangles << "," << r.seconds << "," << r.export_seconds << "," << r.glb_bytes << "," << (r.skipped ? 1 : 0)
            << "," << r.geometric_error << "," << r.geometric_error / size << "\n";
        table << std::left << std::setw(22) << name << std::right;
        if (r.skipped) {
            table << "  skipped: more than " << settings.max_triangles << " triangles per frame (--max-triangles)\n";
            continue;
        }
        table << std::setw(11) << formatG(r.error) << std::setw(11) << formatG(r.error / size) << std::setw(8)
              << (r.family == "tolerance" ? formatG(r.error / r.parameter, 2) : std::string("-")) << std::setw(11)
              << formatG(r.geometric_error) << std::setw(8)
              << (r.family == "tolerance" ? formatG(r.geometric_error / r.parameter, 2) : std::string("-")) << std::setw(11)
              << std::fixed << std::setprecision(0) << r.triangles << std::setprecision(3) << std::setw(10)
              << r.seconds * 1e3 << std::setw(10) << r.export_seconds * 1e3 << std::setw(10)
              << (r.seconds + r.export_seconds) * 1e3 << std::setw(12) << std::setprecision(0) << r.glb_bytes
              << std::defaultfloat << "\n";
    }
    table << "(error: parametric, each output point against the exact image of its own rest point; geometric: "
             "against the nearest point of the other surface, what --tolerance promises; mesh4d/refine/measure.h)\n";
    const double vertex_error = rows.front().error;
    auto pick = [&](double target, const char* what) {
        const TradeRow* best = nullptr;
        for (const auto& r : rows)
            if (r.family == "tolerance" && !r.skipped && r.error <= target && (!best || r.total() < best->total())) best = &r;
        const TradeRow* any = cheapestWithin(rows, target);
        table << "For " << what << " (" << formatG(target) << " ls): ";
        if (best) table << "--tolerance " << formatG(best->parameter, 4) << " (" << formatG(best->total() * 1e3) << " ms/frame)";
        else table << "no tolerance of the ladder";
        if (any && any != best)
            table << "; fastest of all rows: " << any->family << " " << formatG(any->parameter) << " ("
                  << formatG(any->total() * 1e3) << " ms/frame)";
        table << "\n";
    };
    if (vertex_error > 0) {
        pick(vertex_error, "vertex mode's error");
        pick(vertex_error / 10, "a tenth of it");
    } else {
        table << "Vertex mode is exact on these frames (error 0): nothing to trade.\n";
    }
    out << table.str();
    const std::string csv_path = settings.out_dir + "/trade.csv";
    if (!writeFile(csv_path, csv.str(), err) || !plot(settings.out_dir, rows, size, err)) return kExitOutputError;
    if (!settings.quiet) err << "wrote " << csv_path << " and " << settings.out_dir << "/trade.png\n";
    return kExitOk;
}


// ---- The command: `apparent trade` ----

namespace {

class TradeCommand : public Command {
public:
    CLI::App* add(CLI::App* app) override {
        cmd = app->add_subcommand(
            "trade", "Measure error against time and size on a scene: vertex mode, uniform subdivision, a ladder of tolerances");
        cmd->add_option("scene", trs.stage.scene_path, "Scene file (JSON or glTF)")->required();
        cmd->add_option("--out", trs.out_dir, "Folder for trade.csv, trade.png and trade.gp (created if missing)")
            ->capture_default_str();
        cmd->add_option("--model", trade_model_text, "finite|relativistic (default: the scene's model)");
        cmd->add_option("--frames", trade_frames_text, "A:B measures frames A..B-1 (default: 5 frames spread over the scene)");
        cmd->add_option("--levels", trs.levels, "Uniform subdivision levels 1..N to compare")->capture_default_str();
        cmd->add_option("--tolerances", trade_tolerances_text,
                        "Comma list of tolerances relative to the largest moving object's size (default 1e-1,3e-2,...,1e-4)");
        cmd->add_option("--max-triangles", trs.max_triangles, "Skip rows with more output triangles per frame")
            ->capture_default_str();
        cmd->add_flag("--quiet,-q", trs.quiet, "Only the table");
        addStageLimits(cmd, &trs.stage);
        cmd->footer(
            "Prints, for each row: the measured two-sided error to the exact apparent surface (sampled as the tests do),\n"
            "output triangles per frame, cut and .glb-conversion time per frame (one thread, its CPU time) and .glb bytes\n"
            "per frame; "
            "writes DIR/trade.csv and, with gnuplot, DIR/trade.png. Names the tolerance with the least time for vertex\n"
            "mode's error and for a tenth of it. Size: the largest moving object's bounding-box diagonal.");
        return cmd;
    }

    int run(std::ostream& out, std::ostream& err) override {
        if (std::string message; !parseModelList(trade_model_text, &trs.stage, &message)) return usageError(err, message);
        if (!trade_frames_text.empty() && !parseFrames(trade_frames_text, &trs.stage.frame_from, &trs.stage.frame_to))
            return usageError(err, "--frames: '" + trade_frames_text + "' is not A:B with 0 <= A < B");
        trs.has_frames = !trade_frames_text.empty();
        trs.stage.quiet = trs.quiet;
        if (trs.levels < 0 || trs.levels > 8) return usageError(err, "--levels: must be in 0..8");
        if (trs.max_triangles <= 0) return usageError(err, "--max-triangles: must be positive");
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
                return usageError(err, "--tolerances: '" + item + "' is not a positive number (a fraction of the object size)");
            trs.tolerances_rel.push_back(t);
        }
        return guarded([&] { return trade(trs, out, err); }, err);
    }

private:
    TradeSettings trs;
    std::string trade_model_text, trade_frames_text, trade_tolerances_text;
    CLI::App* cmd = nullptr;
};

}  // namespace

std::unique_ptr<Command> tradeCommand() { return std::make_unique<TradeCommand>(); }

}  // namespace apparent
