// The Python extension `apparent._apparent` (issue 34; docs/PYTHON.md): a scene loaded with the
// commands' own stage (pipeline/stage/stage.h), cut at any camera time with the frame loop's own step
// (pipeline/stage/frame_cut.h), and the `render` and `trade` commands run in-process
// (pipeline/commands/cli.h). Bad input raises apparent.Error with the command line's one line; the GIL is
// released while C++ works. The pure-Python layer (python/apparent/__init__.py) wraps these.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pipeline/commands/cli.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/stage.h"

namespace py = pybind11;

namespace {

using apparent::Model;

// Bad input: becomes apparent.Error (a ValueError) with the one line.
struct BadInput : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The stage of one (model, tolerance) and its cutter, built once and shared by every cut.
struct Cutting {
    apparent::Stage stage;
    std::unique_ptr<apparent::FrameCutter> cutter;
};

// One frame as flat arrays (converted to numpy with the GIL held).
struct FrameData {
    double camera_time = 0;
    std::string model;
    std::vector<std::string> object_names;  // objects, then mirror reflections
    std::vector<double> positions;          // N x 3, absolute lab positions, light-seconds
    std::vector<double> emission_time, doppler, proper_time;  // N
    std::vector<int32_t> object;            // N: index into object_names
    // N x 2 and N x 4: the input's TEXCOORD_0 and COLOR_0 at each point (exporters/surface_look.h);
    // NaN for the points of objects whose file has none.
    std::vector<double> texcoords, texcoords1, colors;
    std::vector<int64_t> triangles;         // M x 3
};

// The command's error line without "error: " (warnings may come before it).
std::string errorLine(const std::string& text) {
    std::istringstream lines(text);
    std::string line, last;
    while (std::getline(lines, line))
        if (line.rfind("error: ", 0) == 0) last = line.substr(7);
    return last.empty() ? text : last;
}

class SceneHandle {
public:
    SceneHandle(std::string path, bool allow_outside) {
        base_.scene_path = std::move(path);
        base_.limits.allow_outside = allow_outside;
        base_.quiet = true;
        py::gil_scoped_release release;
        default_ = get("", "");  // validates the scene in its own model and tolerance
        // Its mesh paths passed the confinement (pipeline/input/mesh_input.h) from the working folder of
        // now: later stages of other models and tolerances read the same files whatever it becomes.
        base_.limits.allow_outside = true;
    }

    std::vector<std::string> objects() const {
        std::vector<std::string> names;
        for (const auto& o : default_->stage.objects) names.push_back(o.spec.name);
        return names;
    }
    std::vector<double> frameTimes() const {
        std::vector<double> t;
        const auto& frames = default_->stage.scene.frames;
        for (long long k = 0, n = apparent::frameCount(frames); k < n; ++k) t.push_back(apparent::frameTime(frames, k));
        return t;
    }
    std::string defaultModel() const { return apparent::modelName(default_->stage.scene.model); }
    double defaultTolerance() const { return default_->stage.scene.tolerance; }
    std::string path() const { return base_.scene_path; }

    // The models the scene can be cut in (the stage accepts it for them).
    std::vector<std::string> models() {
        std::vector<std::string> ok;
        py::gil_scoped_release release;
        for (const char* name : {"instant", "finite", "relativistic", "contracted"}) {
            try {
                get(name, "");
                ok.push_back(name);
            } catch (const BadInput&) {
            }
        }
        return ok;
    }

    FrameData cut(double t, const std::string& model, const std::string& tolerance, long long max_triangles,
                  const std::string& attribute_tolerance) {
        FrameData data;
        {
            py::gil_scoped_release release;
            std::shared_ptr<Cutting> c = get(model, tolerance, attribute_tolerance);
            apparent::ExportFrame frame;
            std::string error;
            if (!c->cutter->cut(t, max_triangles, &frame, &error)) throw BadInput(error);
            fill(c->cutter->info(), frame, &data);
        }
        return data;
    }

private:
    // The cutting for `model` ("" : the scene's) at `tolerance` ("": the scene's; as --tolerance)
    // and `attribute_tolerance` ("": none; as --attribute-tolerance).
    std::shared_ptr<Cutting> get(const std::string& model, const std::string& tolerance,
                                 const std::string& attribute_tolerance = "") {
        const std::string key = model + "|" + tolerance + "|" + attribute_tolerance;
        std::lock_guard<std::mutex> lock(mutex_);
        auto found = cache_.find(key);
        if (found != cache_.end()) return found->second;
        apparent::StageOptions options = base_;
        if (!model.empty()) {
            Model m;
            if (!apparent::parseModel(model, &m))
                throw BadInput("--model: unknown model '" + model + "' (instant, finite, relativistic, contracted)");
            options.models = {m};
        }
        if (!tolerance.empty()) {
            // The command line's check and message (pipeline/commands/cli.cpp, --tolerance).
            if (!apparent::parseTolerance(tolerance, &options.tolerance, &options.tolerance_relative))
                throw BadInput("--tolerance: '" + tolerance +
                               "' is neither a positive number of light-seconds, a fraction of each object's size "
                               "such as 1e-3x, nor 'vertex'");
            options.has_tolerance = true;
        }
        if (!attribute_tolerance.empty() &&
            (!apparent::parseTolerance(attribute_tolerance, &options.attribute_tolerance, &options.attribute_tolerance_relative) ||
             (options.attribute_tolerance <= 0 && options.attribute_tolerance_relative <= 0)))
            throw BadInput("--attribute-tolerance: '" + attribute_tolerance +
                           "' is neither a positive number of light-seconds nor a fraction of each object's size such as 1e-3x");
        auto c = std::make_shared<Cutting>();
        std::ostringstream log;
        std::string error;
        if (!apparent::loadStage(options, &c->stage, log, &error)) throw BadInput(error);
        c->cutter = std::make_unique<apparent::FrameCutter>(c->stage, c->stage.models.front());
        cache_[key] = c;
        return c;
    }

