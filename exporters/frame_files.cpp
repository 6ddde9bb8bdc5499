#include "exporters/frame_files.h"

#include "exporters/atomic_file.h"

#include <filesystem>
#include <system_error>
#include <utility>

namespace apparent {

mesh4d::ApparentMesh mergeObjects(const ExportFrame& frame) {
    mesh4d::ApparentMesh all;  // absolute lab positions and times (origin 0)
    for (const auto& part : frame.objects) {
        const uint32_t base = uint32_t(all.positions.size());
        for (size_t i = 0; i < part.positions.size(); ++i) {
            all.positions.push_back(part.absolutePosition(i));
            all.emission_times.push_back(part.absoluteTime(i));
        }
        for (const auto& t : part.triangles) all.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
        all.rest_points.insert(all.rest_points.end(), part.rest_points.begin(), part.rest_points.end());
        all.clipped_triangles += part.clipped_triangles;
    }
    return all;
}

long long leastFrameBytes(const ExportFrame& frame) {
    size_t vertices = 0;
    for (const auto& o : frame.objects) vertices += o.positions.size();
    return 12 * (long long)vertices + 12 * (long long)frame.triangleCount();
}

EncodedOutput FrameSink::encode(const ExportFrame&, const PreparedFrame*) const { return {}; }

PendingOutput FrameSink::pendingEncoded(long long index, const EncodedOutput& frame) {
    return {frame.least, "frame " + std::to_string(index)};
}

bool FrameSink::addEncoded(long long index, const EncodedOutput&, std::vector<std::string>*, std::string* error) {
    *error = "frame " + std::to_string(index) + ": this output cannot take frames from another process";
    return false;
}

FrameFileSink::FrameFileSink(std::string dir, std::string extension, FrameWriter write, FrameSerializer serialize)
    : dir_(std::move(dir)), extension_(std::move(extension)), write_(write), serialize_(serialize) {}

std::string FrameFileSink::path(long long k) const {
    return (std::filesystem::path(dir_) / (frameName(k) + "." + extension_)).string();
}

bool FrameFileSink::begin(const SequenceInfo&, std::string* error) {
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) *error = dir_ + ": cannot create output folder: " + ec.message();
    return !ec;
}

PendingOutput FrameFileSink::pending(const ExportFrame& frame) { return {leastFrameBytes(frame), path(frame.index)}; }

bool FrameFileSink::add(const ExportFrame& frame, const PreparedFrame*, std::vector<std::string>* completed,
                        std::string* error) {
    const std::string p = path(frame.index);
    if (!write_(p, frame, error)) return false;
    completed->push_back(p);
    return true;
}

bool FrameFileSink::finish(SinkSummary*, std::string*) { return true; }

EncodedOutput FrameFileSink::encode(const ExportFrame& frame, const PreparedFrame*) const {
    EncodedOutput e;
    e.least = e.estimate = leastFrameBytes(frame);
    serialize_(frame, &e.bytes);
    return e;
}

PendingOutput FrameFileSink::pendingEncoded(long long index, const EncodedOutput& frame) {
    return {frame.least, path(index)};
}

bool FrameFileSink::addEncoded(long long index, const EncodedOutput& frame, std::vector<std::string>* completed,
                               std::string* error) {
    const std::string p = path(index);
    AtomicOutput out(p);
    if (!out.commitBytes(frame.bytes, error)) return false;
    completed->push_back(p);
    return true;
}

}  // namespace apparent
