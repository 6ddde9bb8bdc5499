#include "exporters/gltf.h"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <memory>
#include <filesystem>
#include <iomanip>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <type_traits>

#include <draco/compression/decode.h>
#include <draco/compression/expert_encode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#include <tiny_gltf.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "exporters/atomic_file.h"
#include "exporters/frame_spill.h"
#include "exporters/gltf_json.h"
#include "mesh4d/angles.h"
#include "mesh4d/box.h"
#include "mesh4d/doppler_colour.h"
#include "mesh4d/normals.h"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

namespace apparent {

namespace {

using mesh4d::Vec3;

// One primitive's KHR_draco_mesh_compression coding (encodeDraco): the Edgebreaker bytes and what
// the accessors take from the decoded mesh (point and face counts, position bounds, attribute ids).
struct DracoCoded {
    std::vector<char> bytes;
    uint64_t points = 0, faces = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    // Draco unique ids of POSITION, NORMAL, _EMISSION_TIME, _DOPPLER, _PROPER_TIME, COLOR_0 (-1: absent).
    int32_t ids[6] = {-1, -1, -1, -1, -1, -1};
    double quantization_error = 0;
    std::string error;  // Draco failed (reported by add())
};

// One primitive's data as it goes into the file: float32 positions relative to the frame origin.
// With meshopt also its packed vertices (MeshoptLayout::stride bytes each, in vertex-fetch order)
// and their normals in the two forms a frame may use (octahedral, kMeshoptNormalStride bytes
// each, and int8 x, y, z, 0 for the record; same order), its indices in
// vertex-cache order referring to them, and POSITION's integer bounds.
struct PrimitiveData {
    std::vector<float> positions, normals, emission;
    std::vector<float> doppler, proper_time;  // --attributes: empty unless asked for
    std::vector<float> colors;  // --shade doppler: COLOR_0, linear RGB (mesh4d/doppler_colour.h); else empty
    std::vector<uint32_t> indices;  // as cut (what index sharing compares)
    // POSITION's bounds (of the float32 values, in vertex order), found by prepare()'s conversion;
    // `bounded` false (frames decoded from bytes): plainPrimitive() finds them from `positions`.
    bool bounded = false;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    std::vector<unsigned char> packed, packed_normals, packed_snorm;
    std::shared_ptr<const std::vector<uint32_t>> ordered;  // shared with the object's MeshoptOrder
    int qmin[3] = {0, 0, 0}, qmax[3] = {0, 0, 0};
    DracoCoded draco;  // with Draco: the coding, made by prepare()
    // A frame made by another process whose arrays stay in its frame spill (frames by reference,
    // exporters/frame_spill.h): where they lie, and what add() needs of them. The vectors above
    // are then empty (draco.bytes too; the rest of DracoCoded is filled).
    struct Remote {
        bool on = false;
        FileSpan positions, normals, emission, doppler, proper_time, colors, indices, draco;
        FileSpan ordered;  // meshopt frames of two objects or more (for a partly shared index stream)
        uint64_t vertices = 0, index_count = 0, packed_vertices = 0, ordered_count = 0;
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // POSITION's bounds (of the float32 values)
        uint64_t index_hash[2] = {0, 0};              // indexHash(indices)
    } remote;
    // Empties the float32 arrays and the index list (an object the frame does not show).
    void clearArrays() {
        for (auto* v : {&positions, &normals, &emission, &doppler, &proper_time, &colors}) v->clear();
        indices.clear();
    }
    size_t vertexCount() const { return remote.on ? size_t(remote.vertices) : emission.size(); }
    size_t indexCount() const { return remote.on ? size_t(remote.index_count) : indices.size(); }
    size_t packedVertices(size_t stride) const { return remote.on ? size_t(remote.packed_vertices) : packed.size() / stride; }
    size_t orderedCount() const { return remote.on ? size_t(remote.ordered_count) : ordered->size(); }
    // Whether the optional attribute (`local` here, `span` by reference) is there.
    template <class V>
    bool has(const V& local, const FileSpan& span) const { return remote.on ? span.length > 0 : !local.empty(); }
};

// 128 bits of an index list, for sharing index buffers between frames made by different
// processes: four independent lanes of multiply-xorshift over the list as 64-bit words (two
// indices each; the lanes are independent, so their multiplications overlap),
// folded and finished by MurmurHash3's fmix64. Not cryptographic: lists made to collide could
// share a hash (the file would then stay valid: a shared list has the same length and vertex
// count, only the other frame's triangles); lists of real frames are not expected to.
void indexHash(const std::vector<uint32_t>& indices, uint64_t out[2]) {
    auto fmix = [](uint64_t k) {
        k ^= k >> 33;
        k *= 0xff51afd7ed558ccdULL;
        k ^= k >> 33;
        k *= 0xc4ceb9fe1a85ec53ULL;
        return k ^ (k >> 33);
    };
    static constexpr uint64_t kMul[4] = {0x9e3779b97f4a7c15ULL, 0xd6e8feb86659fd93ULL, 0xbf58476d1ce4e5b9ULL,
                                         0x94d049bb133111ebULL};
    uint64_t lane[4] = {0x243f6a8885a308d3ULL, 0x13198a2e03707344ULL, 0xa4093822299f31d0ULL, 0x082efa98ec4e6c89ULL};
    auto mix = [](uint64_t h, uint64_t w, uint64_t mul) {
        h = (h ^ w) * mul;
        return h ^ (h >> 29);
    };
    const uint32_t* p = indices.data();
    const size_t n = indices.size();
    size_t i = 0;
    for (; i + 8 <= n; i += 8)
        for (size_t l = 0; l < 4; ++l) lane[l] = mix(lane[l], uint64_t(p[i + 2 * l]) | uint64_t(p[i + 2 * l + 1]) << 32, kMul[l]);
    for (; i < n; ++i) lane[i % 4] = mix(lane[i % 4], p[i], kMul[i % 4]);
    out[0] = fmix(lane[0] ^ fmix(lane[1]) ^ n);
    out[1] = fmix(lane[2] ^ fmix(lane[3]) ^ out[0]);
}

// A frame's meshopt vertex streams: every shown object's packed vertices in object order, encoded
// as one EXT_meshopt_compression ATTRIBUTES view, and their normals either as another view
// (filter OCTAHEDRAL) or as int8 x, y, z, 0 at the end of each record, whichever makes the
// smaller file (a view costs about kMeshoptViewJsonBytes of JSON: small frames keep them inline).
struct MeshoptFrame {
    std::vector<unsigned char> encoded, encoded_normals;  // encoded_normals empty: normals inline
    size_t count = 0;                // vertices in all
    size_t stride = 0;               // bytes per record (MeshoptLayout::stride, + 4 with inline normals)
    bool normals_inline = false;
    std::vector<size_t> first;       // per object, its first vertex in the stream
    // A frame by reference (PrimitiveData::Remote): the two streams in the other process's spill,
    // and the index stream of every shown object (none shared), made there.
    bool remote = false;
    FileSpan remote_encoded, remote_normals, remote_indices;
    // By reference, for frame coherence (SequenceModel::morphTarget): whether the frame's records
    // may open a run, and the frame as a morph target of the previous frame, made where it was
    // cut, in the two forms the previous frame's normals take as a reader decodes them: [0] the
    // octahedral view's output (that frame opened its run, its normals in a view of their own),
    // [1] the int8 normals (it opened its run with its normals in the records, or was a target).
    // Without them (`targets` false) the frame cannot continue a run.
    struct RemoteTarget {
        bool fits = false;  // every difference holds in the target's record
        int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // POSITION's bounds (steps)
        FileSpan encoded;   // the target's view
    };
    bool remote_run = false, targets = false;
    RemoteTarget remote_target[2];
};
constexpr size_t kMeshoptViewJsonBytes = 200;

// The meshopt vertex record (gltf.h): int16 x, y, z, 0 | float32 emission time, then with
// --attributes float32 _DOPPLER and/or _PROPER_TIME, with --shade doppler uint16 (normalized)
// R, G, B, 0; the same for every frame of a sequence (an offset < 0: not in the record).
struct MeshoptLayout {
    explicit MeshoptLayout(const GlbOptions& o) {
        if (o.doppler) { doppler = int(stride); stride += 4; }
        if (o.proper_time) { proper_time = int(stride); stride += 4; }
        if (o.shade_doppler) { color = int(stride); stride += 8; }
    }
    size_t stride = 12;
    int doppler = -1, proper_time = -1, color = -1;
};
// The normals' stream: the EXT_meshopt_compression OCTAHEDRAL filter's 8-bit form (4 bytes a
// vertex), which the decoder turns into normalized int8 x, y, z (and a fourth byte); in the
// record instead (MeshoptFrame), normalized int8 x, y, z, 0 rounded from the float normal.
constexpr size_t kMeshoptNormalStride = 4;
constexpr int kMeshoptNormalBits = 8;

// Frame coherence (meshopt, gltf.h): a frame that is a morph target of its run's mesh stores one
// record per vertex, its difference from the previous frame: int16 x, y, z, 0 (in steps) | float32
// emission time | normalized int8 normal x, y, z, 0 (in 1/127). A run has at most
// kMorphTargetsMost targets, and at most kMorphVertexTargets vertices x targets (three.js expands
// each target to 32 bytes a vertex of float texture: 128 MB at most).
constexpr size_t kMorphStride = 16;
constexpr size_t kMorphTargetsMost = 63;
constexpr size_t kMorphVertexTargets = size_t(1) << 22;

// The emission time as meshopt stores it: rounded (half away from zero) to a multiple of the
// largest power of two not above `step`, so that its low mantissa bits are zero and compress;
// it stays a float32 that readers use as it is, within step / 2 seconds of the plain file's.
double emissionStep(double step) { return std::ldexp(1.0, int(std::floor(std::log2(step)))); }
float emissionRounded(float t, double q) { return float(std::round(double(t) / q) * q); }

// One object's vertex-cache and vertex-fetch orders for an index list, kept for the next frame:
// both depend on the index list alone, so an equal list (vertex mode, or the same refinement)
// takes them from here instead of optimizing again (meshopt_optimizeVertexCache costs about
// 100 ms at 1M triangles).
struct MeshoptOrder {
    std::vector<uint32_t> indices;   // the index list they were computed for
    size_t vertices = 0;             // and its vertex count
    std::shared_ptr<std::vector<uint32_t>> ordered;  // the triangles in cache order, in fetch numbering
    std::vector<unsigned int> remap; // fetch number of each vertex (~0u: unused)
    size_t used = 0;                 // vertices used by a triangle
};

// The meshopt form of `d`: positions quantized from the exact relative coordinates `rel` (xyz
// per vertex) to multiples of `step`, triangles in vertex-cache order, vertices in the order the
// triangles first use them (both depend on the index list alone, so frames with equal index
// lists get equal orders; `order` keeps them from the object's last frame). Returns the largest
// |step * q - rel| over the coordinates.
double packMeshopt(PrimitiveData* d, const std::vector<double>& rel, double step, const MeshoptLayout& layout,
                   MeshoptOrder* order, std::vector<float>* normal_work) {
    const size_t nv = d->vertexCount();
    if (!order->ordered || order->vertices != nv || order->indices != d->indices) {
        order->indices = d->indices;
        order->vertices = nv;
        // A frame still held refers to the old order: a new vector then, else this one again.
        if (!order->ordered || order->ordered.use_count() > 1) order->ordered = std::make_shared<std::vector<uint32_t>>();
        std::vector<uint32_t>& ordered = *order->ordered;
        ordered.resize(d->indices.size());
        meshopt_optimizeVertexCache(ordered.data(), d->indices.data(), d->indices.size(), nv);
        order->remap.resize(nv);
        order->used = meshopt_optimizeVertexFetchRemap(order->remap.data(), ordered.data(), ordered.size(), nv);
        meshopt_remapIndexBuffer(ordered.data(), ordered.data(), ordered.size(), order->remap.data());
    }
    d->ordered = order->ordered;
    const std::vector<unsigned int>& remap = order->remap;
    const size_t used = order->used;
    const size_t stride = layout.stride;
    d->packed.assign(used * stride, 0);
    d->packed_snorm.assign(used * 4, 0);
    std::vector<float>& normals = *normal_work;  // x, y, z, 0 per vertex in stream order, for the filter
    normals.assign(4 * used, 0.0f);
    const double time_step = emissionStep(step);
    // Vertices in parallel (each writes its own record); the largest error and the bounds reduced.
    struct Extremes {
        double worst = 0;
        int lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    };
    const Extremes e = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nv, 16384), Extremes{},
        [&](const tbb::blocked_range<size_t>& r, Extremes x) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                if (remap[i] == ~0u) continue;  // used by no triangle: dropped (a cut mesh has none)
                unsigned char* v = d->packed.data() + size_t(remap[i]) * stride;
                int16_t q[4] = {0, 0, 0, 0};
                for (int c = 0; c < 3; ++c) {
                    const double p = std::nearbyint(rel[3 * i + c] / step);
                    q[c] = int16_t(std::clamp(p, -32767.0, 32767.0));
                    x.worst = std::max(x.worst, std::fabs(double(q[c]) * step - rel[3 * i + c]));
                    x.lo[c] = std::min(x.lo[c], int(q[c]));
                    x.hi[c] = std::max(x.hi[c], int(q[c]));
                    normals[4 * size_t(remap[i]) + size_t(c)] = d->normals[3 * i + c];
                    d->packed_snorm[4 * size_t(remap[i]) + size_t(c)] =
                        static_cast<unsigned char>(int8_t(meshopt_quantizeSnorm(d->normals[3 * i + c], 8)));
                }
                std::memcpy(v, q, 8);
                const float t = emissionRounded(d->emission[i], time_step);
                std::memcpy(v + 8, &t, 4);
                if (layout.doppler >= 0 && !d->doppler.empty()) std::memcpy(v + layout.doppler, &d->doppler[i], 4);
                if (layout.proper_time >= 0 && !d->proper_time.empty()) std::memcpy(v + layout.proper_time, &d->proper_time[i], 4);
                if (layout.color >= 0 && !d->colors.empty()) {
                    uint16_t rgb[4] = {0, 0, 0, 0};
                    for (int c = 0; c < 3; ++c) rgb[c] = uint16_t(meshopt_quantizeUnorm(std::clamp(d->colors[3 * i + c], 0.0f, 1.0f), 16));
                    std::memcpy(v + layout.color, rgb, 8);
                }
            }
            return x;
        },
        [](Extremes a, const Extremes& b) {
            a.worst = std::max(a.worst, b.worst);
            for (int c = 0; c < 3; ++c) { a.lo[c] = std::min(a.lo[c], b.lo[c]); a.hi[c] = std::max(a.hi[c], b.hi[c]); }
            return a;
        });
    const double worst = e.worst;
    for (int c = 0; c < 3; ++c) { d->qmin[c] = e.lo[c]; d->qmax[c] = e.hi[c]; }
    d->packed_normals.resize(used * kMeshoptNormalStride);
    if (used > 0)
        meshopt_encodeFilterOct(d->packed_normals.data(), used, kMeshoptNormalStride, kMeshoptNormalBits, normals.data());
    return worst;
}