    static void fill(const apparent::SequenceInfo& info, const apparent::ExportFrame& frame, FrameData* d) {
        d->camera_time = frame.t_c;
        d->model = info.model;
        for (const auto& o : info.objects) d->object_names.push_back(o.name);
        for (size_t k = 0; k < frame.objects.size(); ++k) {
            const mesh4d::ApparentMesh& part = frame.objects[k];
            const size_t base = d->object.size();
            for (size_t i = 0; i < part.positions.size(); ++i) {
                const mesh4d::Vec3 p = part.absolutePosition(i);
                d->positions.insert(d->positions.end(), {p.x, p.y, p.z});
                d->emission_time.push_back(part.absoluteTime(i));
                d->doppler.push_back(i < part.doppler.size() ? part.doppler[i] : NAN);
                d->proper_time.push_back(i < part.proper_time.size() ? part.proper_time[i] : NAN);
                d->object.push_back(int32_t(k));
            }
            // The object's look at each point, interpolated on its rest triangle.
            apparent::VertexLook at;
            const apparent::ExportObject* o = k < info.objects.size() ? &info.objects[k] : nullptr;
            if (o && o->look && o->rest) apparent::interpolateLook(*o->look, *o->rest, part, &at);
            for (auto [from, to, per] : {std::tuple{&at.texcoord, &d->texcoords, 2}, std::tuple{&at.texcoord1, &d->texcoords1, 2},
                                         std::tuple{&at.color, &d->colors, 4}}) {
                if (from->size() != size_t(per) * part.positions.size()) from->assign(size_t(per) * part.positions.size(), NAN);
                to->insert(to->end(), from->begin(), from->end());
            }
            // As the PLY: triangles with a repeated corner (zero area) are left out.
            for (const auto& t : part.triangles) {
                if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
                for (uint32_t v : t) d->triangles.push_back(int64_t(base + v));
            }
        }
    }

    apparent::StageOptions base_;
    std::mutex mutex_;
    std::map<std::string, std::shared_ptr<Cutting>> cache_;
    std::shared_ptr<Cutting> default_;
};

template <class T>
py::array_t<T> asArray(const std::vector<T>& v, py::ssize_t columns) {
    const py::ssize_t rows = py::ssize_t(v.size()) / columns;
    py::array_t<T> a(columns == 1 ? std::vector<py::ssize_t>{rows} : std::vector<py::ssize_t>{rows, columns});
    if (!v.empty()) std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

// Runs the command line in-process: the exit code, its standard output, and the error line.
py::tuple runCommand(const std::vector<std::string>& args) {
    std::ostringstream out, err;
    int code = 0;
    {
        py::gil_scoped_release release;
        std::vector<const char*> argv{"apparent"};
        for (const std::string& a : args) argv.push_back(a.c_str());
        code = apparent::runCommandLine(int(argv.size()), argv.data(), out, err);
    }
    return py::make_tuple(code, out.str(), errorLine(err.str()));
}

}  // namespace

PYBIND11_MODULE(_apparent, m) {
    m.doc() = "apparent's C++ core (see the package apparent for the documented interface)";
    m.attr("__version__") = APPARENT_VERSION;
    // Each cut's buffers reused by the next instead of faulted in again (docs/PYTHON.md).
    apparent::keepFreedMemory();
    static py::exception<BadInput> error(m, "Error", PyExc_ValueError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const BadInput& e) {
            error(e.what());
        }
    });

    py::class_<FrameData>(m, "FrameData")
        .def_readonly("camera_time", &FrameData::camera_time)
        .def_readonly("model", &FrameData::model)
        .def_readonly("object_names", &FrameData::object_names)
        .def_property_readonly("positions", [](const FrameData& d) { return asArray(d.positions, 3); })
        .def_property_readonly("triangles", [](const FrameData& d) { return asArray(d.triangles, 3); })
        .def_property_readonly("object", [](const FrameData& d) { return asArray(d.object, 1); })
        .def_property_readonly("emission_time", [](const FrameData& d) { return asArray(d.emission_time, 1); })
        .def_property_readonly("doppler", [](const FrameData& d) { return asArray(d.doppler, 1); })
        .def_property_readonly("proper_time", [](const FrameData& d) { return asArray(d.proper_time, 1); })
        .def_property_readonly("texcoords", [](const FrameData& d) { return asArray(d.texcoords, 2); })
        .def_property_readonly("texcoords1", [](const FrameData& d) { return asArray(d.texcoords1, 2); })
        .def_property_readonly("colors", [](const FrameData& d) { return asArray(d.colors, 4); });

    py::class_<SceneHandle>(m, "SceneHandle")
        .def(py::init<std::string, bool>(), py::arg("path"), py::arg("allow_outside") = false)
        .def_property_readonly("path", &SceneHandle::path)
        .def_property_readonly("objects", &SceneHandle::objects)
        .def_property_readonly("frame_times", [](const SceneHandle& s) { return asArray(s.frameTimes(), 1); })
        .def_property_readonly("default_model", &SceneHandle::defaultModel)
        .def_property_readonly("default_tolerance", &SceneHandle::defaultTolerance)
        .def("models", &SceneHandle::models)
        .def("cut", &SceneHandle::cut, py::arg("t"), py::arg("model"), py::arg("tolerance"), py::arg("max_triangles"),
             py::arg("attribute_tolerance") = "");

    m.def("run_command", &runCommand, py::arg("args"),
          "Runs `apparent ARGS...` in-process: (exit code, standard output, error line).");
}
