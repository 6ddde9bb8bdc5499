// The WebAssembly module (issue 36; docs/WEB.md "The cut in WebAssembly"): a scene file in the
// module's file system loaded with the commands' own stage (pipeline/stage/stage.h), cut at any
// camera time with the frame loop's own step (pipeline/stage/frame_cut.h), and the frame returned as
// typed arrays or as the native program's PLY bytes (exporters/ply.h). Built by scripts/build_web.sh
// with Emscripten from the same sources as the native program (APPARENT_NO_TBB, APPARENT_NO_LANES,
// APPARENT_NO_DRACO, APPARENT_NO_OPENMESH: glTF scenes and meshes only). Bad input: `error()` holds
// the command line's one line and nothing else is set.
#include <emscripten/bind.h>
#include <emscripten/val.h>

#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "exporters/ply.h"
#include "pipeline/input/scene_fields.h"
#include "pipeline/stage/frame_cut.h"
#include "pipeline/stage/stage.h"

namespace {

using emscripten::val;

// A vector's bytes as a new JavaScript typed array (a copy: the module's memory may grow).
template <class T>
val copyOut(const std::vector<T>& v) {
    return val::global(std::is_same<T, double>::value     ? "Float64Array"
                       : std::is_same<T, float>::value    ? "Float32Array"
                       : std::is_same<T, uint32_t>::value ? "Uint32Array"
                                                          : "Uint8Array")
        .new_(emscripten::typed_memory_view(v.size(), v.data()));
}

// The stage of one (model, tolerance) and its cutter, built once and shared by every cut.
struct Cutting {
    apparent::Stage stage;
    std::unique_ptr<apparent::FrameCutter> cutter;
};

// One cut frame: per object, its arrays; the whole frame as the native PLY.
class Frame {
public:
    Frame() = default;
    Frame(apparent::ExportFrame frame, std::shared_ptr<const Cutting> cutting)
        : frame_(std::move(frame)), cutting_(std::move(cutting)) {}
    explicit Frame(std::string error) : error_(std::move(error)) {}

    std::string error() const { return error_; }
    double cameraTime() const { return frame_.t_c; }
    size_t objectCount() const { return frame_.objects.size(); }
    std::string objectName(size_t o) const {
        const auto& objects = cutting_->cutter->info().objects;
        return o < objects.size() ? objects[o].name : "";
    }
    // Absolute lab positions (x y z per vertex, light-seconds) and emission times, as the PLY's.
    val positions(size_t o) const {
        std::vector<double> p;
        const auto& part = frame_.objects.at(o);
        for (size_t i = 0; i < part.positions.size(); ++i) {
            const mesh4d::Vec3 q = part.absolutePosition(i);
            p.insert(p.end(), {q.x, q.y, q.z});
        }
        return copyOut(p);
    }
    // float32 relative to the object's local origin (origin()), as the .glb carries them.
    val localPositions(size_t o) const {
        std::vector<float> p;
        for (const mesh4d::Vec3& q : frame_.objects.at(o).positions) p.insert(p.end(), {float(q.x), float(q.y), float(q.z)});
        return copyOut(p);
    }
    val origin(size_t o) const {
        const mesh4d::Vec3 c = frame_.objects.at(o).origin;
        return copyOut(std::vector<double>{c.x, c.y, c.z});
    }
    val emissionTimes(size_t o) const {
        std::vector<double> t;
        const auto& part = frame_.objects.at(o);
        for (size_t i = 0; i < part.positions.size(); ++i) t.push_back(part.absoluteTime(i));
        return copyOut(t);
    }
    val doppler(size_t o) const { return copyOut(frame_.objects.at(o).doppler); }
    val properTime(size_t o) const { return copyOut(frame_.objects.at(o).proper_time); }
    // Triangles as the PLY writes them: those with a repeated corner left out.
    val indices(size_t o) const {
        std::vector<uint32_t> ix;
        for (const auto& t : frame_.objects.at(o).triangles)
            if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) ix.insert(ix.end(), {t[0], t[1], t[2]});
        return copyOut(ix);
    }
    // The native program's PLY file of this frame, byte for byte (exporters/ply.h).
    val ply() const {
        std::string bytes;
        apparent::serializePly(frame_, cutting_->cutter->info(), &bytes);
        return val::global("Uint8Array").new_(emscripten::typed_memory_view(bytes.size(), reinterpret_cast<const uint8_t*>(bytes.data())));
    }

private:
    apparent::ExportFrame frame_;
    std::shared_ptr<const Cutting> cutting_;  // its sequence's names and looks
    std::string error_;
};

