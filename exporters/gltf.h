// One animated binary glTF (.glb) per model, holding every frame of the sequence.
//
// Layout (glTF 2.0):
// - node 0 "camera": a perspective camera placed and aimed like the scene camera (orthographic,
//   xmag half its width, for camera.projection "orthographic");
// - node 1 + k "frame_NNNNN": mesh k (with meshopt the mesh of its run, see frame coherence
//   below), frame k, one primitive per visible object with that
//   object's material; its translation is the frame's local origin (the centre of its bounding
//   box, as JSON doubles) and POSITION is float32 relative to it, so scenes far from the world
//   origin keep their precision. Each primitive has NORMAL (area-weighted) and a float
//   _EMISSION_TIME (the lab time the light left the point); with --shade doppler also COLOR_0. A frame with nothing visible gets a
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
// An object whose look the file carries (surface_look.h) is one Draco mesh per material part
// (each part's triangles and the vertices they use, as glTF-Transform splits a mesh), each its own
// primitive with that material: TEXCOORD_0 as a TEX_COORD attribute quantized to `texcoord_bits`
// over the mesh's larger u or v range R (error at most R / (2 (2^bits - 1)) per coordinate, as for
// POSITION), COLOR_0 as COLOR, float RGB, lossless.
// With meshopt (EXT_meshopt_compression and KHR_mesh_quantization, both required; the BIN chunk
// holds the compressed streams, a fallback buffer without data stands for the decoded ones):
// a frame's vertices (all its primitives') are one interleaved stream of records, with the
// normals either in a stream of their own or at the end of each record (whichever encodes smaller,
// the extra view counted as 200 bytes of JSON: small frames keep them inline), and its indices one
// stream (the index view left out when every object shares the previous frame's). The record: POSITION as int16 (not
// normalized) multiples of the frame's step about the frame's origin (8 bytes with padding),
// _EMISSION_TIME float32 rounded to a multiple of the largest power of two not above the step
// (within step / 2 seconds of the plain file's, c = 1: its low mantissa bits compress), then with
// --attributes _DOPPLER and/or _PROPER_TIME as float32 (the plain file's values, bit for bit), and
// with --shade doppler COLOR_0 as normalized uint16 RGB (8 bytes with padding; within 0.5 / 65535
// of the plain file's float colour, clamped to [0, 1]); when the file carries an object's look
// (surface_look.h) the looks' COLOR_0 in that slot (unless --shade doppler) and TEXCOORD_0 as
// float32 (the plain file's values, bit for bit), one primitive per material sharing the frame's
// records, each with its part of the object's index list (each part vertex-cache ordered on its
// own; no morph targets). NORMAL in its own view goes through the
// OCTAHEDRAL filter at 8 bits (decoded to normalized int8; each component within 2.63 / 127 of
// the plain file's normal, derived in tests/web/meshopt_roundtrip.js); in the record it is
// normalized int8 x, y, z, 0 (within 0.5 / 127). Indices
// uint16 (uint32 past 65535 vertices), triangles in vertex-cache order and vertices in the order
// they first use them (meshopt_optimizeVertexCache, meshopt_optimizeVertexFetchRemap). The frame
// node's scale is its step (the animation shows it with scale = step, hides it with 0), so a
// reader gets origin + step * q. The step: with a tolerance T, T / sqrt(3), which bounds the
// quantization error by T / 2 (each coordinate moves at most step / 2); in vertex mode (no
// tolerance), at least 14 bits over the frame's largest extent E (Draco's and gltfpack's default):
// step = E / 16382 rounded down to a power of 2^(1/4) (at most 19% finer; so that frames of
// slightly different extents share it), error at most sqrt(3) / 2 * E / 16382 (about 5.3e-5 E);
// --meshopt-bits B
// asks for step = E / (2^B - 2) instead (a warning says when its bound exceeds T). When E / step
// would exceed int16 the step grows to E / 65534 and the warning says so too.
// Frame coherence (meshopt): consecutive frames that show the same objects with the same index
// lists, the same step and no reflections form a run: its first frame's mesh is written as above,
// and each later frame is a morph target of that mesh (glTF 2.0 morph targets with
// KHR_mesh_quantization) holding its difference from the frame before: POSITION int16 (not
// normalized) steps, NORMAL normalized int8 (from the previous frame's int8 normal as a reader
// decodes it), _EMISSION_TIME float32 (exact: the difference of two rounded times), one
// interleaved 16-byte record per vertex in one compressed view. Frame node k refers to its run's
// mesh with weights 1 for the run's first p targets and 0 for the rest (p: its place in the run;
// the first frame has none), so a reader gets its vertices exactly as if written alone: positions
// the same integers, emission times the same float32, normals within 0.5 / 127 per component
// (the run's first frame: the octahedral bound). A run ends at a frame that differs in any of
// these, whose differences do not fit (int16 steps, int8 normals, a time difference not exact in
// float32), after 63 targets, or when vertices x targets would pass 2^22 (three.js expands each
// target to 32 bytes a vertex of float texture: at most 128 MB). Not with --attributes or
// --shade doppler (their values stay bit for bit in each frame's own record). three.js, and so
// model-viewer, apply the weights; viewers that ignore _EMISSION_TIME in targets see the first
// frame's emission times.
// Index buffers are shared: a primitive whose index list (and vertex count) equals that of the
// same object in the previous frame refers to that frame's index accessor (plain and meshopt;
// Draco codes indices with the vertices). In vertex mode with nothing clipped, each object then
// has one index accessor for the whole sequence.
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
    // Draco TEXCOORD_0 quantization, 1..30 (an object whose look the file carries): over the larger
    // of the u and v ranges R of each Draco mesh, error at most R / (2 (2^bits - 1)) per coordinate.
    int texcoord_bits = 12;
    bool meshopt = false;    // EXT_meshopt_compression + KHR_mesh_quantization (not with draco)
    int meshopt_bits = 0;    // meshopt position bits 2..16 over each frame's extent; 0: step from the tolerance
    // --attributes: per-vertex float attributes _DOPPLER and _PROPER_TIME (mesh4d/light_factors.h),
    // plain, Draco (GENERIC, unquantized) or meshopt (float32 in the vertex record).
    bool doppler = false;
    bool proper_time = false;
    // --shade doppler: COLOR_0 (float VEC3, linear) per vertex, each object's base colour shifted
    // by the vertex's Doppler factor (mesh4d/doppler_colour.h); the materials' baseColorFactor is
    // then white (alpha kept) and the plain colour is in the material's extras "base_color".
    // Plain or Draco (COLOR, unquantized) as float; meshopt as normalized uint16 (see above).
    bool shade_doppler = false;
    // Set by the .glb writer from the sequence's objects (withMeshoptLooks), not by the command
    // line: with meshopt, the vertex record has slots for the looks' COLOR_0 and TEXCOORD_0
    // (an object whose look the file carries, surface_look.h), and for TEXCOORD_1 when such a
    // look has that set.
    bool meshopt_looks = false;
    bool meshopt_texcoord1 = false;
};