// One primitive's Draco coding (KHR_draco_mesh_compression), made by prepare() on the worker
// threads (and, with MPI, on the rank that cut the frame); `error` set when Draco failed. The
// position error bound is half a step of the quantization grid, which spans the largest extent
// of the primitive's positions in 2^bits - 1 steps.
void encodeDraco(const PrimitiveData& d, const GlbOptions& options, DracoCoded* out) {
    *out = DracoCoded();
    // Step: build the Draco mesh with identity point mapping.
    draco::Mesh dm;
    const size_t nv = d.vertexCount();
    dm.set_num_points(uint32_t(nv));
    auto addAttribute = [&](draco::GeometryAttribute::Type type, int components, const float* values) {
        draco::GeometryAttribute ga;
        ga.Init(type, nullptr, components, draco::DT_FLOAT32, false, 4 * components, 0);
        const int id = dm.AddAttribute(ga, /*identity_mapping=*/true, uint32_t(nv));
        for (size_t i = 0; i < nv; ++i)
            dm.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), values + components * i);
        return id;
    };
    const int pos = addAttribute(draco::GeometryAttribute::POSITION, 3, d.positions.data());
    const int nrm = addAttribute(draco::GeometryAttribute::NORMAL, 3, d.normals.data());
    const int emt = addAttribute(draco::GeometryAttribute::GENERIC, 1, d.emission.data());
    const int dop = d.doppler.empty() ? -1 : addAttribute(draco::GeometryAttribute::GENERIC, 1, d.doppler.data());
    const int tau = d.proper_time.empty() ? -1 : addAttribute(draco::GeometryAttribute::GENERIC, 1, d.proper_time.data());
    const int col = d.colors.empty() ? -1 : addAttribute(draco::GeometryAttribute::COLOR, 3, d.colors.data());
    for (size_t f = 0; f < d.indices.size(); f += 3)
        dm.AddFace({draco::PointIndex(d.indices[f]), draco::PointIndex(d.indices[f + 1]),
                    draco::PointIndex(d.indices[f + 2])});

    // Step: encode; the emission time stays unquantized (lossless).
    draco::ExpertEncoder enc(dm);
    enc.SetAttributeQuantization(pos, options.position_bits);
    enc.SetAttributeQuantization(nrm, options.normal_bits);
    enc.SetSpeedOptions(5, 5);
    enc.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer buf;
    const draco::Status st = enc.EncodeToBuffer(&buf);
    if (!st.ok()) {
        out->error = "Draco encoding failed: " + st.error_msg_string();
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < d.positions.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], double(d.positions[i]));
        hi[i % 3] = std::max(hi[i % 3], double(d.positions[i]));
    }
    double extent = 0;
    for (int c = 0; c < 3; ++c) extent = std::max(extent, hi[c] - lo[c]);
    out->quantization_error = 0.5 * extent / double((1u << options.position_bits) - 1);

    // Step: decode it again; the accessors must describe what a reader will get.
    draco::DecoderBuffer db;
    db.Init(buf.data(), buf.size());
    draco::Decoder dec;
    auto decoded = dec.DecodeMeshFromBuffer(&db);
    if (!decoded.ok()) {
        out->error = "Draco could not decode its own output: " + decoded.status().error_msg_string();
        return;
    }
    const std::unique_ptr<draco::Mesh> back = std::move(decoded).value();
    const draco::PointAttribute* bpos = back->GetAttributeByUniqueId(dm.attribute(pos)->unique_id());
    for (int c = 0; c < 3; ++c) {
        out->lo[c] = INFINITY;
        out->hi[c] = -INFINITY;
    }
    for (draco::PointIndex p(0); p < back->num_points(); ++p) {
        float v[3];
        bpos->GetMappedValue(p, v);
        for (int c = 0; c < 3; ++c) { out->lo[c] = std::min(out->lo[c], double(v[c])); out->hi[c] = std::max(out->hi[c], double(v[c])); }
    }
    out->points = back->num_points();
    out->faces = back->num_faces();
    const int ids[6] = {pos, nrm, emt, dop, tau, col};
    for (int a = 0; a < 6; ++a) out->ids[a] = ids[a] >= 0 ? int32_t(dm.attribute(ids[a])->unique_id()) : -1;
    out->bytes.assign(buf.data(), buf.data() + buf.size());
}

// Where the BIN chunk goes while frames arrive: a spill file (so memory does not grow with the
// frame count), or nowhere (counting only, for the size without Draco).
// The first frame is held instead (`holding`): data that lies in the frame's own buffers (kept
// alive by `pinned`; `borrowable` lists them) stays where it is, anything else is copied into
// `own`, and `held` lists the chunk in order. A lone frame is then written once, in place after
// the JSON chunk by finish(), without a spill file; a second frame first sends the held data to
// the spill file (spill()), which is opened only then.
// With frames by reference (MPI, exporters/frame_spill.h) the chunk becomes a list of `pieces`
// instead: ranges of this sink's spill file, of other processes' frame spills and runs of zeros,
// copied into the .glb by finish(). A reference ends the holding (the held data is spilled first).
struct BinSink {
    static constexpr int32_t kZeros = -3, kLocal = -2;  // FileSpan::source of pieces not from a spill
    bool counting = false;  // count only
    std::string dir;        // the spill file's folder
    int fd = -1;            // the spill file (-1: not opened yet)
    size_t size = 0;
    std::string error;  // the first write error
    bool holding = false;
    struct Held {
        const char* data;  // borrowed bytes, or nullptr: at `offset` in `own`
        size_t offset, n;
    };
    std::vector<Held> held;
    std::string own;
    std::vector<std::pair<const char*, const char*>> borrowable;
    std::shared_ptr<const void> pinned;
    bool in_pieces = false;
    std::vector<FileSpan> pieces;
    size_t local = 0;  // bytes written to fd

    void write(const void* data, size_t n) {
        size += n;
        if (counting || n == 0) return;
        if (holding) {
            const char* p = static_cast<const char*>(data);
            for (const auto& [lo, hi] : borrowable)
                if (p >= lo && p + n <= hi) {
                    held.push_back({p, 0, n});
                    return;
                }
            held.push_back({nullptr, own.size(), n});
            own.append(p, n);
            return;
        }
        toSpill(data, n);
    }
    // Appends to the spill file (opened on first use), and to the pieces when there are pieces.
    void toSpill(const void* data, size_t n) {
        // The spill file has no name (atomic_file.h): nothing is left behind, even after SIGKILL.
        if (fd < 0 && error.empty()) fd = openAnonymousFile(dir, &error);
        if (fd >= 0 && error.empty() && !writeAll(fd, data, n, &error)) error = "cannot write: " + error;
        if (in_pieces) piece({kLocal, local, n});
        local += n;
    }
    // The held data to the spill file; every write goes there from now on.
    void spill() {
        if (!holding) return;
        holding = false;
        for (const Held& h : held) toSpill(h.data ? h.data : own.data() + h.offset, h.n);
        held = {};
        own = {};
        borrowable.clear();
        pinned.reset();
    }
    // The held data in order, appended to `out` (finish() of a lone frame writes them).
    void heldPieces(std::vector<iovec>* out) const {
        for (const Held& h : held) out->push_back({const_cast<char*>(h.data ? h.data : own.data() + h.offset), h.n});
    }
    void pad(size_t n) {
        static const char zeros[4] = {0, 0, 0, 0};
        if (!in_pieces) return write(zeros, n);
        piece({kZeros, 0, n});
        size += n;
    }
    // Bytes of another process's frame spill (counted only without pieces: the plain twin).
    void reference(const FileSpan& s) {
        if (!counting) {
            spill();
            if (!in_pieces) startPieces();
            piece(s);
        }
        size += s.length;
    }
    // From here on a list of pieces; what the file holds so far is the first.
    void startPieces() {
        in_pieces = true;
        if (local > 0) pieces.push_back({kLocal, 0, local});
    }
    void piece(const FileSpan& s) {
        if (s.length == 0) return;
        FileSpan* last = pieces.empty() ? nullptr : &pieces.back();
        if (last && last->source == s.source && (s.source == kZeros || last->offset + last->length == s.offset))
            last->length += s.length;
        else
            pieces.push_back(s);
    }
};

class GlbBuilder {
public:
    // The JSON records (gltf_json.h), written by SequenceModel::finish.
    std::vector<gltfjson::Accessor> accessors;
    std::vector<gltfjson::BufferView> views;
    std::vector<gltfjson::Mesh> meshes;
    std::vector<gltfjson::Node> nodes;
    size_t fallback_size = 0;  // meshopt: the fallback buffer's byteLength (0: no meshopt view)

    GlbBuilder(const GlbOptions& options, BinSink* sink) : options_(options), sink_(sink) {}

    size_t sinkSize() const { return sink_->size; }

    int addView(const void* data, size_t n, int target) {
        return newView(n, target, [&] { sink_->write(data, n); });
    }
    // The same of bytes in a frame source (frames by reference).
    int addView(const FileSpan& span, int target) {
        return newView(size_t(span.length), target, [&] { sink_->reference(span); });
    }
    // A view of `local` (this process's vector) or, for a frame by reference, of `span`.
    template <class V>
    int addView(const PrimitiveData& d, const V& local, const FileSpan& span, int target) {
        return d.remote.on ? addView(span, target) : addView(local.data(), local.size() * sizeof(local[0]), target);
    }

    // A new accessor (`vec3`: VEC3, else SCALAR) at `offset` bytes of `view`; with `lo` and `hi`
    // its min and max (`n` values each).
    int addAccessor(int view, int component, bool vec3, size_t count, size_t offset = 0, const double* lo = nullptr,
                    const double* hi = nullptr, int n = 0) {
        gltfjson::Accessor& a = accessors.emplace_back();
        a.view = view;
        a.component = component;
        a.vec3 = vec3;
        a.count = count;
        a.offset = offset;
        if (lo) {
            a.bounds = uint8_t(n);
            std::copy(lo, lo + n, a.min);
            std::copy(hi, hi + n, a.max);
        }
        return int(accessors.size()) - 1;
    }
    int addNormalized(int view, int component, bool vec3, size_t count, size_t offset) {
        const int a = addAccessor(view, component, vec3, count, offset);
        accessors.back().normalized = true;
        return a;
    }

    // A plain (uncompressed) primitive; `shared_indices` >= 0: that index accessor instead of a new one.
    gltfjson::Primitive plainPrimitive(const PrimitiveData& d, int shared_indices) {
        gltfjson::Primitive prim;
        double lo[3], hi[3];
        if (d.remote.on) {
            std::copy(d.remote.lo, d.remote.lo + 3, lo);
            std::copy(d.remote.hi, d.remote.hi + 3, hi);
        } else if (d.bounded) {
            std::copy(d.lo, d.lo + 3, lo);
            std::copy(d.hi, d.hi + 3, hi);
        } else {
            bounds(d.positions, lo, hi);
        }
        const PrimitiveData::Remote& r = d.remote;
        const size_t nv = d.vertexCount();
        auto& at = prim.attributes;
        at[gltfjson::kPosition] = addAccessor(addView(d, d.positions, r.positions, kArray), kFloat, true, nv, 0, lo, hi, 3);
        at[gltfjson::kNormal] = addAccessor(addView(d, d.normals, r.normals, kArray), kFloat, true, nv);
        at[gltfjson::kEmissionTime] = addAccessor(addView(d, d.emission, r.emission, kArray), kFloat, false, nv);
        if (d.has(d.doppler, r.doppler))
            at[gltfjson::kDoppler] = addAccessor(addView(d, d.doppler, r.doppler, kArray), kFloat, false, nv);
        if (d.has(d.proper_time, r.proper_time))
            at[gltfjson::kProperTime] = addAccessor(addView(d, d.proper_time, r.proper_time, kArray), kFloat, false, nv);
        if (d.has(d.colors, r.colors))
            at[gltfjson::kColor0] = addAccessor(addView(d, d.colors, r.colors, kArray), kFloat, true, nv);
        prim.indices = shared_indices >= 0 ? shared_indices
                                           : addAccessor(addView(d, d.indices, r.indices, kElements),
                                                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false, d.indexCount());
        return prim;
    }

    // An EXT_meshopt_compression primitive: its vertices at `first_vertex` of the frame's vertex
    // view `vview` (records of `layout`, `stride` bytes each) and normal view `nview` (-1: the
    // normals end each record), its indices the accessor `indices` (made by the caller: new or
    // shared).
    gltfjson::Primitive meshoptPrimitive(const PrimitiveData& d, const MeshoptLayout& layout, size_t stride, int vview,
                                         int nview, size_t first_vertex, int indices) {
        gltfjson::Primitive prim;
        const size_t nv = d.packedVertices(layout.stride);
        const size_t at0 = first_vertex * stride;
        auto& at = prim.attributes;
        const double lo[3] = {double(d.qmin[0]), double(d.qmin[1]), double(d.qmin[2])};
        const double hi[3] = {double(d.qmax[0]), double(d.qmax[1]), double(d.qmax[2])};
        at[gltfjson::kPosition] = addAccessor(vview, TINYGLTF_COMPONENT_TYPE_SHORT, true, nv, at0, lo, hi, 3);
        at[gltfjson::kNormal] =
            nview >= 0 ? addNormalized(nview, TINYGLTF_COMPONENT_TYPE_BYTE, true, nv, first_vertex * kMeshoptNormalStride)
                       : addNormalized(vview, TINYGLTF_COMPONENT_TYPE_BYTE, true, nv, at0 + layout.stride);
        at[gltfjson::kEmissionTime] = addAccessor(vview, kFloat, false, nv, at0 + 8);
        if (layout.doppler >= 0 && d.has(d.doppler, d.remote.doppler))
            at[gltfjson::kDoppler] = addAccessor(vview, kFloat, false, nv, at0 + size_t(layout.doppler));
        if (layout.proper_time >= 0 && d.has(d.proper_time, d.remote.proper_time))
            at[gltfjson::kProperTime] = addAccessor(vview, kFloat, false, nv, at0 + size_t(layout.proper_time));
        if (layout.color >= 0 && d.has(d.colors, d.remote.colors))
            at[gltfjson::kColor0] =
                addNormalized(vview, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true, nv, at0 + size_t(layout.color));
        prim.indices = indices;
        return prim;
    }

    // A view of the fallback buffer (1, no data) whose EXT_meshopt_compression object points at
    // `encoded` in the BIN chunk. `octahedral`: the view's data went through the OCTAHEDRAL filter.
    int addMeshoptView(const std::vector<unsigned char>& encoded, size_t count, size_t stride, bool indices,
                       bool octahedral = false) {
        return newMeshoptView(encoded.size(), count, stride, indices, octahedral,
                              [&] { sink_->write(encoded.data(), encoded.size()); });
    }
    // The same of an encoded stream in a frame source (frames by reference).
    int addMeshoptView(const FileSpan& encoded, size_t count, size_t stride, bool indices, bool octahedral = false) {
        return newMeshoptView(size_t(encoded.length), count, stride, indices, octahedral,
                              [&] { sink_->reference(encoded); });
    }
    template <class Write>
    int newMeshoptView(size_t length, size_t count, size_t stride, bool indices, bool octahedral, const Write& write) {
        if (sink_->size % 4) sink_->pad(4 - sink_->size % 4);
        gltfjson::BufferView& v = views.emplace_back();
        v.meshopt = true;
        v.ext = {sink_->size, length, stride, count, indices, octahedral};
        write();
        v.buffer = 1;
        v.offset = fallback_size;
        v.length = count * stride;
        v.stride = indices ? 0 : stride;
        v.target = indices ? kElements : kArray;
        fallback_size += (v.length + 3) / 4 * 4;
        return int(views.size()) - 1;
    }

