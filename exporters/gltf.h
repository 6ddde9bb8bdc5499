// One animated binary glTF (.glb) per model, holding every frame of the sequence.
//
// Layout (glTF 2.0):
// - node 0 "camera": a perspective camera placed and aimed like the scene camera;
// - node 1 + k "frame_NNNNN": mesh k, frame k, one primitive per visible object with that
//   object's material; its translation is the frame's local origin (the centre of its bounding
//   box, as JSON doubles) and POSITION is float32 relative to it, so scenes far from the world
//   origin keep their precision. Each primitive has NORMAL (area-weighted) and a float
//   _EMISSION_TIME (the lab time the light left the point). A frame with nothing visible gets a
//   node without a mesh (glTF forbids empty accessors).
// - reflections (ExportObject::mirror set) are their own nodes: a child "frame_NNNNN mirror M" of
//   frame node k per mirror M showing something in frame k, with one primitive per reflected
//   object, relative to the same origin (no transform of their own; the frame's animation shows
//   and hides them with it) and extras {"mirror": M}. They come after all frame nodes.
// - one animation "frames" of STEP scale channels: node k is visible (scale 1) during
//   [k/fps, (k+1)/fps) and hidden (scale 0) otherwise; the last frame stays visible at the final
//   key n/fps, which closes the sequence (docs/DEPENDENCIES.md section 4).
// - scene extras: model, tolerance, units, fps, first_frame, frame_times, objects, scene_file.
// With Draco (KHR_draco_mesh_compression, required), every primitive's attributes and indices
// are Edgebreaker-coded; POSITION is quantized to `position_bits` over the primitive's largest
// extent, NORMAL to `normal_bits`, and _EMISSION_TIME kept lossless. Accessor counts and bounds
// are taken from the decoded Draco mesh, because Draco drops degenerate faces and reorders points.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "exporters/frame_sink.h"

namespace apparent {

struct GlbOptions {
    bool draco = false;
    int position_bits = 14;  // Draco position quantization, 1..30
    int normal_bits = 10;    // Draco normal quantization, 1..30
};

struct GlbStats {
    size_t bytes = 0;                 // size of the written file
    size_t bytes_without_draco = 0;   // with Draco: size of the same file without it (0 otherwise)
    double max_float_error = 0;       // largest |float32 - double| over exported positions, light-seconds
    double max_quantization_error = 0;  // Draco: largest position quantization error bound, light-seconds
    double max_extent = 0;            // largest frame extent, light-seconds (to judge the errors above)
};

// The .glb of a sequence written as frames arrive: each frame's binary data goes at once to a
// spill file in the output's folder that has no name (openAnonymousFile, atomic_file.h: nothing
// is left behind whatever ends the process), only the JSON-side
// description (a few hundred bytes per frame) stays in memory, and finish() assembles the file
// under a temporary name and renames it into place. Memory does not grow with the frame data;
// the disk briefly holds the binary data twice.
struct GlbFrameData;  // one frame converted for the file (GlbSequenceWriter::prepare)

class GlbSequenceWriter {
public:
    GlbSequenceWriter(const std::string& path, const SequenceInfo& info, const GlbOptions& options);
    ~GlbSequenceWriter();
    GlbSequenceWriter(const GlbSequenceWriter&) = delete;
    GlbSequenceWriter& operator=(const GlbSequenceWriter&) = delete;
    // Frames in order; false with a message naming the file on failure.
    bool add(const ExportFrame& frame, std::string* error);
    // The same in two steps: prepare() (crease split, normals, float32 conversion: the costly
    // part) may run on any thread and for several frames at once; add() then takes the frames in
    // order. The file is the same either way.
    std::shared_ptr<GlbFrameData> prepare(const ExportFrame& frame) const;  // shared: GlbFrameData is opaque here
    bool add(const ExportFrame& frame, const GlbFrameData& prepared, std::string* error);
    // Writes the file; a .glb cannot exceed 4 GiB (refused with a message). With `check`, the
    // file's whole size (JSON chunk included) is checked with it before anything is written.
    bool finish(GlbStats* stats, std::string* error, const FrameSink::OutputCheck& check = nullptr);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The .glb as a frame sink: one GlbSequenceWriter per sequence (begin() starts it), frames
// converted by prepare() on the loop's worker threads. finish() reports the file and its size
// (with Draco also the size without it); `verbose` adds the float32 and Draco position error
// bounds to the summary, and a warning says when Draco's bound exceeds the sequence's tolerance.
class GlbSink : public FrameSink {
public:
    GlbSink(std::string path, const GlbOptions& options, bool verbose);
    ~GlbSink() override;
    bool begin(const SequenceInfo& info, std::string* error) override;
    std::shared_ptr<const PreparedFrame> prepare(const ExportFrame& frame) const override;
    PendingOutput pending(const ExportFrame& frame) override;
    // Positions and indices (Draco's size is not known before encoding: 0).
    long long estimate(const ExportFrame& frame) const override { return options_.draco ? 0 : leastFrameBytes(frame); }
    bool add(const ExportFrame& frame, const PreparedFrame* prepared, std::vector<std::string>* completed,
             std::string* error) override;
    bool finish(SinkSummary* summary, std::string* error) override;
    void setFinishCheck(OutputCheck check) override { check_ = std::move(check); }

private:
    std::string path_;
    GlbOptions options_;
    bool verbose_;
    std::string model_;
    double tolerance_ = 0;
    OutputCheck check_;
    long long least_ = 0;  // least size of the file so far without Draco (positions and indices alone)
    std::unique_ptr<GlbSequenceWriter> writer_;
};

// All frames at once (the same file as GlbSequenceWriter fed `frames`).
bool writeAnimatedGlb(const std::string& path, const std::vector<ExportFrame>& frames, const SequenceInfo& info,
                      const GlbOptions& options, GlbStats* stats, std::string* error);

}  // namespace apparent