struct GlbStats {
    size_t bytes = 0;                 // size of the written file
    size_t bytes_without_draco = 0;   // with Draco or meshopt: size of the same file without it (0 otherwise)
    double max_float_error = 0;       // largest |float32 - double| over exported positions, light-seconds
    double max_quantization_error = 0;  // Draco, meshopt: largest position quantization error bound, light-seconds
    // Draco: largest TEXCOORD_0 or TEXCOORD_1 quantization error bound (texture coordinate units; 0
    // without any, and with meshopt, whose texture coordinates are the plain file's float32);
    // whether any primitive has them.
    double max_texcoord_error = 0;
    bool texcoords = false;
    bool meshopt_range_clamped = false;  // meshopt: a frame's step had to grow to fit int16
    double max_extent = 0;            // largest frame extent, light-seconds (to judge the errors above)
};

// The .glb of a sequence written as frames arrive: each frame's binary data goes at once to a
// spill file in the output's folder that has no name (openAnonymousFile, atomic_file.h: nothing
// is left behind whatever ends the process), only the JSON-side
// description (a few hundred bytes per frame) stays in memory, and finish() assembles the file
// under a temporary name (the BIN chunk placed by copy_file_range) and renames it into place.
// The first frame's data waits in its own buffers instead (the prepared frame is kept; frames
// from addEncoded() are copied) until a second frame comes: a lone frame's file is then written
// once, in place after its JSON chunk, with no spill file at all (writeWhole, atomic_file.h: past
// the page cache when large).
// Memory does not grow with the frame data: besides the JSON side it keeps the previous frame's
// index lists (to share equal ones). Frame buffers come from a pool shared by every writer of
// the process (at most max(4, 2 x cores) kept), so neither the frames of a sequence nor a lone
// frame written after another allocate again once the frames stop growing; prepare()'s scratch
// (crease split, meshopt orders) is pooled apart, one set per prepare() running at once, not
// one per frame held in flight. The disk briefly holds the binary data twice (frames by
// reference: in the frame spills, until finish() has copied them).
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
    // shared: GlbFrameData is opaque here. Without `streams`, meshopt's records alone (encode()'s
    // previous frame), not a frame for add().
    std::shared_ptr<GlbFrameData> prepare(const ExportFrame& frame, bool streams = true) const;
    bool add(const ExportFrame& frame, const GlbFrameData& prepared, std::string* error);
    // Frames across processes (pipeline/run/distribute.h): a prepared frame as bytes (its number,
    // camera time, which objects show, and the prepared data: float32 attributes, index lists, the
    // meshopt streams), made where the frame was cut, and add() of such bytes where the file is
    // written, frames in order: the file is the same bytes as add(frame, prepare(frame)) gives.
    // Cross-frame decisions (shared index buffers, Draco coding) are made by addEncoded(), so they
    // come out as in one process. addEncoded() refuses malformed bytes with a message.
    // Frames by reference (exporters/frame_spill.h: under MPI, when every rank's frame spill is
    // visible to rank 0): once this process has a frame spill, encode() writes the frame's arrays
    // there (the order the file takes them) and returns only the frame's description with where
    // they lie (a few hundred bytes: counts, bounds, a 128-bit hash per index list for sharing);
    // addEncoded() of it keeps them where they are, and finish() copies them into the file with
    // copy_file_range. The writing process then handles no frame data except, with meshopt, a
    // frame whose objects share their index lists only in part: their lists are read back and
    // their stream encoded there. Either form gives the same file.
    // Meshopt records that may be morph targets (frame coherence: no --attributes, no --shade
    // doppler) by reference need the previous frame (`previous`: its records are prepared here):
    // the frame is also encoded as its morph target, in both forms the writer may pick (after a
    // run's first frame, after a target), and the writer decides the runs from the descriptions
    // as in one process. Without it the frame cannot continue a run (the writer refuses it when
    // one is open).
    std::string encode(const ExportFrame& frame, const GlbFrameData& prepared, const ExportFrame* previous = nullptr) const;
    bool addEncoded(const std::string& bytes, std::string* error);
    // Writes the file; a .glb cannot exceed 4 GiB (refused with a message). With `check`, the
    // file's whole size (JSON chunk included) is checked with it before anything is written.
    bool finish(GlbStats* stats, std::string* error, const FrameSink::OutputCheck& check = nullptr);