    // A KHR_draco_mesh_compression primitive from its coding (DracoCoded, made by prepare());
    // returns false with the message when Draco failed there. `quantization_error` receives the
    // position error bound.
    bool dracoPrimitive(const PrimitiveData& d, gltfjson::Primitive* prim, double* quantization_error,
                        std::string* error) {
        const DracoCoded& c = d.draco;
        if (!c.error.empty()) {
            *error = c.error;
            return false;
        }
        *quantization_error = c.quantization_error;
        const size_t n_points = size_t(c.points);
        auto& at = prim->attributes;
        at[gltfjson::kPosition] = addAccessor(-1, kFloat, true, n_points, 0, c.lo, c.hi, 3);
        at[gltfjson::kNormal] = addAccessor(-1, kFloat, true, n_points);
        at[gltfjson::kEmissionTime] = addAccessor(-1, kFloat, false, n_points);
        if (c.ids[3] >= 0) at[gltfjson::kDoppler] = addAccessor(-1, kFloat, false, n_points);
        if (c.ids[4] >= 0) at[gltfjson::kProperTime] = addAccessor(-1, kFloat, false, n_points);
        if (c.ids[5] >= 0) at[gltfjson::kColor0] = addAccessor(-1, kFloat, true, n_points);
        prim->indices = addAccessor(-1, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false, size_t(c.faces) * 3);
        prim->draco_view = d.remote.on ? addView(d.remote.draco, 0) : addView(c.bytes.data(), c.bytes.size(), 0);
        // The Draco ids in DracoCoded's order: POSITION, NORMAL, _EMISSION_TIME, _DOPPLER, _PROPER_TIME, COLOR_0.
        static constexpr int kOrder[6] = {gltfjson::kPosition, gltfjson::kNormal,     gltfjson::kEmissionTime,
                                          gltfjson::kDoppler,  gltfjson::kProperTime, gltfjson::kColor0};
        for (int i = 0; i < 6; ++i) prim->draco_ids[size_t(kOrder[i])] = c.ids[i];
        return true;
    }

private:
    // A new view of `n` bytes that `write` puts into the sink, 4-byte aligned for float/uint32.
    template <class Write>
    int newView(size_t n, int target, const Write& write) {
        if (sink_->size % 4) sink_->pad(4 - sink_->size % 4);
        gltfjson::BufferView& v = views.emplace_back();
        v.buffer = 0;
        v.offset = sink_->size;
        v.length = n;
        v.target = target;
        write();
        return int(views.size()) - 1;
    }

    static constexpr int kArray = TINYGLTF_TARGET_ARRAY_BUFFER;
    static constexpr int kElements = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
    static constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
    GlbOptions options_;
    BinSink* sink_;

    // Per coordinate, in vertex order (the same bits as any order but for the sign of a zero).
    static void bounds(const std::vector<float>& xyz, double* lo, double* hi) {
        double l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i + 3 <= xyz.size(); i += 3)
            for (int c = 0; c < 3; ++c) {
                l[c] = std::min(l[c], double(xyz[i + size_t(c)]));
                h[c] = std::max(h[c], double(xyz[i + size_t(c)]));
            }
        std::copy(l, l + 3, lo);
        std::copy(h, h + 3, hi);
    }
};

// Float32 data of one object's mesh relative to `origin`; tracks the largest rounding. Vertices
// are split along creases sharper than kCreaseDeg so folds shade flat and curves smooth.
constexpr double kCreaseDeg = 30.0;
// The meshopt form's scratch vectors (kept by the frame's buffers, used object by object).
struct MeshoptScratch {
    std::vector<double> exact;
    std::vector<MeshoptOrder> orders;  // per object
    std::vector<float> normals;
    std::vector<unsigned char> vertices, normal_stream;  // the frame's streams before encoding
    std::vector<unsigned char> inline_records, inline_encoded;  // the same with the normals inline
};
// With `step` > 0 also the meshopt form, positions quantized to multiples of `step` (*max_quant
// receives the largest coordinate error). The conversion runs in parallel (TBB) and writes into
// `d`, whose vectors keep their capacity from frame to frame; `map` and `work` are the crease
// split's (reused the same way, object by object), `scratch` meshopt's and `order` the object's
// meshopt orders.
void toPrimitive(const mesh4d::ApparentMesh& m, const double origin[3], double step, double* max_err,
                 double* max_quant, PrimitiveData* d, mesh4d::CreaseMap* map, mesh4d::CreaseWork* work,
                 MeshoptScratch* scratch, MeshoptOrder* order, const GlbOptions& options,
                 const std::array<double, 4>& base_color) {
    mesh4d::creaseSplitMap(m, kCreaseDeg, map, work);
    const size_t nv = map->source.size();
    d->positions.resize(3 * nv);
    d->normals.resize(3 * nv);
    d->emission.resize(nv);
    const bool doppler = options.doppler && m.doppler.size() == m.positions.size();
    const bool proper_time = options.proper_time && m.proper_time.size() == m.positions.size();
    d->doppler.resize(doppler ? nv : 0);
    d->proper_time.resize(proper_time ? nv : 0);
    const bool shade = options.shade_doppler && m.doppler.size() == m.positions.size();
    d->colors.resize(shade ? 3 * nv : 0);
    const std::array<double, 3> base{base_color[0], base_color[1], base_color[2]};
    std::vector<double>& exact = scratch->exact;
    exact.resize(step > 0 ? 3 * nv : 0);
    // The object's own origin first: both large terms cancel before the small local one is added.
    const double shift[3] = {m.origin[0] - origin[0], m.origin[1] - origin[1], m.origin[2] - origin[2]};
    // The largest rounding and the float32 positions' bounds. std::min and std::max keep the
    // first of equal values (a signed zero) and the join takes the left part first, so the
    // bounds are GlbBuilder::bounds()'s in vertex order, bit for bit, whatever the split.
    struct Reduced {
        double worst = 0;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    };
    const Reduced reduced = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nv, 16384), Reduced{},
        [&](const tbb::blocked_range<size_t>& r, Reduced red) {
            // Local pointers: through the by-reference captures every array would be reloaded
            // after each store.
            const uint32_t* const source = map->source.data();
            const mesh4d::Vec3* const pos = m.positions.data();
            const mesh4d::Vec3* const nrm = map->normals.data();
            float* const out_pos = d->positions.data();
            float* const out_nrm = d->normals.data();
            float* const out_emission = d->emission.data();
            double* const out_exact = step > 0 ? exact.data() : nullptr;
            const double s0 = shift[0], s1 = shift[1], s2 = shift[2];
            double w = red.worst;
            double lo[3] = {red.lo[0], red.lo[1], red.lo[2]}, hi[3] = {red.hi[0], red.hi[1], red.hi[2]};
            for (size_t k = r.begin(); k < r.end(); ++k) {
                const uint32_t v = source[k];
                const double rel[3] = {s0 + pos[v].x, s1 + pos[v].y, s2 + pos[v].z};
                for (int c = 0; c < 3; ++c) {
                    const float fv = float(rel[c]);
                    out_pos[3 * k + c] = fv;
                    w = std::max(w, std::fabs(double(fv) - rel[c]));
                    lo[c] = std::min(lo[c], double(fv));
                    hi[c] = std::max(hi[c], double(fv));
                    if (out_exact) out_exact[3 * k + c] = rel[c];
                }
                out_nrm[3 * k] = float(nrm[k].x);
                out_nrm[3 * k + 1] = float(nrm[k].y);
                out_nrm[3 * k + 2] = float(nrm[k].z);
                out_emission[k] = float(m.absoluteTime(v));
                if (doppler) d->doppler[k] = float(m.doppler[v]);
                if (proper_time) d->proper_time[k] = float(m.proper_time[v]);
                if (shade) {
                    const std::array<double, 3> c = mesh4d::dopplerColour(base, m.doppler[v]);
                    for (int j = 0; j < 3; ++j) d->colors[3 * k + size_t(j)] = float(c[size_t(j)]);
                }
            }
            red.worst = w;
            for (int c = 0; c < 3; ++c) {
                red.lo[c] = lo[c];
                red.hi[c] = hi[c];
            }
            return red;
        },
        [](Reduced a, const Reduced& b) {
            a.worst = std::max(a.worst, b.worst);
            for (int c = 0; c < 3; ++c) {
                a.lo[c] = std::min(a.lo[c], b.lo[c]);
                a.hi[c] = std::max(a.hi[c], b.hi[c]);
            }
            return a;
        });
    *max_err = std::max(*max_err, reduced.worst);
    d->bounded = true;
    for (int c = 0; c < 3; ++c) {
        d->lo[c] = reduced.lo[c];
        d->hi[c] = reduced.hi[c];
    }
    d->indices.resize(3 * map->triangles.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, map->triangles.size(), 65536), [&](const tbb::blocked_range<size_t>& r) {
        std::memcpy(d->indices.data() + 3 * r.begin(), map->triangles.data() + r.begin(), r.size() * sizeof(map->triangles[0]));
    });
    if (step > 0)
        *max_quant = std::max(*max_quant, packMeshopt(d, exact, step, MeshoptLayout(options), order,
                                                      &scratch->normals));
}

// Rotation quaternion (x, y, z, w) of the camera node: glTF cameras look down local -Z with +Y
// up, so the node's axes are right = f x up, up' = right x f, back = -f.
std::vector<double> cameraRotation(const ExportCamera& cam) {
    const Vec3 f = (cam.look_at - cam.position) / mesh4d::norm(cam.look_at - cam.position);
    const Vec3 r = mesh4d::cross(f, cam.up) / mesh4d::norm(mesh4d::cross(f, cam.up));
    const Vec3 u = mesh4d::cross(r, f);
    const Vec3 b = -f;
    // Matrix columns r, u, b; standard matrix-to-quaternion conversion choosing the largest term.
    const double m00 = r.x, m01 = u.x, m02 = b.x, m10 = r.y, m11 = u.y, m12 = b.y, m20 = r.z, m21 = u.z, m22 = b.z;
    const double trace = m00 + m11 + m22;
    double x, y, z, w;
    if (trace > 0) {
        const double s = 0.5 / std::sqrt(trace + 1.0);
        w = 0.25 / s; x = (m21 - m12) * s; y = (m02 - m20) * s; z = (m10 - m01) * s;
    } else if (m00 > m11 && m00 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m00 - m11 - m22);
        w = (m21 - m12) / s; x = 0.25 * s; y = (m01 + m10) / s; z = (m02 + m20) / s;
    } else if (m11 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m11 - m00 - m22);
        w = (m02 - m20) / s; x = (m01 + m10) / s; y = 0.25 * s; z = (m12 + m21) / s;
    } else {
        const double s = 2.0 * std::sqrt(1.0 + m22 - m00 - m11);
        w = (m10 - m01) / s; x = (m02 + m20) / s; y = (m12 + m21) / s; z = 0.25 * s;
    }
    const double len = std::sqrt(x * x + y * y + z * z + w * w);
    return {x / len, y / len, z / len, w / len};
}

// A frame's meshopt index stream: the objects' vertex-cache-ordered lists, one after another.
void encodeIndexStream(const std::vector<unsigned int>& all, size_t most_vertices, std::vector<unsigned char>* out) {
    out->resize(meshopt_encodeIndexBufferBound(all.size(), most_vertices));
    out->resize(meshopt_encodeIndexBuffer(out->data(), out->size(), all.data(), all.size()));
}

// Reads `span` of its frame source into `out` (appended); false with a message.
bool readSpan(const FileSpan& span, void* out, std::string* error) {
    const int fd = frameSource(span.source);
    size_t done = 0;
    while (fd >= 0 && done < span.length) {
        const ssize_t r = ::pread(fd, static_cast<char*>(out) + done, size_t(span.length) - done, off_t(span.offset + done));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;
        done += size_t(r);
    }
    if (done == span.length) return true;
    *error = "cannot read frame data of process " + std::to_string(span.source) +
             (fd < 0 ? std::string(": not known") : ": " + std::string(std::strerror(errno)));
    return false;
}

// Appends the object's vertex-cache-ordered indices (read back from its spill when by reference).
bool appendOrdered(const PrimitiveData& d, std::vector<unsigned int>* all, std::string* error) {
    if (!d.remote.on) {
        all->insert(all->end(), d.ordered->begin(), d.ordered->end());
        return true;
    }
    if (d.remote.ordered.length != 4 * d.remote.ordered_count) {
        *error = "internal: a partly shared index stream without the objects' lists";
        return false;
    }
    const size_t at = all->size();
    all->resize(at + size_t(d.remote.ordered_count));
    return readSpan(d.remote.ordered, all->data() + at, error);
}

// Frame coherence (gltf.h), the one home of its record arithmetic, used where the file is written
// and, by reference, where the frame was cut. A frame's records and normals as a run's reference
// for the next frame: its shown objects' packed records in order, and their normals as a reader
// decodes them (`decoded_normals`: the octahedral view's int8 output, or the record's when the
// normals are inline; else the int8 normals, as a target's record holds them). False when they
// do not make `count` whole vertices.
// Without `records` and `normals`: only whether they would make them.
bool runReference(const std::vector<const PrimitiveData*>& shown, size_t count, bool normals_inline,
                  bool decoded_normals, std::vector<unsigned char>* records, std::vector<unsigned char>* normals) {
    size_t record_bytes = 0, normal_bytes = 0;
    for (const PrimitiveData* d : shown) {
        const std::vector<unsigned char>& n = decoded_normals && !normals_inline ? d->packed_normals : d->packed_snorm;
        record_bytes += d->packed.size();
        normal_bytes += n.size();
    }
    if (record_bytes != count * 12 || normal_bytes != count * 4) return false;
    if (!records) return true;
    records->clear();
    normals->clear();
    for (const PrimitiveData* d : shown) {
        records->insert(records->end(), d->packed.begin(), d->packed.end());
        const std::vector<unsigned char>& n = decoded_normals && !normals_inline ? d->packed_normals : d->packed_snorm;
        normals->insert(normals->end(), n.begin(), n.end());
    }
    if (decoded_normals && !normals_inline) meshopt_decodeFilterOct(normals->data(), count, kMeshoptNormalStride);
    return true;
}

// The shown objects' records (in order) as differences from the reference `records` and
// `normals` (runReference) of `count` vertices: one kMorphStride record per vertex in `rec`,
// each object's first vertex in `first`, POSITION's bounds in `lo` and `hi` (steps). False when
// a difference does not fit the record (int16 steps, an emission time difference exact in
// float32, int8 normal steps) or the vertex counts differ.
bool morphRecords(const std::vector<const PrimitiveData*>& shown, const std::vector<unsigned char>& records,
                  const std::vector<unsigned char>& normals, size_t count, std::vector<unsigned char>* rec,
                  std::vector<size_t>* first, int lo[3], int hi[3]) {
    for (const PrimitiveData* d : shown)
        if (d->packed.size() != d->packed_snorm.size() * 3) return false;
    if (records.size() != count * 12 || normals.size() != count * 4) return false;
    rec->assign(count * kMorphStride, 0);
    first->clear();
    for (int c = 0; c < 3; ++c) {
        lo[c] = INT32_MAX;
        hi[c] = INT32_MIN;
    }
    size_t v = 0;
    for (const PrimitiveData* d : shown) {
        first->push_back(v);
        for (size_t i = 0; i < d->packed.size() / 12; ++i, ++v) {
            if (v >= count) return false;
            int16_t now[4], before[4], dq[4] = {0, 0, 0, 0};
            std::memcpy(now, &d->packed[12 * i], 8);
            std::memcpy(before, &records[12 * v], 8);
            int8_t dn[4] = {0, 0, 0, 0};
            for (int c = 0; c < 3; ++c) {
                const int dd = int(now[c]) - int(before[c]);
                if (dd < -32767 || dd > 32767) return false;
                dq[c] = int16_t(dd);
                lo[c] = std::min(lo[c], dd);
                hi[c] = std::max(hi[c], dd);
                const int dnc = int(int8_t(d->packed_snorm[4 * i + size_t(c)])) - int(int8_t(normals[4 * v + size_t(c)]));
                if (dnc < -127 || dnc > 127) return false;
                dn[c] = int8_t(dnc);
            }
            float t_now, t_before;
            std::memcpy(&t_now, &d->packed[12 * i + 8], 4);
            std::memcpy(&t_before, &records[12 * v + 8], 4);
            const double dt = double(t_now) - double(t_before);
            const float dt32 = float(dt);
            if (double(dt32) != dt) return false;
            unsigned char* r = &(*rec)[kMorphStride * v];
            std::memcpy(r, dq, 8);
            std::memcpy(r + 8, &dt32, 4);
            std::memcpy(r + 12, dn, 4);
        }
    }
    return v == count;
}

// A target's records as its view's bytes (EXT_meshopt_compression ATTRIBUTES).
std::vector<unsigned char> encodeMorphRecords(const std::vector<unsigned char>& rec, size_t count) {
    std::vector<unsigned char> encoded(meshopt_encodeVertexBufferBound(count, kMorphStride));
    encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), rec.data(), count, kMorphStride));
    return encoded;
}