// A scene file (a path in the module's file system) and, per (model, tolerance), its stage and cutter.
class Scene {
public:
    explicit Scene(std::string path) {
        base_.scene_path = std::move(path);
        base_.quiet = true;
        default_ = get("", "");
        if (!default_) error_ = last_error_;
    }
    std::string error() const { return error_; }
    std::string defaultModel() const { return default_ ? apparent::modelName(default_->stage.scene.model) : ""; }
    // The camera time of the scene's frame k (pipeline/input/scene.h frameTime).
    double frameTime(double k) const {
        return default_ ? apparent::frameTime(default_->stage.scene.frames, (long long)k) : 0;
    }
    double frameCount() const {
        return default_ ? double(apparent::frameCount(default_->stage.scene.frames)) : 0;
    }
    // The frame at camera time t in `model` ("": the scene's) at `tolerance` ("": the scene's; as
    // --tolerance: light-seconds, a fraction such as 1e-3x, or "vertex").
    Frame cut(double t, const std::string& model, const std::string& tolerance) {
        std::shared_ptr<const Cutting> c = get(model, tolerance);
        if (!c) return Frame(last_error_);
        apparent::ExportFrame frame;
        std::string error;
        if (!c->cutter->cut(t, 0, &frame, &error)) return Frame(error);
        return Frame(std::move(frame), c);
    }

private:
    // The command line's checks and messages (python/_apparent.cpp does the same for Python).
    std::shared_ptr<Cutting> get(const std::string& model, const std::string& tolerance) {
        const std::string key = model + "|" + tolerance;
        if (auto found = cache_.find(key); found != cache_.end()) return found->second;
        apparent::StageOptions options = base_;
        if (!model.empty()) {
            apparent::Model m;
            if (!apparent::parseModel(model, &m)) {
                last_error_ = "--model: unknown model '" + model + "' (instant, finite, relativistic, contracted)";
                return nullptr;
            }
            options.models = {m};
        }
        if (!tolerance.empty()) {
            if (!apparent::parseTolerance(tolerance, &options.tolerance, &options.tolerance_relative)) {
                last_error_ = "--tolerance: '" + tolerance +
                              "' is neither a positive number of light-seconds, a fraction of each object's size such "
                              "as 1e-3x, nor 'vertex'";
                return nullptr;
            }
            options.has_tolerance = true;
        }
        auto c = std::make_shared<Cutting>();
        std::ostringstream log;
        if (!apparent::loadStage(options, &c->stage, log, &last_error_)) return nullptr;
        c->cutter = std::make_unique<apparent::FrameCutter>(c->stage, c->stage.models.front());
        return cache_[key] = std::move(c);
    }

    apparent::StageOptions base_;
    std::map<std::string, std::shared_ptr<Cutting>> cache_;
    std::shared_ptr<Cutting> default_;  // the scene's own model and tolerance
    std::string error_, last_error_;
};

}  // namespace

EMSCRIPTEN_BINDINGS(apparent_web) {
    using namespace emscripten;
    class_<Frame>("Frame")
        .function("error", &Frame::error)
        .function("cameraTime", &Frame::cameraTime)
        .function("objectCount", &Frame::objectCount)
        .function("objectName", &Frame::objectName)
        .function("positions", &Frame::positions)
        .function("localPositions", &Frame::localPositions)
        .function("origin", &Frame::origin)
        .function("emissionTimes", &Frame::emissionTimes)
        .function("doppler", &Frame::doppler)
        .function("properTime", &Frame::properTime)
        .function("indices", &Frame::indices)
        .function("ply", &Frame::ply);
    class_<Scene>("Scene")
        .constructor<std::string>()
        .function("error", &Scene::error)
        .function("defaultModel", &Scene::defaultModel)
        .function("frameTime", &Scene::frameTime)
        .function("frameCount", &Scene::frameCount)
        .function("cut", &Scene::cut);
}