private:
    std::string encodeByReference(const ExportFrame& frame, const GlbFrameData& prepared, const ExportFrame* previous) const;
    bool addByReference(const std::string& bytes, std::string* error);
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The frame number and object count a frame encoded whole (GlbSequenceWriter::encode without a
// frame spill: what shard files hold) starts with; false when `bytes` does not start as one.
bool encodedFrameHead(const std::string& bytes, long long* index, size_t* objects);

// The .glb as a frame sink: one GlbSequenceWriter per sequence (begin() starts it), frames
// converted by prepare() on the loop's worker threads. finish() reports the file and its size
// (with Draco or meshopt also the size without it); `verbose` adds the float32 and the codec's
// position error bounds to the summary, and a warning says when the codec's bound exceeds the
// sequence's tolerance (meshopt: only with --meshopt-bits, or where int16 cannot hold a frame).
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
    // Only --attributes doppler/proper_time and --shade doppler read them.
    bool readsLightFactors() const override { return options_.doppler || options_.proper_time || options_.shade_doppler; }
    // Only where it carries an object's look (surface_look.h: plain files).
    bool readsRestPoints() const override { return reads_rest_points_; }
    bool canHoldCommits() const override { return true; }  // the file appears in finish() only
    // Frames across processes: GlbSequenceWriter::encode and addEncoded.
    bool beginEncoding(const SequenceInfo& info, std::string* error) override { return begin(info, error); }
    EncodedOutput encode(const ExportFrame& frame, const PreparedFrame* prepared) const override;
    // Meshopt frames by reference that may be morph targets (GlbSequenceWriter::encode).
    bool encodesAfterPrevious() const override;
    EncodedOutput encodeAfter(const ExportFrame& frame, const PreparedFrame* prepared,
                              const ExportFrame* previous) const override;
    PendingOutput pendingEncoded(long long index, const EncodedOutput& frame) override;
    bool addEncoded(long long index, const EncodedOutput& frame, std::vector<std::string>* completed,
                    std::string* error) override;

private:
    std::string path_;
    GlbOptions options_;
    bool verbose_;
    std::string model_;
    double tolerance_ = 0;
    bool reads_rest_points_ = false;
    OutputCheck check_;
    long long least_ = 0;  // least size of the file so far uncompressed (positions and normals alone)
    std::unique_ptr<GlbSequenceWriter> writer_;
};

// All frames at once (the same file as GlbSequenceWriter fed `frames`).
bool writeAnimatedGlb(const std::string& path, const std::vector<ExportFrame>& frames, const SequenceInfo& info,
                      const GlbOptions& options, GlbStats* stats, std::string* error);

}  // namespace apparent