// The glTF model of a sequence, built frame by frame: JSON-side objects in `model`, binary data
// streamed to the sink. Two run side by side with Draco: the real one and a plain one that only
// counts, for the size without Draco.
struct SequenceModel {
    SequenceModel(const SequenceInfo& info_, const GlbOptions& options, BinSink* sink)
        : info(info_), b(options, sink), layout(options), shade_doppler(options.shade_doppler) {
        // Step: the camera node (node 0); its clip planes are set in finish().
        gltfjson::Node& node = b.nodes.emplace_back();
        node.name = "camera";
        node.camera = 0;
        node.has_translation = node.has_rotation = true;
        node.translation[0] = info.camera.position.x;
        node.translation[1] = info.camera.position.y;
        node.translation[2] = info.camera.position.z;
        const std::vector<double> q = cameraRotation(info.camera);
        std::copy(q.begin(), q.end(), node.rotation);
        scene_nodes.push_back(0);
        if (options.draco) extensions.push_back("KHR_draco_mesh_compression");
        if (options.meshopt)
            for (const char* e : {"EXT_meshopt_compression", "KHR_mesh_quantization"}) extensions.push_back(e);
        compression = options.draco ? Compression::draco : options.meshopt ? Compression::meshopt : Compression::none;
        previous.resize(info.objects.size());
    }

    // Step: frame k's node (node 1 + k), given each object's primitive data (empty: not shown).
    // The scene's own objects go into the frame node's mesh; reflections (ExportObject::mirror)
    // into one mesh per mirror, whose child node of the frame node is made in finish(), after all
    // frame nodes, so that frame k stays node 1 + k. Meshes are numbered in frame order either way.
    // `scale`: the frame node's scale while shown (meshopt: the quantization step, else 1).
    // `meshopt`: the frame's encoded vertex stream (with meshopt compression).
    bool addFrame(const ExportFrame& f, const std::vector<PrimitiveData>& data, const double origin[3], double scale,
                  const MeshoptFrame* meshopt, GlbStats* stats, std::string* error) {
        gltfjson::Node node;
        if (previous.size() < f.objects.size()) previous.resize(f.objects.size());
        node.name = frameName(f.index);
        // Step: the objects' groups in order: -1 (the frame node) first, then mirrors as they appear.
        std::vector<int> groups;
        for (size_t o = 0; o < f.objects.size(); ++o) {
            if (f.objects[o].triangles.empty()) continue;
            const int g = groupOf(o);
            if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
        }
        std::stable_partition(groups.begin(), groups.end(), [](int g) { return g < 0; });
        // Step: which objects share the previous frame's index list (the same list as cut, and the
        // same vertex count): their primitives refer to its accessor.
        std::vector<int> shared(f.objects.size(), -1);
        for (size_t o = 0; o < f.objects.size(); ++o) {
            const Previous& prev = previous[o];
            if (compression != Compression::draco && !f.objects[o].triangles.empty() && prev.accessor >= 0 &&
                prev.same(data[o]))
                shared[o] = prev.accessor;
        }
        // Step (meshopt): a frame that continues the open run becomes a morph target of its mesh.
        if (compression == Compression::meshopt && meshopt) {
            std::string target_error;
            if (morphTarget(f, data, scale, *meshopt, shared, groups, &target_error)) {
                morph_nodes.push_back({b.nodes.size(), run.targets, runs.size() - 1});
                node.mesh = run.mesh;
                return endFrame(f, &node, origin, scale);
            }
            if (!target_error.empty()) {
                *error = target_error;
                return false;
            }
        }
        // Step (meshopt): the frame's vertex and normal views, and one index view for the objects
        // that do not share, uint16 unless one of them has more than 65535 vertices.
        int vview = -1, nview = -1;
        std::vector<int> meshopt_indices(f.objects.size(), -1);
        if (compression == Compression::meshopt && meshopt && meshopt->count > 0) {
            vview = meshopt->remote ? b.addMeshoptView(meshopt->remote_encoded, meshopt->count, meshopt->stride, false)
                                    : b.addMeshoptView(meshopt->encoded, meshopt->count, meshopt->stride, false);
            if (!meshopt->normals_inline)
                nview = meshopt->remote ? b.addMeshoptView(meshopt->remote_normals, meshopt->count, kMeshoptNormalStride,
                                                           false, true)
                                        : b.addMeshoptView(meshopt->encoded_normals, meshopt->count, kMeshoptNormalStride,
                                                           false, true);
            size_t size = 2, count = 0, most = 0;
            bool none_shared = true;
            std::vector<size_t> first(f.objects.size(), 0);
            for (size_t o = 0; o < f.objects.size(); ++o)
                if (!f.objects[o].triangles.empty() && shared[o] < 0) {
                    most = std::max(most, data[o].packedVertices(layout.stride));
                    first[o] = count;
                    count += data[o].orderedCount();
                } else if (!f.objects[o].triangles.empty()) {
                    none_shared = false;
                }
            if (most > 65535) size = 4;
            if (count > 0) {
                int iview = -1;
                if (meshopt->remote && none_shared) {
                    // Every shown object's indices: the stream the other process encoded.
                    iview = b.addMeshoptView(meshopt->remote_indices, count, size, true);
                } else {
                    // Some objects share theirs (by reference: their lists read back from the spill).
                    std::vector<unsigned int> all;
                    all.reserve(count);
                    for (size_t o = 0; o < f.objects.size(); ++o)
                        if (!f.objects[o].triangles.empty() && shared[o] < 0 &&
                            !appendOrdered(data[o], &all, error))
                            return false;
                    std::vector<unsigned char> encoded;
                    encodeIndexStream(all, most, &encoded);
                    iview = b.addMeshoptView(encoded, all.size(), size, true);
                }
                for (size_t o = 0; o < f.objects.size(); ++o)
                    if (!f.objects[o].triangles.empty() && shared[o] < 0) {
                        meshopt_indices[o] = b.addAccessor(iview,
                                                           size == 2 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT
                                                                     : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                                           false, data[o].orderedCount(), first[o] * size);
                    }
            }
        }
        std::vector<bool> shown(f.objects.size(), false);
        for (const int group : groups) {
            gltfjson::Mesh mesh;
            mesh.name = group < 0 ? node.name : reflectionName(node.name, mirrorName(group));
            for (size_t o = 0; o < f.objects.size(); ++o) {
                if (f.objects[o].triangles.empty() || groupOf(o) != group) continue;
                gltfjson::Primitive prim;
                Previous& prev = previous[o];
                if (compression == Compression::draco) {
                    double qerr = 0;
                    if (!b.dracoPrimitive(data[o], &prim, &qerr, error)) {
                        *error = mesh.name + ": " + *error;
                        return false;
                    }
                    stats->max_quantization_error = std::max(stats->max_quantization_error, qerr);
                } else if (compression == Compression::meshopt) {
                    prim = b.meshoptPrimitive(data[o], layout, meshopt->stride, vview, nview, meshopt->first[o],
                                              shared[o] >= 0 ? shared[o] : meshopt_indices[o]);
                } else {
                    prim = b.plainPrimitive(data[o], shared[o]);
                }
                if (compression != Compression::draco && shared[o] < 0) prev.take(prim.indices, data[o], borrow_indices);
                shown[o] = true;
                prim.material = o < info.objects.size() ? int(o) : -1;
                mesh.primitives.push_back(std::move(prim));
            }
            b.meshes.push_back(std::move(mesh));
            if (group < 0)
                node.mesh = int(b.meshes.size()) - 1;
            else
                reflections.push_back({frames, mirrorName(group), int(b.meshes.size()) - 1});
        }
        // Sharing is between consecutive frames: an object not shown forgets its index list.
        for (size_t o = 0; o < f.objects.size(); ++o)
            if (!shown[o]) previous[o] = Previous();
        // Step (meshopt): the frame opens a run when later frames may become its morph targets.
        run.mesh = -1;
        if (compression == Compression::meshopt && meshopt && meshopt->count > 0) startRun(f, data, scale, *meshopt, groups, node.mesh);
        if (groups.empty()) return endFrame(f, &node, nullptr, scale);
        return endFrame(f, &node, origin, scale);
    }

    // The frame node's transform, its scale channel's value and the frame's extras (any frame).
    bool endFrame(const ExportFrame& f, gltfjson::Node* node, const double* origin, double scale) {
        // Reflections are relative to the same origin: their child nodes need no transform.
        if (origin) {
            node->has_translation = true;
            std::copy(origin, origin + 3, node->translation);
        }
        const double s = frames == 0 ? scale : 0.0;
        node->has_scale = true;
        node->scale[0] = node->scale[1] = node->scale[2] = s;
        frame_scales.push_back(float(scale));
        b.nodes.push_back(std::move(*node));
        scene_nodes.push_back(int(b.nodes.size()) - 1);
        frame_times.push_back(f.t_c);
        if (frames == 0) first_frame = f.index;
        ++frames;
        return true;
    }

    // Frame coherence (gltf.h). The objects a frame shows, in order.
    static std::vector<size_t> shownObjects(const ExportFrame& f) {
        std::vector<size_t> objects;
        for (size_t o = 0; o < f.objects.size(); ++o)
            if (!f.objects[o].triangles.empty()) objects.push_back(o);
        return objects;
    }

    // Opens a run at the frame just made (its mesh `mesh`) when its layout allows morph targets:
    // records without --attributes or --shade doppler, no reflections. Keeps the frame's records
    // and its normals as a reader decodes them (the octahedral view's int8 output, or the record's).
    void startRun(const ExportFrame& f, const std::vector<PrimitiveData>& data, double step, const MeshoptFrame& mf,
                  const std::vector<int>& groups, int mesh) {
        if (layout.stride != 12 || groups.size() != 1 || groups[0] >= 0 || mesh < 0) return;
        const size_t limit = std::min(kMorphTargetsMost, kMorphVertexTargets / mf.count);
        if (limit == 0) return;
        run.objects = shownObjects(f);
        if (mf.remote) {
            // By reference the records stay where the frame was cut, which made the next frame's target.
            if (!mf.remote_run) return;
        } else {
            std::vector<const PrimitiveData*> shown;
            for (const size_t o : run.objects) shown.push_back(&data[o]);
            if (!runReference(shown, mf.count, mf.normals_inline, true, &run.records, &run.normals)) return;
        }
        run.mesh = mesh;
        run.step = step;
        run.normals_inline = mf.normals_inline;
        run.count = mf.count;
        run.limit = limit;
        run.targets = 0;
        runs.push_back(0);
    }

    // Makes the frame a morph target of the open run's mesh when it continues the run: the same
    // objects alone (no reflections), each with the previous frame's index list, the same step
    // and vertex count, room for a target, and every difference from the previous frame held by
    // the target's record (int16 steps, an emission time difference exact in float32, int8
    // normal steps). Returns false, having changed nothing, otherwise.
    bool morphTarget(const ExportFrame& f, const std::vector<PrimitiveData>& data, double step, const MeshoptFrame& mf,
                     const std::vector<int>& shared, const std::vector<int>& groups, std::string* error) {
        if (run.mesh < 0 || step != run.step || mf.count != run.count || run.targets >= run.limit) return false;
        if (groups.size() != 1 || groups[0] >= 0) return false;
        const std::vector<size_t> objects = shownObjects(f);
        if (objects != run.objects) return false;
        for (const size_t o : objects)
            if (shared[o] < 0) return false;
        std::vector<size_t> first;
        int lo[3], hi[3];
        int view = -1;
        if (mf.remote) {
            // Made where the frame was cut, against the previous frame's records (runReference).
            if (!mf.targets) {
                *error = "internal: frame " + std::to_string(f.index) + " by reference without its morph target";
                return false;
            }
            const MeshoptFrame::RemoteTarget& t = mf.remote_target[run.targets == 0 && !run.normals_inline ? 0 : 1];
            if (!t.fits) return false;
            size_t v = 0;
            for (const size_t o : objects) {
                first.push_back(v);
                v += data[o].packedVertices(12);
            }
            if (v != run.count) return false;
            std::copy(t.lo, t.lo + 3, lo);
            std::copy(t.hi, t.hi + 3, hi);
            view = b.addMeshoptView(t.encoded, run.count, kMorphStride, false);
        } else {
            std::vector<const PrimitiveData*> shown;
            for (const size_t o : objects) shown.push_back(&data[o]);
            std::vector<unsigned char>& rec = morph_records;
            if (!morphRecords(shown, run.records, run.normals, run.count, &rec, &first, lo, hi)) return false;
            view = b.addMeshoptView(encodeMorphRecords(rec, run.count), run.count, kMorphStride, false);
        }
        // Per primitive the target's three accessors.
        gltfjson::Mesh& mesh = b.meshes[size_t(run.mesh)];
        const double lo_d[3] = {double(lo[0]), double(lo[1]), double(lo[2])};
        const double hi_d[3] = {double(hi[0]), double(hi[1]), double(hi[2])};
        for (size_t j = 0; j < objects.size(); ++j) {
            const size_t nv = data[objects[j]].packedVertices(12);
            const size_t at = first[j] * kMorphStride;
            // POSITION's bounds (required) are the whole frame's: a bound of every primitive's.
            std::array<int, gltfjson::kAttributes>& target = mesh.primitives[j].targets.emplace_back();
            target.fill(-1);
            target[gltfjson::kPosition] = b.addAccessor(view, TINYGLTF_COMPONENT_TYPE_SHORT, true, nv, at, lo_d, hi_d, 3);
            target[gltfjson::kEmissionTime] = b.addAccessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, false, nv, at + 8);
            target[gltfjson::kNormal] = b.addNormalized(view, TINYGLTF_COMPONENT_TYPE_BYTE, true, nv, at + 12);
        }
        // The frame is now the run's reference for the next one.
        size_t v = 0;
        for (const size_t o : objects) {
            if (mf.remote) break;
            const PrimitiveData& d = data[o];
            std::memcpy(&run.records[12 * v], d.packed.data(), d.packed.size());
            std::memcpy(&run.normals[4 * v], d.packed_snorm.data(), d.packed_snorm.size());
            v += d.packed.size() / 12;
        }
        ++run.targets;
        runs.back() = run.targets;
        return true;
    }

    // "frame_00042 mirror backdrop": the node (and mesh) of frame 42's reflections in mirror "backdrop".
    static std::string reflectionName(const std::string& frame, const std::string& mirror) {
        return frame + " mirror " + mirror;
    }
    int groupOf(size_t object) const { return object < info.objects.size() ? info.objects[object].mirror_index : -1; }
    // The name of mirror `index` (of its first reflection), or "#index" when it has none.
    std::string mirrorName(int index) const {
        for (const ExportObject& o : info.objects)
            if (o.mirror_index == index && !o.mirror.empty()) return o.mirror;
        return "#" + std::to_string(index);
    }

    // Step: what needs the whole sequence: the camera's clip planes, the animation (at most 3 keys
    // per channel), the scene extras. Returns the JSON chunk's text.
    std::string finish(double far) {
        // Clip planes in light-seconds: 1e-3 of, and 10 times, the farthest apparent point's
        // distance (the validator requires zfar > znear).
        far = far > 0 ? far : 1.0;

        // STEP scale channels, at most 3 keys each so the file grows linearly with the frame
        // count: scale 0 until k/fps, 1 during frame k, 0 from (k+1)/fps on. The last frame keeps
        // scale 1 at the final key n/fps, which closes the sequence so that it lasts 1/fps too
        // (with one key per frame the last frame would have zero length).
        // All key times in one view, the distinct scale sequences (a handful: frame scales repeat)
        // in another, each channel's accessors pointing into them.
        const size_t n = frames;
        std::vector<float> all_times, all_scales;
        std::vector<std::pair<size_t, size_t>> time_keys(n);  // offset (floats) and count per frame
        std::vector<size_t> scale_key(n);                   // offset (floats) of the frame's scales
        std::map<std::vector<float>, size_t> distinct;
        std::vector<float> scales;
        for (size_t k = 0; k < n; ++k) {
            scales.clear();
            time_keys[k] = {all_times.size(), 0};
            auto key = [&](size_t i, float v) {
                all_times.push_back(float(double(i) / info.fps));
                scales.insert(scales.end(), {v, v, v});
                ++time_keys[k].second;
            };
            const float shown = frame_scales[k];
            if (k > 0) key(0, 0.0f);
            key(k, shown);
            key(k + 1, k + 1 == n ? shown : 0.0f);
            auto it = distinct.find(scales);
            if (it == distinct.end()) {
                it = distinct.emplace(scales, all_scales.size()).first;
                all_scales.insert(all_scales.end(), scales.begin(), scales.end());
            }
            scale_key[k] = it->second;
        }
        const int times_view = b.addView(all_times.data(), all_times.size() * 4, 0);
        const int scales_view = b.addView(all_scales.data(), all_scales.size() * 4, 0);
        std::map<size_t, int> scale_accessors;  // by offset
        std::vector<std::pair<int, int>> samplers(n);  // per frame, its input and output accessors
        for (size_t k = 0; k < n; ++k) {
            const auto [offset, count] = time_keys[k];
            const double lo = all_times[offset], hi = all_times[offset + count - 1];
            samplers[k].first =
                b.addAccessor(times_view, TINYGLTF_COMPONENT_TYPE_FLOAT, false, count, 4 * offset, &lo, &hi, 1);
            auto sa = scale_accessors.find(scale_key[k]);
            if (sa == scale_accessors.end())
                sa = scale_accessors
                         .emplace(scale_key[k], b.addAccessor(scales_view, TINYGLTF_COMPONENT_TYPE_FLOAT, true, count,
                                                              4 * scale_key[k]))
                         .first;
            samplers[k].second = sa->second;
        }

        // Step: the reflections' nodes, children of their frame nodes (so shown and hidden with them).
        for (const Reflection& r : reflections) {
            gltfjson::Node child;
            child.name = reflectionName(b.nodes[1 + r.frame].name, r.mirror);
            child.mesh = r.mesh;
            child.has_mirror = true;
            child.mirror = r.mirror;
            b.nodes.push_back(std::move(child));
            b.nodes[1 + r.frame].children.push_back(int(b.nodes.size()) - 1);
        }
        // The target frames' weights: the first `place` of the run's targets at 1 (cumulative
        // differences), written as integers.
        for (const MorphNode& m : morph_nodes) {
            std::vector<int>& w = b.nodes[m.node].weights;
            w.assign(runs[m.run], 0);
            std::fill(w.begin(), w.begin() + std::ptrdiff_t(m.place), 1);
        }

        // The JSON, its keys in byte order at every level (gltf_json.h).
        gltfjson::Text t;
        t.out.reserve(256 * (b.accessors.size() + b.views.size() + b.nodes.size()) + 1024);
        auto array = [&t](const char* key, const auto& records) {
            if (records.empty()) return;
            t.key(key);
            t.open('[');
            for (const auto& r : records) gltfjson::write(&t, r);
            t.close(']');
        };
        auto strings = [&t](const char* key, const std::vector<std::string>& list) {
            if (list.empty()) return;
            t.key(key);
            t.open('[');
            for (const std::string& s : list) t.value(s);
            t.close(']');
        };
        auto numbers = [&t](const char* key, const double* v, size_t count) {
            t.key(key);
            t.open('[');
            for (size_t i = 0; i < count; ++i) t.value(v[i]);
            t.close(']');
        };
        t.open('{');
        array("accessors", b.accessors);
        // One animation "frames" of STEP scale channels.
        t.key("animations");
        t.open('[');
        t.open('{');
        t.key("channels");
        t.open('[');
        for (size_t k = 0; k < n; ++k) {
            t.open('{');
            t.key("sampler");
            t.value(uint64_t(k));
            t.key("target");
            t.open('{');
            t.key("node");
            t.value(uint64_t(1 + k));
            t.key("path");
            t.value("scale");
            t.close('}');
            t.close('}');
        }
        t.close(']');
        t.key("name");
        t.value("frames");
        t.key("samplers");
        t.open('[');
        for (const auto& [input, output] : samplers) {
            t.open('{');
            t.key("input");
            t.value(input);
            t.key("interpolation");
            t.value("STEP");
            t.key("output");
            t.value(output);
            t.close('}');
        }
        t.close(']');
        t.close('}');
        t.close(']');
        t.key("asset");
        t.open('{');
        t.key("generator");
        t.value("apparent");
        t.key("version");
        t.value("2.0");
        t.close('}');
        array("bufferViews", b.views);
        // Buffer 0: the GLB BIN chunk (its size: what the sink received); with meshopt buffer 1,
        // the fallback buffer without data.
        t.key("buffers");
        t.open('[');
        t.open('{');
        t.key("byteLength");
        t.value(uint64_t(b.sinkSize()));
        t.close('}');
        if (std::any_of(b.views.begin(), b.views.end(), [](const gltfjson::BufferView& v) { return v.meshopt; })) {
            t.open('{');
            t.key("byteLength");
            t.value(uint64_t(b.fallback_size));
            t.key("extensions");
            t.open('{');
            t.key("EXT_meshopt_compression");
            t.open('{');
            t.key("fallback");
            t.value(true);
            t.close('}');
            t.close('}');
            t.close('}');
        }
        t.close(']');
        t.key("cameras");
        t.open('[');
        t.open('{');
        t.key("perspective");
        t.open('{');
        const double yfov = info.camera.fov_deg * mesh4d::kPi / 180.0;
        if (yfov > 0) {
            t.key("yfov");
            t.value(yfov);
        }
        t.key("zfar");
        t.value(10 * far);
        t.key("znear");
        t.value(1e-3 * far);
        t.close('}');
        t.key("type");
        t.value("perspective");
        t.close('}');
        t.close(']');
        strings("extensionsRequired", extensions);
        strings("extensionsUsed", extensions);
        // One material per object: a thin shell seen from both sides (the flanges), blended
        // when not opaque (e.g. a mirror, to show the reflections behind it). With --shade
        // doppler COLOR_0 holds the whole shaded colour (glTF multiplies it with the factor): a
        // white factor, the plain colour kept in extras for viewers that switch between the two.
        if (!info.objects.empty()) {
            t.key("materials");
            t.open('[');
            for (const ExportObject& o : info.objects) {
                t.open('{');
                if (o.base_color[3] < 1) {
                    t.key("alphaMode");
                    t.value("BLEND");
                }
                t.key("doubleSided");
                t.value(true);
                const double plain[4] = {o.base_color[0], o.base_color[1], o.base_color[2], o.base_color[3]};
                const double white[4] = {1.0, 1.0, 1.0, o.base_color[3]};
                if (shade_doppler) {
                    t.key("extras");
                    t.open('{');
                    numbers("base_color", plain, 4);
                    t.close('}');
                }
                if (!o.name.empty()) {
                    t.key("name");
                    t.value(o.name);
                }
                t.key("pbrMetallicRoughness");
                t.open('{');
                const double* factor = shade_doppler ? white : plain;
                // glTF's default factor (1, 1, 1, 1) is left out.
                if (std::any_of(factor, factor + 4, [](double c) { return !(std::fabs(c - 1.0) < 1e-12); }))
                    numbers("baseColorFactor", factor, 4);
                t.key("metallicFactor");
                t.value(0.0);
                t.key("roughnessFactor");
                t.value(0.8);
                t.close('}');
                t.close('}');
            }
            t.close(']');
        }
        array("meshes", b.meshes);
        array("nodes", b.nodes);
        t.key("scene");
        t.value(0);
        // Scene extras: what was computed, in which units, at which camera times.
        t.key("scenes");
        t.open('[');
        t.open('{');
        t.key("extras");
        t.open('{');
        t.key("first_frame");
        t.value(int64_t(int(first_frame)));
        t.key("fps");
        t.value(info.fps);
        t.key("frame_times");
        t.open('[');
        for (const double time : frame_times) t.value(time);
        t.close(']');
        t.key("model");
        t.value(info.model);
        t.key("objects");
        t.open('[');
        for (const ExportObject& o : info.objects) t.value(o.name);
        t.close(']');
        t.key("scene_file");
        t.value(info.scene_path);
        t.key("tolerance");
        t.value(info.tolerance);
        t.key("units");
        t.value("light-seconds, seconds, c = 1");
        t.close('}');
        if (!info.model.empty()) {
            t.key("name");
            t.value(info.model);
        }
        t.key("nodes");
        t.open('[');
        for (const int node : scene_nodes) t.value(node);
        t.close(']');
        t.close('}');
        t.close(']');
        t.close('}');
        return std::move(t.out);
    }

    const SequenceInfo& info;
    GlbBuilder b;
    MeshoptLayout layout;  // with meshopt: the vertex record
    bool shade_doppler = false;
    std::vector<std::string> extensions;  // used and required
    std::vector<int> scene_nodes;
    std::vector<double> frame_times;
    std::vector<float> frame_scales;  // per frame, its node's scale while shown
    long long first_frame = 0;
    size_t frames = 0;
    enum class Compression { none, draco, meshopt } compression = Compression::none;
    // Per object, its index list in the previous frame and the accessor holding it (-1: none).
    // Frames by reference compare the lists' hashes (indexHash), frames of this process the lists.
    // An object's index list in the last frame. Copied, or only pointed to while its frame is
    // held in place (borrow_indices: the writer's first frame, BinSink::pinned), so that a lone
    // frame never copies it; keepPrevious() copies it before that frame is let go.
    struct Previous {
        int accessor = -1;
        size_t vertices = 0;
        std::vector<uint32_t> indices;
        const std::vector<uint32_t>* borrowed = nullptr;  // instead of `indices`
        bool remote = false;
        uint64_t count = 0, hash[2] = {0, 0};
        bool same(const PrimitiveData& d) const {
            if (vertices != d.vertexCount() || remote != d.remote.on) return false;
            if (!remote) return (borrowed ? *borrowed : indices) == d.indices;
            return count == d.remote.index_count && hash[0] == d.remote.index_hash[0] && hash[1] == d.remote.index_hash[1];
        }
        void take(int accessor_, const PrimitiveData& d, bool borrow) {
            accessor = accessor_;
            vertices = d.vertexCount();
            remote = d.remote.on;
            borrowed = nullptr;
            if (remote) {
                indices.clear();
                count = d.remote.index_count;
                hash[0] = d.remote.index_hash[0];
                hash[1] = d.remote.index_hash[1];
            } else if (borrow) {
                borrowed = &d.indices;
            } else {
                indices = d.indices;
            }
        }
        void keep() {
            if (borrowed) indices = *borrowed;
            borrowed = nullptr;
        }
    };
    std::vector<Previous> previous;
    bool borrow_indices = false;  // the frame being added is held in place until keepPrevious()
    void keepPrevious() {
        for (Previous& p : previous) p.keep();
    }
    struct Reflection {
        size_t frame;        // frame node 1 + frame is the parent
        std::string mirror;  // the mirror's name
        int mesh;
    };
    std::vector<Reflection> reflections;
    // Frame coherence (meshopt): the open run (mesh < 0: none), each run's target count, and the
    // frame nodes that are targets (node index, place in the run: its first `place` weights are 1).
    struct Run {
        int mesh = -1;
        double step = 0;
        size_t count = 0, targets = 0, limit = 0;
        bool normals_inline = false;  // the run's first frame's normals were in its records
        std::vector<size_t> objects;
        std::vector<unsigned char> records;  // the last frame's records (int16 x, y, z, 0 | float32 time)
        std::vector<unsigned char> normals;  // the last frame's normals as decoded (int8 x, y, z, w)
    } run;
    std::vector<size_t> runs;
    struct MorphNode {
        size_t node, place, run;
    };
    std::vector<MorphNode> morph_nodes;
    std::vector<unsigned char> morph_records;  // scratch
};

size_t padded4(size_t n) { return (n + 3) / 4 * 4; }

// Appends `n` bytes of `in` from `offset` to `out` (at its position) by copy_file_range (the kernel
// copies between the two files' pages, no trip through a user buffer); where it cannot (another
// file system, an old kernel), by pread and write. False with a message.
bool copyRange(int in, uint64_t offset, uint64_t n, int out, std::string* error) {
    if (n == 0) return true;
    if (in < 0) {
        *error = "internal: frame data from an unknown process";
        return false;
    }
    uint64_t off = 0;
    while (off < n) {
        loff_t at = loff_t(offset + off);
        const ssize_t r = ::copy_file_range(in, &at, out, nullptr, size_t(n - off), 0);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;  // the fallback below takes over from `off`
        off += uint64_t(r);
    }
    std::vector<char> chunk(off < n ? size_t(1) << 20 : 0);
    while (off < n) {
        const ssize_t r = ::pread(in, chunk.data(), size_t(std::min<uint64_t>(chunk.size(), n - off)), off_t(offset + off));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) {
            *error = std::string("cannot read back the spill file: ") + std::strerror(r < 0 ? errno : EIO);
            return false;
        }
        if (!writeAll(out, chunk.data(), size_t(r), error)) return false;
        off += uint64_t(r);
    }
    return true;
}

}  // namespace

struct GlbFrameData : PreparedFrame, std::enable_shared_from_this<GlbFrameData> {
    // The buffers whose bytes may go into the file as they are (BinSink::borrowable).
    std::vector<std::pair<const char*, const char*>> buffers() const {
        std::vector<std::pair<const char*, const char*>> out;
        auto add = [&](const auto& v) {
            if (v.empty()) return;
            const char* p = reinterpret_cast<const char*>(v.data());
            out.emplace_back(p, p + v.size() * sizeof(v[0]));
        };
        add(meshopt.encoded);
        add(meshopt.encoded_normals);
        for (const PrimitiveData& d : data) {
            for (const auto* v : {&d.positions, &d.normals, &d.emission, &d.doppler, &d.proper_time, &d.colors}) add(*v);
            add(d.indices);
            add(d.packed);
            add(d.packed_normals);
            add(d.packed_snorm);
            add(d.draco.bytes);
        }
        return out;
    }
    // For a frame of `objects` objects, keeping every vector's capacity.
    void reset(size_t objects) {
        origin[0] = origin[1] = origin[2] = 0;
        step = 0;
        clamped = false;
        meshopt.encoded.clear();
        meshopt.encoded_normals.clear();
        meshopt.count = 0;
        meshopt.first.clear();
        meshopt.remote = false;
        data.resize(objects);
        for (PrimitiveData& p : data) {
            // The float32 arrays and the index list keep their size: prepare() empties those of
            // the objects not shown, toPrimitive() sizes the others (no zero fill unless they grow).
            p.bounded = false;
            p.ordered.reset();
            p.draco.bytes.clear();
            p.draco.error.clear();
            p.packed.clear();
            p.packed_normals.clear();
            p.packed_snorm.clear();
            p.remote = PrimitiveData::Remote();
        }
        far = max_extent = max_float_error = max_quantization_error = 0;
    }
    double origin[3] = {0, 0, 0};
    double step = 0;       // meshopt: the quantization step (0 without meshopt)
    bool clamped = false;  // meshopt: the step grew to fit int16
    MeshoptFrame meshopt;  // with meshopt: the frame's encoded vertex streams
    std::vector<PrimitiveData> data;  // per object; empty when it shows nothing
    double far = 0, max_extent = 0, max_float_error = 0, max_quantization_error = 0;
};

// What prepare() needs only while it runs (the crease split's work and map, meshopt's vectors): as
// many sets as prepare() calls run at once, not one per frame held in flight, taken from a pool
// of their own (their capacity kept, and the crease split's adjacency reused for the same
// triangles). At 1M triangles a set is about 130 MB.
struct PrepareScratch {
    std::vector<mesh4d::CreaseMap> crease_map;  // per object
    std::vector<mesh4d::CreaseWork> crease_work;
    MeshoptScratch meshopt;
};

// Frame buffers given back by released GlbFrameData, shared by every writer of the process (and
// with the deleters, so it outlives them): a frame written alone to its own file, or the next
// model's sequence, reuses the buffers of the last one instead of allocating and touching fresh
// memory. It keeps at most poolFrames() frames' buffers (as many as the frame loop holds in
// flight); more are freed when given back.
struct FramePool {
    std::mutex mutex;
    std::vector<std::unique_ptr<GlbFrameData>> free;
    std::vector<std::unique_ptr<PrepareScratch>> scratch;  // likewise, at most poolFrames()
};
size_t poolFrames() { return std::max<size_t>(4, 2 * size_t(std::thread::hardware_concurrency())); }
std::shared_ptr<FramePool> processFramePool() {
    static const std::shared_ptr<FramePool> pool = std::make_shared<FramePool>();
    return pool;
}

struct GlbSequenceWriter::Impl {
    Impl(const std::string& p, const SequenceInfo& i, const GlbOptions& o)
        : path(p), info(i), options(o), model(info, options, &sink) {
        sink.dir = std::filesystem::path(p).parent_path().string();
        sink.holding = true;  // the first frame (BinSink)
        count_only.counting = true;
        if (options.draco || options.meshopt) {
            GlbOptions plain_options = options;
            plain_options.draco = plain_options.meshopt = false;
            plain = std::make_unique<SequenceModel>(info, plain_options, &count_only);
        }
    }
    ~Impl() {
        if (sink.fd >= 0) ::close(sink.fd);
        releaseUsed();
    }
    // Frames by reference: the ranges of the frame sources this sequence used, freed once read.
    void use(const FileSpan& s) {
        if (s.length == 0) return;
        auto [it, added] = used.emplace(s.source, std::make_pair(s.offset, s.offset + s.length));
        if (!added) {
            it->second.first = std::min(it->second.first, s.offset);
            it->second.second = std::max(it->second.second, s.offset + s.length);
        }
    }
    void releaseUsed() {
        for (const auto& [source, range] : used) releaseFrameData({source, range.first, range.second - range.first});
        used.clear();
    }

    std::string path;
    SequenceInfo info;
    GlbOptions options;
    BinSink sink, count_only;
    SequenceModel model;
    std::unique_ptr<SequenceModel> plain;  // with Draco or meshopt: the same sequence without it, counted
    GlbStats stats;
    double far = 0;
    std::shared_ptr<FramePool> pool = processFramePool();
    std::map<int32_t, std::pair<uint64_t, uint64_t>> used;  // per frame source: [first, end) read from it
};

GlbSequenceWriter::GlbSequenceWriter(const std::string& path, const SequenceInfo& info, const GlbOptions& options)
    : impl_(std::make_unique<Impl>(path, info, options)) {}

GlbSequenceWriter::~GlbSequenceWriter() = default;


namespace {

// The meshopt quantization step of a frame of largest extent `extent` (gltf.h): from the
// tolerance (T / sqrt(3)), from `bits` (E / (2^bits - 2)), or 14 bits over E in vertex mode; at
// least E / 65534 so that every coordinate fits int16 (*clamped says when that decided). In
// vertex mode at least 14 bits over E (Draco's and gltfpack's default): E / 16382 rounded down to
// a power of 2^(1/4) (at most 19% finer), so that frames of slightly different extents share the
// step and can be morph targets of one another (gltf.h). A quarter octave: a power of two cost the
// Duck (clipped, so no morph targets) 2% against 0.3%, and an eighth of one the torus 6% more.
double meshoptStep(double extent, double tolerance, int bits, bool* clamped) {
    const double finest = extent / 65534.0;
    double step = bits > 0        ? extent / (std::ldexp(1.0, bits) - 2)
                  : tolerance > 0 ? tolerance / std::sqrt(3.0)
                                  : std::exp2(std::floor(4 * std::log2(extent / 16382.0)) / 4);
    *clamped = step < finest;  // only a tolerance can ask for more than int16 holds
    if (*clamped) step = finest;
    if (!(step > 0)) step = 1;  // every point at the origin: any step is exact
    return step;
}

}  // namespace

std::shared_ptr<GlbFrameData> GlbSequenceWriter::prepare(const ExportFrame& f, bool streams) const {
    // Step: a frame's buffers from the process's pool (they keep their capacity: a sequence does
    // not allocate again frame after frame, nor a lone frame after the first); the shared pointer
    // gives them back when released.
    std::shared_ptr<FramePool> pool = impl_->pool;
    GlbFrameData* raw = nullptr;
    {
        std::lock_guard<std::mutex> lock(pool->mutex);
        if (!pool->free.empty()) {
            raw = pool->free.back().release();
            pool->free.pop_back();
        }
    }
    if (!raw) raw = new GlbFrameData;
    std::shared_ptr<GlbFrameData> d(raw, [pool](GlbFrameData* back) {
        std::unique_ptr<GlbFrameData> owned(back);
        std::lock_guard<std::mutex> lock(pool->mutex);
        if (pool->free.size() < poolFrames()) pool->free.push_back(std::move(owned));
    });
    d->reset(f.objects.size());
    for (size_t o = 0; o < f.objects.size(); ++o)
        if (f.objects[o].triangles.empty()) d->data[o].clearArrays();  // not shown: no data
    std::unique_ptr<PrepareScratch> scratch;
    {
        std::lock_guard<std::mutex> lock(pool->mutex);
        if (!pool->scratch.empty()) {
            scratch = std::move(pool->scratch.back());
            pool->scratch.pop_back();
        }
    }
    if (!scratch) scratch = std::make_unique<PrepareScratch>();
    struct GiveBack {  // the scratch back to the pool however prepare() ends
        FramePool* pool;
        std::unique_ptr<PrepareScratch>* scratch;
        ~GiveBack() {
            std::lock_guard<std::mutex> lock(pool->mutex);
            if (pool->scratch.size() < poolFrames()) pool->scratch.push_back(std::move(*scratch));
        }
    } give_back{pool.get(), &scratch};
    scratch->crease_map.resize(f.objects.size());
    scratch->crease_work.resize(f.objects.size());
    scratch->meshopt.orders.resize(f.objects.size());
    // Step: the frame's origin (the centre of its bounding box) and the far distance (parallel
    // minima and maxima: exact in any order). The far distance is the largest norm() (hypot) of
    // any point, but norm() is taken only where the squared distance comes within 1e-9 of the
    // largest so far: the point of largest norm() always does (the two agree to a few ulps).
    mesh4d::EventBox box;
    const Vec3 camera = impl_->info.camera.position;
    for (const auto& o : f.objects) {
        struct Extremes {
            mesh4d::EventBox box;
            double far = 0, far2 = 0;
        };
        const Extremes e = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, o.positions.size(), 16384), Extremes{},
            [&](const tbb::blocked_range<size_t>& r, Extremes x) {
                for (size_t i = r.begin(); i < r.end(); ++i) {
                    const Vec3 p = o.absolutePosition(i);
                    const Vec3 to = p - camera;
                    const double d2 = mesh4d::dot(to, to);
                    if (d2 >= x.far2 * (1 - 1e-9)) {
                        x.far = std::max(x.far, mesh4d::norm(to));
                        x.far2 = std::max(x.far2, d2);
                    }
                    x.box.addPoint(p);
                }
                return x;
            },
            [](Extremes a, const Extremes& b) {
                a.box.addPoint(b.box.lo);
                a.box.addPoint(b.box.hi);
                a.far = std::max(a.far, b.far);
                a.far2 = std::max(a.far2, b.far2);
                return a;
            });
        d->far = std::max(d->far, e.far);
        if (!o.positions.empty()) {
            box.addPoint(e.box.lo);
            box.addPoint(e.box.hi);
        }
    }
    const Vec3 center = box.center();
    for (int c = 0; c < 3; ++c) d->origin[c] = center[c];
    // Step: each object's float32 data with normals (crease split), relative to the origin.
    if (f.triangleCount() > 0) {
        d->max_extent = std::max(d->max_extent, box.extent());
        if (impl_->options.meshopt) {
            d->step = meshoptStep(box.extent(), impl_->info.tolerance, impl_->options.meshopt_bits, &d->clamped);
            d->max_quantization_error = std::sqrt(3.0) / 2 * d->step;
        }
        double worst_coordinate = 0;
        for (size_t o = 0; o < f.objects.size(); ++o)
            if (!f.objects[o].triangles.empty())
                toPrimitive(f.objects[o], d->origin, d->step, &d->max_float_error, &worst_coordinate, &d->data[o],
                            &scratch->crease_map[o], &scratch->crease_work[o], &scratch->meshopt,
                            &scratch->meshopt.orders[o], impl_->options,
                            impl_->info.objects[o].base_color);
        // Step (Draco): every shown primitive coded here, on the worker thread.
        if (impl_->options.draco)
            for (size_t o = 0; o < f.objects.size(); ++o)
                if (!f.objects[o].triangles.empty()) encodeDraco(d->data[o], impl_->options, &d->data[o].draco);
        if (impl_->options.meshopt && !streams) {
            // Records only (the frame before a frame encoded by reference): no streams.
            MeshoptFrame& mf = d->meshopt;
            mf.stride = MeshoptLayout(impl_->options).stride;
            mf.first.assign(f.objects.size(), 0);
            mf.count = 0;
            for (size_t o = 0; o < f.objects.size(); ++o) {
                mf.first[o] = mf.count;
                mf.count += d->data[o].packed.size() / mf.stride;
            }
        } else if (impl_->options.meshopt) {
            // Step: one vertex stream and one normal stream for the whole frame, encoded here (on the
            // worker thread).
            const size_t stride = MeshoptLayout(impl_->options).stride;
            MeshoptFrame& mf = d->meshopt;
            mf.first.assign(f.objects.size(), 0);
            std::vector<unsigned char>& all = scratch->meshopt.vertices;
            std::vector<unsigned char>& normals = scratch->meshopt.normal_stream;
            all.clear();
            normals.clear();
            for (size_t o = 0; o < f.objects.size(); ++o) {
                mf.first[o] = all.size() / stride;
                all.insert(all.end(), d->data[o].packed.begin(), d->data[o].packed.end());
                normals.insert(normals.end(), d->data[o].packed_normals.begin(), d->data[o].packed_normals.end());
            }
            mf.count = all.size() / stride;
            mf.encoded.resize(meshopt_encodeVertexBufferBound(mf.count, stride));
            mf.encoded.resize(meshopt_encodeVertexBuffer(mf.encoded.data(), mf.encoded.size(), all.data(), mf.count, stride));
            mf.encoded_normals.resize(meshopt_encodeVertexBufferBound(mf.count, kMeshoptNormalStride));
            mf.encoded_normals.resize(meshopt_encodeVertexBuffer(mf.encoded_normals.data(), mf.encoded_normals.size(),
                                                                 normals.data(), mf.count, kMeshoptNormalStride));
            // Step: the records with the int8 normals at their end, encoded too; the smaller wins
            // (the separate view counted with its JSON).
            const size_t wide = stride + 4;
            std::vector<unsigned char>& records = scratch->meshopt.inline_records;
            records.resize(mf.count * wide);
            size_t k = 0;
            for (size_t o = 0; o < f.objects.size(); ++o) {
                const PrimitiveData& p = d->data[o];
                for (size_t i = 0; i < p.packed.size() / stride; ++i, ++k) {
                    std::memcpy(&records[k * wide], &p.packed[i * stride], stride);
                    std::memcpy(&records[k * wide + stride], &p.packed_snorm[4 * i], 4);
                }
            }
            std::vector<unsigned char>& encoded_inline = scratch->meshopt.inline_encoded;
            encoded_inline.resize(meshopt_encodeVertexBufferBound(mf.count, wide));
            encoded_inline.resize(
                meshopt_encodeVertexBuffer(encoded_inline.data(), encoded_inline.size(), records.data(), mf.count, wide));
            mf.stride = stride;
            mf.normals_inline = encoded_inline.size() <= mf.encoded.size() + mf.encoded_normals.size() + kMeshoptViewJsonBytes;
            if (mf.normals_inline) {
                mf.encoded.swap(encoded_inline);
                mf.encoded_normals.clear();
                mf.stride = wide;
            }
        }
    }
    return d;
}

bool GlbSequenceWriter::add(const ExportFrame& f, std::string* error) { return add(f, *prepare(f), error); }

bool GlbSequenceWriter::add(const ExportFrame& f, const GlbFrameData& prepared, std::string* error) {
    Impl& m = *impl_;
    m.far = std::max(m.far, prepared.far);
    m.stats.max_extent = std::max(m.stats.max_extent, prepared.max_extent);
    m.stats.max_float_error = std::max(m.stats.max_float_error, prepared.max_float_error);
    const std::vector<PrimitiveData>& data = prepared.data;
    const double* origin = prepared.origin;
    m.stats.max_quantization_error = std::max(m.stats.max_quantization_error, prepared.max_quantization_error);
    m.stats.meshopt_range_clamped = m.stats.meshopt_range_clamped || prepared.clamped;
    // Step: the first frame is held (its own buffers kept, BinSink), a second one sends it to the
    // spill file.
    if (m.model.frames > 0) {
        m.model.keepPrevious();  // the held frame's index lists copied before it is let go
        if (m.plain) m.plain->keepPrevious();
        m.sink.spill();
    } else if (m.sink.holding) {
        m.sink.pinned = prepared.weak_from_this().lock();  // none (addEncoded's frame): copied instead
        if (m.sink.pinned) m.sink.borrowable = prepared.buffers();
    }
    m.model.borrow_indices = m.sink.pinned != nullptr;
    if (m.plain) m.plain->borrow_indices = m.model.borrow_indices;
    // Step: into the model (binary data to the spill file), and into the counted plain twin.
    if (!m.model.addFrame(f, data, origin, prepared.step > 0 ? prepared.step : 1.0, &prepared.meshopt, &m.stats,
                          error)) {
        *error = m.path + ": " + *error;
        return false;
    }
    GlbStats ignored;
    if (m.plain && !m.plain->addFrame(f, data, origin, 1.0, nullptr, &ignored, error)) {
        *error = m.path + ": " + *error;
        return false;
    }
    if (!m.sink.error.empty()) {
        *error = m.path + ": spill file: " + m.sink.error;
        return false;
    }
    // A .glb's length field is 32 bits: stop as soon as the frame data alone passes 4 GiB.
    if (m.sink.size > 0xffffffffull) {
        *error = m.path + ": more than a .glb can hold (4 GiB) after frame " + std::to_string(f.index) +
                 "; render fewer frames at once (--frames) or add --draco";
        return false;
    }
    return true;
}

bool GlbSequenceWriter::finish(GlbStats* stats, std::string* error, const FrameSink::OutputCheck& check) {
    Impl& m = *impl_;
    if (m.model.frames == 0) {
        *error = m.path + ": no frames to write";
        return false;
    }
    const std::string json = m.model.finish(m.far);
    if (!m.sink.error.empty()) {
        *error = m.path + ": spill file: " + m.sink.error;
        return false;
    }
    const size_t bin = m.sink.size;
    const uint64_t total = 12 + 8 + padded4(json.size()) + 8 + padded4(bin);
    if (m.plain) {
        const std::string plain_json = m.plain->finish(m.far);
        m.stats.bytes_without_draco = 12 + 8 + padded4(plain_json.size()) + 8 + padded4(m.count_only.size);
    }
    if (total > 0xffffffffull) {
        *error = m.path + ": " + std::to_string(total) +
                 " bytes, more than a .glb can hold (4 GiB); render fewer frames at once (--frames) or add --draco";
        return false;
    }

    // The whole file against the output limit before any of it is written.
    if (check && !check((long long)total, m.path, error)) return false;

    // Step: header, JSON chunk, BIN chunk copied from the spill file; through a temporary name,
    // every write checked and synced before the rename.
    AtomicOutput out(m.path);
    const int fd = out.fd();
    if (fd < 0) {
        *error = out.openError();
        return false;
    }
    auto put32 = [](std::string* s, uint32_t v) {
        for (int i = 0; i < 4; ++i) s->push_back(char((v >> (8 * i)) & 0xff));  // little-endian
    };
    std::string head = "glTF";
    put32(&head, 2);
    put32(&head, uint32_t(total));
    put32(&head, uint32_t(padded4(json.size())));
    put32(&head, 0x4E4F534A);  // JSON
    head += json;
    head.append(padded4(json.size()) - json.size(), ' ');
    put32(&head, uint32_t(padded4(bin)));
    put32(&head, 0x004E4942);  // BIN
    std::string werr;
    bool ok = true;
    if (!m.sink.in_pieces) {
        static const char zeros[4] = {0, 0, 0, 0};
        if (m.sink.holding) {
            // A lone frame: head, frame data from where it is held and padding as one file
            // (writeWhole: past the page cache when large; no spill file).
            std::vector<iovec> pieces{{head.data(), head.size()}};
            m.sink.heldPieces(&pieces);
            pieces.push_back({const_cast<char*>(zeros), padded4(bin) - bin});
            ok = writeWhole(fd, pieces.data(), pieces.size(), &werr);
        } else {
            // The BIN chunk copied from the spill file after the head (copy_file_range: the
            // kernel copies between the two files' pages; pread and write where it cannot). The
            // file's blocks reserved in one call first: page by page, ext4's delayed allocation
            // costs more than copying the bytes. Only a hint: where it fails (a file system
            // without it, no space), the writes below say what is wrong.
            (void)::fallocate(fd, 0, 0, off_t(total));
            ok = writeAll(fd, head.data(), head.size(), &werr) && copyRange(m.sink.fd, 0, bin, fd, &werr) &&
                 writeAll(fd, zeros, padded4(bin) - bin, &werr);
        }
    } else {
        // Frames by reference: the file at its whole size (zeros: the alignment runs and the
        // chunk's padding), the head, this spill's pieces, then every other range placed at its
        // offset by placeFrameData() (under MPI each rank copies its own frames, all at once).
        ok = ::ftruncate(fd, off_t(total)) == 0;
        if (!ok) werr = std::strerror(errno);
        ok = ok && writeAll(fd, head.data(), head.size(), &werr);
        std::vector<Placement> placements;
        uint64_t at = head.size();
        for (const FileSpan& p : m.sink.pieces) {
            if (p.source == BinSink::kLocal) {
                ok = ok && (::lseek(fd, off_t(at), SEEK_SET) >= 0 || (werr = std::strerror(errno), false)) && copyRange(m.sink.fd, p.offset, p.length, fd, &werr);
            } else if (p.source != BinSink::kZeros) {
                placements.push_back({p, at});
            }
            at += p.length;
        }
        std::error_code ec;  // an absolute name: other processes open it too
        const std::filesystem::path temp = std::filesystem::absolute(out.tempPath(), ec);
        ok = ok && placeFrameData(ec ? out.tempPath() : temp.string(), placements, &werr);
    }
    if (ok && ::fsync(fd) != 0) { werr = std::strerror(errno); ok = false; }
    if (!ok) {
        *error = m.path + ": cannot write: " + werr;
        return false;
    }
    if (!out.commit(error)) return false;
    m.releaseUsed();
    m.stats.bytes = size_t(total);
    if (stats) *stats = m.stats;
    return true;
}

namespace {

std::string humanBytes(size_t n) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(1);
    if (n >= 1 << 20) os << double(n) / (1 << 20) << " MiB";
    else if (n >= 1 << 10) os << double(n) / (1 << 10) << " KiB";
    else os << n << " B";
    return os.str();
}

}  // namespace

GlbSink::GlbSink(std::string path, const GlbOptions& options, bool verbose)
    : path_(std::move(path)), options_(options), verbose_(verbose) {}

GlbSink::~GlbSink() = default;

bool GlbSink::begin(const SequenceInfo& info, std::string*) {
    model_ = info.model;
    tolerance_ = info.tolerance;
    writer_ = std::make_unique<GlbSequenceWriter>(path_, info, options_);
    return true;  // the spill file's errors surface at the first add()
}

std::shared_ptr<const PreparedFrame> GlbSink::prepare(const ExportFrame& frame) const { return writer_->prepare(frame); }

PendingOutput GlbSink::pending(const ExportFrame& frame) {
    // Uncompressed, the file holds at least the frames' positions and normals, 24 bytes per
    // vertex (indices may be shared with the previous frame); Draco's and meshopt's sizes are not
    // known before encoding. Nothing of the .glb counts as written before finish().
    if (!options_.draco && !options_.meshopt) {
        long long vertices = 0;
        for (const auto& o : frame.objects) vertices += (long long)o.positions.size();
        least_ += 24 * vertices;
    }
    return {least_, model_ + ".glb"};
}

bool GlbSink::add(const ExportFrame& frame, const PreparedFrame* prepared, std::vector<std::string>*,
                  std::string* error) {
    if (!prepared) return writer_->add(frame, error);
    return writer_->add(frame, static_cast<const GlbFrameData&>(*prepared), error);
}

bool GlbSink::finish(SinkSummary* summary, std::string* error) {
    GlbStats stats;
    if (!writer_->finish(&stats, error, check_)) return false;
    summary->completed.push_back(path_);
    // Step: ", out/m.glb (1.2 MiB with Draco, 4.5 MiB without); float32 ... ; Draco ..."
    summary->text = ", " + path_ + " (" + humanBytes(stats.bytes);
    if (options_.draco) summary->text += " with Draco, " + humanBytes(stats.bytes_without_draco) + " without";
    if (options_.meshopt) summary->text += " with meshopt, " + humanBytes(stats.bytes_without_draco) + " without";
    summary->text += ")";
    std::ostringstream os;
    os << std::setprecision(3);
    if (verbose_) os << "; float32 position error <= " << stats.max_float_error << " ls";
    if (options_.draco && verbose_)
        os << "; Draco " << options_.position_bits << "-bit position error <= " << stats.max_quantization_error << " ls";
    if (options_.meshopt && verbose_) os << "; meshopt position error <= " << stats.max_quantization_error << " ls";
    summary->text += os.str();
    // meshopt's bound against the tolerance: a requested bit count too coarse, or a tolerance
    // finer than int16 can hold over a frame.
    if (options_.meshopt && tolerance_ > 0 && stats.max_quantization_error > tolerance_) {
        std::ostringstream w;
        w << std::setprecision(3) << path_ << ": meshopt position error up to " << stats.max_quantization_error
          << " ls exceeds the tolerance " << tolerance_ << " ls; "
          << (stats.meshopt_range_clamped ? "16 bits cannot hold a frame at that tolerance (use --compress draco)"
                                          : "leave out --meshopt-bits (the step then follows the tolerance)");
        summary->warnings.push_back(w.str());
    }
    // Warn when Draco's quantization is coarser than the accuracy asked for (gltfpack warns the
    // same way about position bits).
    if (options_.draco && tolerance_ > 0 && stats.max_quantization_error > tolerance_) {
        std::ostringstream w;
        w << std::setprecision(3) << path_ << ": Draco position error up to " << stats.max_quantization_error
          << " ls exceeds the tolerance " << tolerance_ << " ls; consider more bits (--draco-bits "
          << std::min(30, options_.position_bits + 2) << ")";
        summary->warnings.push_back(w.str());
    }
    return true;
}

// ---- Frames across processes: a prepared frame as bytes (gltf.h, GlbSequenceWriter::encode) ----

namespace {

// Little-endian host assumed for the arrays (x86-64 and aarch64; checked where decoded).
class FrameBytesOut {
public:
    explicit FrameBytesOut(std::string* out) : out_(out) {}
    template <class T>
    void put(const T& v) {
        static_assert(std::is_trivially_copyable<T>::value, "plain values only");
        out_->append(reinterpret_cast<const char*>(&v), sizeof(T));
    }
    template <class T>
    void putVector(const std::vector<T>& v) {
        put(uint64_t(v.size()));
        if (!v.empty()) out_->append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }

private:
    std::string* out_;
};

class FrameBytesIn {
public:
    FrameBytesIn(const std::string& in) : in_(in) {}
    template <class T>
    bool get(T* v) {
        if (in_.size() - at_ < sizeof(T)) return false;
        std::memcpy(v, in_.data() + at_, sizeof(T));
        at_ += sizeof(T);
        return true;
    }
    template <class T>
    bool getVector(std::vector<T>* v) {
        uint64_t n = 0;
        if (!get(&n) || n > (in_.size() - at_) / sizeof(T)) return false;
        v->resize(size_t(n));
        if (n) std::memcpy(v->data(), in_.data() + at_, size_t(n) * sizeof(T));
        at_ += size_t(n) * sizeof(T);
        return true;
    }
    bool atEnd() const { return at_ == in_.size(); }

private:
    const std::string& in_;
    size_t at_ = 0;
};

constexpr uint32_t kFrameBytesMagic = 0x31464741;  // "AGF1": apparent glb frame, version 1
constexpr uint32_t kFrameRefMagic = 0x31524741;    // "AGR1": the same by reference (frame_spill.h)

// What both forms of a frame (whole, by reference) say first after their own start: which
// objects show, and the frame's origin, step and bounds.
void putFrameHead(FrameBytesOut* out, const ExportFrame& f, const GlbFrameData& d) {
    out->put(uint64_t(f.objects.size()));
    for (const auto& o : f.objects) out->put(uint8_t(o.triangles.empty() ? 0 : 1));
    for (int c = 0; c < 3; ++c) out->put(d.origin[c]);
    out->put(d.step);
    out->put(uint8_t(d.clamped));
    for (double v : {d.far, d.max_extent, d.max_float_error, d.max_quantization_error}) out->put(v);
}

void putSpan(FrameBytesOut* out, const FileSpan& s) {
    out->put(s.source);
    out->put(s.offset);
    out->put(s.length);
}
bool getSpan(FrameBytesIn* in, FileSpan* s) { return in->get(&s->source) && in->get(&s->offset) && in->get(&s->length); }

void putText(FrameBytesOut* out, const std::string& text) { out->putVector(std::vector<char>(text.begin(), text.end())); }
// A Draco-coded primitive's facts besides its bytes, as both forms of a frame send them.
void putDracoFacts(FrameBytesOut* out, const DracoCoded& dc) {
    out->put(dc.points);
    out->put(dc.faces);
    for (int c = 0; c < 3; ++c) out->put(dc.lo[c]);
    for (int c = 0; c < 3; ++c) out->put(dc.hi[c]);
    for (int32_t id : dc.ids) out->put(id);
    out->put(dc.quantization_error);
    putText(out, dc.error);
}
bool getText(FrameBytesIn* in, std::string* text) {
    std::vector<char> v;
    if (!in->getVector(&v)) return false;
    text->assign(v.begin(), v.end());
    return true;
}

}  // namespace

// A frame by reference: its arrays written to this process's frame spill in the order the file
// takes them (plainPrimitive's views; meshopt's streams), the frame's description with their spans.
// With meshopt records that may be morph targets (no --attributes, no --shade doppler), also the
// frame as a morph target of the previous frame (`pf`: its records prepared here too), in both
// forms rank 0 may take (MeshoptFrame::RemoteTarget), and whether its records may open a run.
std::string GlbSequenceWriter::encodeByReference(const ExportFrame& f, const GlbFrameData& d,
                                                 const ExportFrame* pf) const {
    const bool meshopt = impl_->options.meshopt;
    const size_t record = MeshoptLayout(impl_->options).stride;
    // Step (frame coherence): the run facts and the targets (one encoding when both forms agree).
    uint8_t may_run = 0, targets = 0;
    MeshoptFrame::RemoteTarget target[2];
    std::vector<unsigned char> target_encoded[2];
    if (meshopt && record == 12 && d.meshopt.count > 0) {
        auto shownOf = [](const ExportFrame& frame, const GlbFrameData& data) {
            std::vector<const PrimitiveData*> shown;
            for (size_t o = 0; o < frame.objects.size() && o < data.data.size(); ++o)
                if (!frame.objects[o].triangles.empty()) shown.push_back(&data.data[o]);
            return shown;
        };
        const std::vector<const PrimitiveData*> shown = shownOf(f, d);
        may_run = runReference(shown, d.meshopt.count, d.meshopt.normals_inline, true, nullptr, nullptr);
        // The frame before, its records alone (no streams: which form its normals took is in its
        // own description, for rank 0 to pick the target's form).
        const std::shared_ptr<GlbFrameData> before_data = pf ? prepare(*pf, false) : nullptr;
        const GlbFrameData* pd = before_data.get();
        if (pf && pd) {
            targets = 1;
            const std::vector<const PrimitiveData*> before = shownOf(*pf, *pd);
            // A target keeps every object's index list (the writer's sharing): else none fits.
            bool same_lists = before.size() == shown.size();
            same_lists = same_lists && f.objects.size() == pf->objects.size() && d.data.size() == f.objects.size() &&
                         pd->data.size() == f.objects.size();
            for (size_t o = 0; same_lists && o < f.objects.size(); ++o)
                same_lists = f.objects[o].triangles.empty() == pf->objects[o].triangles.empty() &&
                             d.data[o].indices == pd->data[o].indices;
            std::vector<unsigned char> rec[2];
            for (int form = 0; same_lists && form < 2; ++form) {
                std::vector<unsigned char> records, normals;
                std::vector<size_t> first;
                MeshoptFrame::RemoteTarget& t = target[form];
                t.fits = runReference(before, pd->meshopt.count, false, form == 0, &records, &normals) &&
                         morphRecords(shown, records, normals, pd->meshopt.count, &rec[form], &first, t.lo, t.hi);
                if (!t.fits) continue;
                if (form == 1 && target[0].fits && rec[1] == rec[0])
                    continue;  // the same bytes: one encoding (its span copied below)
                target_encoded[form] = encodeMorphRecords(rec[form], pd->meshopt.count);
            }
        }
    }
    size_t shown = 0;
    for (const auto& o : f.objects) shown += o.triangles.empty() ? 0 : 1;
    // Step (meshopt): the index stream of every shown object, as add() makes it when none shares.
    std::vector<unsigned char> all_indices;
    if (meshopt && d.meshopt.count > 0) {
        std::vector<unsigned int> all;
        size_t most = 0;
        for (size_t o = 0; o < f.objects.size(); ++o)
            if (!f.objects[o].triangles.empty() && d.data[o].ordered) {
                all.insert(all.end(), d.data[o].ordered->begin(), d.data[o].ordered->end());
                most = std::max(most, d.data[o].packed.size() / record);
            }
        if (!all.empty()) encodeIndexStream(all, most, &all_indices);
    }
    // Step: the pieces, in order.
    std::vector<iovec> pieces;
    auto piece = [&](const auto& v) {
        pieces.push_back({const_cast<void*>(static_cast<const void*>(v.data())), v.size() * sizeof(v[0])});
    };
    piece(d.meshopt.encoded);
    piece(d.meshopt.encoded_normals);
    piece(all_indices);
    for (size_t o = 0; o < d.data.size(); ++o) {
        const PrimitiveData& p = d.data[o];
        for (const auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors}) piece(*v);
        piece(p.indices);
        piece(p.draco.bytes);
        static const std::vector<uint32_t> none;
        piece(meshopt && shown > 1 && p.ordered ? *p.ordered : none);  // a partly shared stream is made from them
    }
    piece(target_encoded[0]);
    piece(target_encoded[1]);
    std::vector<FileSpan> spans;
    std::string spill_error;
    if (!spillFrameData(pieces, &spans, &spill_error)) spans.assign(pieces.size(), FileSpan());
    target[0].encoded = spans[pieces.size() - 2];
    target[1].encoded = target_encoded[1].empty() ? target[0].encoded : spans[pieces.size() - 1];
    // Step: the description.
    std::string bytes;
    FrameBytesOut out(&bytes);
    out.put(kFrameRefMagic);
    out.put(int64_t(f.index));
    out.put(f.t_c);
    putText(&out, spill_error);
    putFrameHead(&out, f, d);
    out.put(uint64_t(d.meshopt.count));
    out.put(uint64_t(d.meshopt.stride));
    out.put(uint8_t(d.meshopt.normals_inline));
    out.putVector(d.meshopt.first);
    size_t k = 0;
    for (int i = 0; i < 3; ++i) putSpan(&out, spans[k++]);
    out.put(uint64_t(d.data.size()));
    for (const PrimitiveData& p : d.data) {
        for (int i = 0; i < 9; ++i) putSpan(&out, spans[k++]);
        uint64_t hash[2] = {0, 0};
        indexHash(p.indices, hash);
        std::vector<double> lo(3, INFINITY), hi(3, -INFINITY);
        for (size_t i = 0; i < p.positions.size(); ++i) {
            lo[i % 3] = std::min(lo[i % 3], double(p.positions[i]));
            hi[i % 3] = std::max(hi[i % 3], double(p.positions[i]));
        }
        out.put(uint64_t(p.vertexCount()));
        out.put(uint64_t(p.indices.size()));
        out.put(uint64_t(p.packed.size() / record));
        out.put(uint64_t(p.ordered ? p.ordered->size() : 0));
        for (int c = 0; c < 3; ++c) out.put(lo[size_t(c)]);
        for (int c = 0; c < 3; ++c) out.put(hi[size_t(c)]);
        out.put(hash[0]);
        out.put(hash[1]);
        for (int c = 0; c < 3; ++c) out.put(int32_t(p.qmin[c]));
        for (int c = 0; c < 3; ++c) out.put(int32_t(p.qmax[c]));
        const DracoCoded& dc = p.draco;
        putDracoFacts(&out, dc);
    }
    out.put(may_run);
    out.put(targets);
    for (const MeshoptFrame::RemoteTarget& t : target) {
        out.put(uint8_t(t.fits));
        for (int c = 0; c < 3; ++c) out.put(t.lo[c]);
        for (int c = 0; c < 3; ++c) out.put(t.hi[c]);
        putSpan(&out, t.encoded);
    }
    return bytes;
}

// The frame of encodeByReference() for add(): its description, the arrays left where they are.
bool GlbSequenceWriter::addByReference(const std::string& bytes, std::string* error) {
    FrameBytesIn in(bytes);
    uint32_t magic = 0;
    int64_t index = 0;
    uint64_t objects = 0, count = 0, stride = 0, primitives = 0;
    uint8_t clamped = 0, normals_inline = 0;
    std::string spill_error;
    ExportFrame f;
    GlbFrameData d;
    MeshoptFrame& mf = d.meshopt;
    bool ok = in.get(&magic) && magic == kFrameRefMagic && in.get(&index) && in.get(&f.t_c) &&
              getText(&in, &spill_error) && in.get(&objects) && objects <= bytes.size();
    f.index = index;
    if (ok && !spill_error.empty()) {
        *error = impl_->path + ": spill file: cannot write: " + spill_error;  // as a writer's own spill says
        return false;
    }
    if (ok) f.objects.resize(size_t(objects));
    for (size_t o = 0; ok && o < f.objects.size(); ++o) {
        uint8_t shown = 0;
        ok = in.get(&shown);
        if (shown) f.objects[o].triangles.push_back({0, 0, 0});
    }
    for (int c = 0; ok && c < 3; ++c) ok = in.get(&d.origin[c]);
    ok = ok && in.get(&d.step) && in.get(&clamped) && in.get(&d.far) && in.get(&d.max_extent) &&
         in.get(&d.max_float_error) && in.get(&d.max_quantization_error) && in.get(&count) && in.get(&stride) &&
         in.get(&normals_inline) && in.getVector(&mf.first) && getSpan(&in, &mf.remote_encoded) &&
         getSpan(&in, &mf.remote_normals) && getSpan(&in, &mf.remote_indices) && in.get(&primitives) &&
         primitives == objects;
    d.clamped = clamped != 0;
    mf.count = size_t(count);
    mf.stride = size_t(stride);
    mf.normals_inline = normals_inline != 0;
    mf.remote = true;
    if (ok) d.data.resize(size_t(primitives));
    for (size_t o = 0; ok && o < d.data.size(); ++o) {
        PrimitiveData& p = d.data[o];
        PrimitiveData::Remote& r = p.remote;
        r.on = true;
        for (FileSpan* s : {&r.positions, &r.normals, &r.emission, &r.doppler, &r.proper_time, &r.colors, &r.indices,
                            &r.draco, &r.ordered})
            ok = ok && getSpan(&in, s);
        ok = ok && in.get(&r.vertices) && in.get(&r.index_count) && in.get(&r.packed_vertices) &&
             in.get(&r.ordered_count);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&r.lo[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&r.hi[c]);
        ok = ok && in.get(&r.index_hash[0]) && in.get(&r.index_hash[1]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmin[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmax[c]);
        DracoCoded& dc = p.draco;
        ok = ok && in.get(&dc.points) && in.get(&dc.faces);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&dc.lo[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&dc.hi[c]);
        for (int a = 0; ok && a < 6; ++a) ok = in.get(&dc.ids[a]);
        ok = ok && in.get(&dc.quantization_error) && getText(&in, &dc.error);
        // What add() takes of the spans: whole vertices and triangles, every source known.
        const uint64_t nv = r.vertices;
        auto optional = [nv](const FileSpan& s, uint64_t per) { return s.length == 0 || s.length == per * nv; };
        ok = ok && r.positions.length == 12 * nv && r.normals.length == 12 * nv && r.emission.length == 4 * nv &&
             optional(r.doppler, 4) && optional(r.proper_time, 4) && optional(r.colors, 12) &&
             r.indices.length == 4 * r.index_count && r.index_count % 3 == 0 &&
             (r.ordered.length == 0 || r.ordered.length == 4 * r.ordered_count);
        for (const FileSpan* s : {&r.positions, &r.normals, &r.emission, &r.doppler, &r.proper_time, &r.colors,
                                  &r.indices, &r.draco, &r.ordered})
            if (ok && s->length > 0) {
                ok = frameSource(s->source) >= 0;
                impl_->use(*s);
            }
    }
    uint8_t may_run = 0, targets = 0;
    ok = ok && in.get(&may_run) && in.get(&targets);
    mf.remote_run = may_run != 0;
    mf.targets = targets != 0;
    for (MeshoptFrame::RemoteTarget& t : mf.remote_target) {
        uint8_t fits = 0;
        ok = ok && in.get(&fits);
        t.fits = fits != 0;
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&t.lo[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&t.hi[c]);
        ok = ok && getSpan(&in, &t.encoded) && (!t.fits || t.encoded.length > 0);
    }
    for (const FileSpan* s : {&mf.remote_encoded, &mf.remote_normals, &mf.remote_indices, &mf.remote_target[0].encoded,
                              &mf.remote_target[1].encoded})
        if (ok && s->length > 0) {
            ok = frameSource(s->source) >= 0;
            impl_->use(*s);
        }
    ok = ok && in.atEnd() && (mf.first.empty() || mf.first.size() == d.data.size());
    if (!ok) {
        *error = impl_->path + ": frame data from another process is malformed (frame " + std::to_string(index) + ")";
        return false;
    }
    return add(f, d, error);
}

std::string GlbSequenceWriter::encode(const ExportFrame& f, const GlbFrameData& d, const ExportFrame* previous) const {
    // Frames by reference, but meshopt frames that may be morph targets (records, no --attributes
    // or --shade doppler) only when morphTargetsByReference(): else they travel whole, since
    // frame coherence takes their records' differences from the previous frame's on rank 0.
    const bool morph_capable = impl_->options.meshopt && MeshoptLayout(impl_->options).stride == 12;
    if (frameSpillInstalled() && (!morph_capable || morphTargetsByReference()))
        return encodeByReference(f, d, previous);
    std::string bytes;
    FrameBytesOut out(&bytes);
    out.put(kFrameBytesMagic);
    out.put(int64_t(f.index));
    out.put(f.t_c);
    putFrameHead(&out, f, d);
    out.putVector(d.meshopt.encoded);
    out.putVector(d.meshopt.encoded_normals);
    out.put(uint64_t(d.meshopt.count));
    out.put(uint64_t(d.meshopt.stride));
    out.put(uint8_t(d.meshopt.normals_inline));
    out.putVector(d.meshopt.first);
    out.put(uint64_t(d.data.size()));
    for (const PrimitiveData& p : d.data) {
        for (const auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors})
            out.putVector(*v);
        out.putVector(p.indices);
        out.putVector(p.packed);
        out.putVector(p.packed_normals);
        out.putVector(p.packed_snorm);
        out.put(uint8_t(p.ordered ? 1 : 0));
        if (p.ordered) out.putVector(*p.ordered);
        for (int c = 0; c < 3; ++c) out.put(int32_t(p.qmin[c]));
        for (int c = 0; c < 3; ++c) out.put(int32_t(p.qmax[c]));
        const DracoCoded& dc = p.draco;
        out.putVector(dc.bytes);
        putDracoFacts(&out, dc);
    }
    return bytes;
}

bool GlbSequenceWriter::addEncoded(const std::string& bytes, std::string* error) {
    uint32_t form = 0;
    if (bytes.size() >= 4) std::memcpy(&form, bytes.data(), 4);
    if (form == kFrameRefMagic) return addByReference(bytes, error);
    // Step: the frame as add() reads it: its number, time and which objects show (one stand-in
    // triangle each: add() looks at nothing else of the cut mesh), and the prepared data.
    FrameBytesIn in(bytes);
    uint32_t magic = 0;
    int64_t index = 0;
    uint64_t objects = 0;
    ExportFrame f;
    GlbFrameData d;
    bool ok = in.get(&magic) && magic == kFrameBytesMagic && in.get(&index) && in.get(&f.t_c) && in.get(&objects) &&
              objects <= bytes.size();
    f.index = index;
    if (ok) f.objects.resize(size_t(objects));
    for (size_t o = 0; ok && o < f.objects.size(); ++o) {
        uint8_t shown = 0;
        ok = in.get(&shown);
        if (shown) f.objects[o].triangles.push_back({0, 0, 0});
    }
    uint8_t clamped = 0, normals_inline = 0;
    uint64_t count = 0, stride = 0, primitives = 0;
    for (int c = 0; ok && c < 3; ++c) ok = in.get(&d.origin[c]);
    ok = ok && in.get(&d.step) && in.get(&clamped) && in.get(&d.far) && in.get(&d.max_extent) &&
         in.get(&d.max_float_error) && in.get(&d.max_quantization_error) && in.getVector(&d.meshopt.encoded) &&
         in.getVector(&d.meshopt.encoded_normals) && in.get(&count) && in.get(&stride) && in.get(&normals_inline) &&
         in.getVector(&d.meshopt.first) && in.get(&primitives) && primitives == objects;
    d.clamped = clamped != 0;
    d.meshopt.count = size_t(count);
    d.meshopt.stride = size_t(stride);
    d.meshopt.normals_inline = normals_inline != 0;
    const size_t record = MeshoptLayout(impl_->options).stride;
    if (ok) d.data.resize(size_t(primitives));
    for (size_t o = 0; ok && o < d.data.size(); ++o) {
        PrimitiveData& p = d.data[o];
        for (auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors})
            ok = ok && in.getVector(v);
        uint8_t has_ordered = 0;
        ok = ok && in.getVector(&p.indices) && in.getVector(&p.packed) && in.getVector(&p.packed_normals) &&
             in.getVector(&p.packed_snorm) && in.get(&has_ordered);
        if (ok && has_ordered) {
            auto ordered = std::make_shared<std::vector<uint32_t>>();
            ok = in.getVector(ordered.get());
            p.ordered = std::move(ordered);
        }
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmin[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmax[c]);
        DracoCoded& dc = p.draco;
        std::vector<char> draco_error;
        ok = ok && in.getVector(&dc.bytes) && in.get(&dc.points) && in.get(&dc.faces);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&dc.lo[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&dc.hi[c]);
        for (int a = 0; ok && a < 6; ++a) ok = in.get(&dc.ids[a]);
        ok = ok && in.get(&dc.quantization_error) && in.getVector(&draco_error);
        dc.error.assign(draco_error.begin(), draco_error.end());
        // What add() writes as it is: finite attributes (a NaN gives an invalid accessor).
        for (const auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors})
            ok = ok && std::all_of(v->begin(), v->end(), [](float x) { return std::isfinite(x); });
        // What add() indexes by: whole vertices, indices within them, the meshopt stream's offsets.
        const size_t nv = p.emission.size();
        ok = ok && p.positions.size() == 3 * nv && p.normals.size() == 3 * nv && p.indices.size() % 3 == 0 &&
             std::all_of(p.indices.begin(), p.indices.end(), [nv](uint32_t i) { return i < nv; }) &&
             p.packed.size() % record == 0 &&
             (!p.ordered || std::all_of(p.ordered->begin(), p.ordered->end(),
                                        [&](uint32_t i) { return size_t(i) < p.packed.size() / record; })) &&
             (!impl_->options.meshopt || f.objects[o].triangles.empty() || p.ordered);
    }
    ok = ok && in.atEnd() && (d.meshopt.first.empty() || d.meshopt.first.size() == d.data.size()) &&
         std::isfinite(d.origin[0]) && std::isfinite(d.origin[1]) && std::isfinite(d.origin[2]) &&
         std::isfinite(d.step) && std::isfinite(d.far) && std::isfinite(f.t_c);
    if (!ok) {
        *error = impl_->path + ": frame data from another process is malformed (frame " + std::to_string(index) + ")";
        return false;
    }
    return add(f, d, error);
}

bool encodedFrameHead(const std::string& bytes, long long* index, size_t* objects) {
    FrameBytesIn in(bytes);
    uint32_t magic = 0;
    int64_t k = 0;
    double t_c = 0;
    uint64_t n = 0;
    if (!(in.get(&magic) && magic == kFrameBytesMagic && in.get(&k) && in.get(&t_c) && in.get(&n))) return false;
    *index = k;
    *objects = size_t(n);
    return true;
}

bool GlbSink::encodesAfterPrevious() const {
    return options_.meshopt && MeshoptLayout(options_).stride == 12 && frameSpillInstalled() &&
           morphTargetsByReference();
}

EncodedOutput GlbSink::encode(const ExportFrame& frame, const PreparedFrame* prepared) const {
    return encodeAfter(frame, prepared, nullptr);
}

EncodedOutput GlbSink::encodeAfter(const ExportFrame& frame, const PreparedFrame* prepared,
                                   const ExportFrame* previous) const {
    EncodedOutput e;
    if (!options_.draco && !options_.meshopt)
        for (const auto& o : frame.objects) e.least += 24 * (long long)o.positions.size();  // as pending()
    e.estimate = estimate(frame);
    std::shared_ptr<const PreparedFrame> own;
    if (!prepared) {
        own = writer_->prepare(frame);
        prepared = own.get();
    }
    e.bytes = writer_->encode(frame, static_cast<const GlbFrameData&>(*prepared), previous);
    return e;
}

PendingOutput GlbSink::pendingEncoded(long long, const EncodedOutput& frame) {
    least_ += frame.least;
    return {least_, model_ + ".glb"};
}

bool GlbSink::addEncoded(long long, const EncodedOutput& frame, std::vector<std::string>*, std::string* error) {
    return writer_->addEncoded(frame.bytes, error);
}

bool writeAnimatedGlb(const std::string& path, const std::vector<ExportFrame>& frames, const SequenceInfo& info,
                      const GlbOptions& options, GlbStats* stats, std::string* error) {
    GlbSequenceWriter writer(path, info, options);
    for (const ExportFrame& f : frames)
        if (!writer.add(f, error)) return false;
    return writer.finish(stats, error);
}

}  // namespace apparent
