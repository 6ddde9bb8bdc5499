// The .glb writer's stages, internal to exporters/glb/ (the public interface and the manual of
// the file's layout is exporters/gltf.h, whose names callers use). One file per stage; this
// header lists each stage's functions and the types they hand on, in the order a frame takes:
//   primitive.cpp  an object's cut mesh as the file's float32 arrays (toPrimitive -> PrimitiveData)
//   meshopt.cpp    meshopt packing (packMeshopt, meshoptStep), a frame's index stream, and frame
//                  coherence's record arithmetic (runReference, morphRecords, encodeMorphRecords)
//   draco.cpp      one primitive's Draco coding (encodeDraco -> DracoCoded)
//   bin.cpp        the BIN chunk while frames arrive (BinSink), frame data read and copied
//   container.cpp  the glTF records of views, accessors and primitives (GlbBuilder)
//   sequence.cpp   the sequence's model frame by frame: nodes, meshes, shared indices, morph runs
//                  (SequenceModel)
//   document.cpp   what needs the whole sequence (SequenceModel::finish): the animation, the
//                  reflections' nodes, the targets' weights, and the JSON chunk (jsonChunk)
//   write.cpp      GlbSequenceWriter (prepare, add, finish), GlbSink, writeAnimatedGlb
//   remote.cpp     frames across processes (GlbSequenceWriter::encode, addEncoded)
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <sys/uio.h>
#include <utility>
#include <vector>

#include "exporters/frame_spill.h"
#include "exporters/gltf.h"
#include "exporters/gltf_json.h"
#include "mesh4d/normals.h"

namespace apparent::glb {

// ---- What the stages hand on: one primitive's data, meshopt's frame streams and records ----

// One primitive's KHR_draco_mesh_compression coding (encodeDraco): the Edgebreaker bytes and what
// the accessors take from the decoded mesh (point and face counts, position bounds, attribute ids).
// With material parts (PrimitiveData::part_first) each part is a Draco mesh of its own (its
// triangles and the vertices they use): `bytes` holds their codings one after another, `parts`
// where each lies and its counts and bounds; the attribute ids are every part's.
struct DracoCoded {
    std::vector<char> bytes;
    uint64_t points = 0, faces = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    // Draco unique ids of POSITION, NORMAL, _EMISSION_TIME, _DOPPLER, _PROPER_TIME, COLOR_0,
    // TEXCOORD_0, TEXCOORD_1 (-1: absent).
    static constexpr int kIds = 8;
    int32_t ids[kIds] = {-1, -1, -1, -1, -1, -1, -1, -1};
    double quantization_error = 0;
    double texcoord_error = 0;  // the texture coordinates' bound (gltf.h), 0 without
    struct Part {
        uint64_t offset = 0, length = 0;  // in `bytes`
        uint64_t points = 0, faces = 0;
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    };
    std::vector<Part> parts;  // empty: one mesh, the fields above
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
    // --shade doppler: COLOR_0, linear RGB (mesh4d/doppler_colour.h); else the input's COLOR_0
    // (surface_look.h, RGB) when it has one; else empty.
    std::vector<float> colors;
    std::vector<float> texcoords, texcoords1;  // the input's TEXCOORD_0 and _1 (surface_look.h); else empty
    // The object's triangles grouped by material (plain files of an object with a look): part p
    // is indices [3 part_first[p], 3 part_first[p + 1]) in material part_material[p] of the look;
    // empty: one part, the object's one material.
    std::vector<uint32_t> part_first, part_material;
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
        FileSpan positions, normals, emission, doppler, proper_time, colors, texcoords, texcoords1, indices, draco;
        FileSpan ordered;  // meshopt frames of two objects or more (for a partly shared index stream)
        uint64_t vertices = 0, index_count = 0, packed_vertices = 0, ordered_count = 0;
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // POSITION's bounds (of the float32 values)
        uint64_t index_hash[2] = {0, 0};              // indexHash(indices)
    } remote;
    // Empties the float32 arrays and the index list (an object the frame does not show).
    void clearArrays() {
        for (auto* v : {&positions, &normals, &emission, &doppler, &proper_time, &colors, &texcoords, &texcoords1})
            v->clear();
        indices.clear();
        part_first.clear();
        part_material.clear();
    }
    size_t vertexCount() const { return remote.on ? size_t(remote.vertices) : emission.size(); }
    size_t indexCount() const { return remote.on ? size_t(remote.index_count) : indices.size(); }
    size_t packedVertices(size_t stride) const { return remote.on ? size_t(remote.packed_vertices) : packed.size() / stride; }
    size_t orderedCount() const { return remote.on ? size_t(remote.ordered_count) : ordered->size(); }
    // Whether the optional attribute (`local` here, `span` by reference) is there.
    template <class V>
    bool has(const V& local, const FileSpan& span) const { return remote.on ? span.length > 0 : !local.empty(); }
};

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
// --attributes float32 _DOPPLER and/or _PROPER_TIME, with --shade doppler or the looks' COLOR_0
// uint16 (normalized) R, G, B, 0, with the looks float32 TEXCOORD_0 u, v, and float32 TEXCOORD_1
// u, v when a carried look has that set; the same for every frame
// of a sequence (an offset < 0: not in the record). The looks' slots are there when any object's
// look is carried, whether or not it has texture coordinates or colours (zeros then): the layout
// must follow from what every process of a sequence knows (a shard's header carries the looks'
// materials and images, not their vertex arrays).
struct MeshoptLayout {
    explicit MeshoptLayout(const GlbOptions& o) {
        if (o.doppler) { doppler = int(stride); stride += 4; }
        if (o.proper_time) { proper_time = int(stride); stride += 4; }
        if (o.shade_doppler || o.meshopt_looks) { color = int(stride); stride += 8; }
        if (o.meshopt_looks) { texcoord = int(stride); stride += 8; }
        if (o.meshopt_looks && o.meshopt_texcoord1) { texcoord1 = int(stride); stride += 8; }
    }
    size_t stride = 12;
    int doppler = -1, proper_time = -1, color = -1, texcoord = -1, texcoord1 = -1;
};

// `options` with GlbOptions::meshopt_looks set when the file is meshopt's and carries any of
// `info`'s objects' looks (carriesLook).
GlbOptions withMeshoptLooks(const GlbOptions& options, const SequenceInfo& info);

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

// One object's vertex-cache and vertex-fetch orders for an index list, kept for the next frame:
// both depend on the index list alone, so an equal list (vertex mode, or the same refinement)
// takes them from here instead of optimizing again (meshopt_optimizeVertexCache is the costly
// step of a large frame's packing).
struct MeshoptOrder {
    std::vector<uint32_t> indices;   // the index list they were computed for
    std::vector<uint32_t> part_first;  // and its material parts (PrimitiveData::part_first)
    size_t vertices = 0;             // and its vertex count
    std::shared_ptr<std::vector<uint32_t>> ordered;  // the triangles in cache order, in fetch numbering
    std::vector<unsigned int> remap; // fetch number of each vertex (~0u: unused)
    size_t used = 0;                 // vertices used by a triangle
};

// The meshopt form's scratch vectors (kept by the frame's buffers, used object by object).
struct MeshoptScratch {
    std::vector<double> exact;
    std::vector<MeshoptOrder> orders;  // per object
    std::vector<float> normals;
    std::vector<unsigned char> vertices, normal_stream;  // the frame's streams before encoding
    std::vector<unsigned char> inline_records, inline_encoded;  // the same with the normals inline
};

// ---- primitive.cpp ----

// Float32 data of one object's mesh relative to `origin`; tracks the largest rounding. Vertices
// are split along creases sharper than kCreaseDeg so folds shade flat and curves smooth. In a plain
// file an object with a look (`object.look`) also gets its texture coordinates and colours and
// its triangles grouped by material (PrimitiveData::part_first).
// With `step` > 0 also the meshopt form, positions quantized to multiples of `step` (*max_quant
// receives the largest coordinate error). The conversion runs in parallel (TBB) and writes into
// `d`, whose vectors keep their capacity from frame to frame; `map` and `work` are the crease
// split's (reused the same way, object by object), `scratch` meshopt's and `order` the object's
// meshopt orders.
void toPrimitive(const mesh4d::ApparentMesh& m, const double origin[3], double step, double* max_err,
                 double* max_quant, PrimitiveData* d, mesh4d::CreaseMap* map, mesh4d::CreaseWork* work,
                 MeshoptScratch* scratch, MeshoptOrder* order, const GlbOptions& options,
                 const ExportObject& object);

// Whether the .glb carries `object`'s look (it has one: plain, Draco and meshopt files alike).
bool carriesLook(const GlbOptions& options, const ExportObject& object);

// ---- meshopt.cpp ----

// The meshopt form of `d`: positions quantized from the exact relative coordinates `rel` (xyz
// per vertex) to multiples of `step`, triangles in vertex-cache order (within each material
// part, which keeps its place), vertices in the order the triangles first use them (both depend
// on the index list and parts alone, so frames with equal ones get equal orders; `order` keeps
// them from the object's last frame); the look's TEXCOORD_0 and COLOR_0 in their slots of
// `layout`. Returns the largest |step * q - rel| over the coordinates.
double packMeshopt(PrimitiveData* d, const std::vector<double>& rel, double step, const MeshoptLayout& layout,
                   MeshoptOrder* order, std::vector<float>* normal_work);

// The meshopt quantization step of a frame of largest extent `extent` (gltf.h): from the
// tolerance (T / sqrt(3)), from `bits` (E / (2^bits - 2)), or 14 bits over E in vertex mode; at
// least E / 65534 so that every coordinate fits int16 (*clamped says when that decided).
double meshoptStep(double extent, double tolerance, int bits, bool* clamped);

// A frame's meshopt vertex streams (MeshoptFrame) from its objects' packed records (`stride`
// bytes each): one vertex view and one normal view, or the normals at the end of each record,
// whichever is smaller with the view's JSON counted (kMeshoptViewJsonBytes). Encoded where the
// frame is prepared (on a worker thread); `scratch` keeps the streams' capacity.
void encodeFrameStreams(const std::vector<PrimitiveData>& data, size_t stride, MeshoptScratch* scratch,
                        MeshoptFrame* out);

// A frame's meshopt index stream: the objects' vertex-cache-ordered lists, one after another.
void encodeIndexStream(const std::vector<unsigned int>& all, size_t most_vertices, std::vector<unsigned char>* out);

// Appends the object's vertex-cache-ordered indices (read back from its spill when by reference).
bool appendOrdered(const PrimitiveData& d, std::vector<unsigned int>* all, std::string* error);

// Frame coherence (gltf.h), the one home of its record arithmetic, used where the file is written
// and, by reference, where the frame was cut. A frame's records and normals as a run's reference
// for the next frame: its shown objects' packed records in order, and their normals as a reader
// decodes them (`decoded_normals`: the octahedral view's int8 output, or the record's when the
// normals are inline; else the int8 normals, as a target's record holds them). False when they
// do not make `count` whole vertices.
// Without `records` and `normals`: only whether they would make them.
bool runReference(const std::vector<const PrimitiveData*>& shown, size_t count, bool normals_inline,
                  bool decoded_normals, std::vector<unsigned char>* records, std::vector<unsigned char>* normals);

// The shown objects' records (in order) as differences from the reference `records` and
// `normals` (runReference) of `count` vertices: one kMorphStride record per vertex in `rec`,
// each object's first vertex in `first`, POSITION's bounds in `lo` and `hi` (steps). False when
// a difference does not fit the record (int16 steps, an emission time difference exact in
// float32, int8 normal steps) or the vertex counts differ.
bool morphRecords(const std::vector<const PrimitiveData*>& shown, const std::vector<unsigned char>& records,
                  const std::vector<unsigned char>& normals, size_t count, std::vector<unsigned char>* rec,
                  std::vector<size_t>* first, int lo[3], int hi[3]);

// A target's records as its view's bytes (EXT_meshopt_compression ATTRIBUTES).
std::vector<unsigned char> encodeMorphRecords(const std::vector<unsigned char>& rec, size_t count);

// ---- draco.cpp ----

// One primitive's Draco coding (KHR_draco_mesh_compression), made by prepare() on the worker
// threads (and, with MPI, on the rank that cut the frame); `error` set when Draco failed. The
// position error bound is half a step of the quantization grid, which spans the largest extent
// of the primitive's positions in 2^bits - 1 steps (TEXCOORD_0's the same over the larger of its
// u and v ranges). Data with material parts: one Draco mesh per part (DracoCoded::parts).
void encodeDraco(const PrimitiveData& d, const GlbOptions& options, DracoCoded* out);

// ---- bin.cpp ----

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

    void write(const void* data, size_t n);
    // Appends to the spill file (opened on first use), and to the pieces when there are pieces.
    void toSpill(const void* data, size_t n);
    // The held data to the spill file; every write goes there from now on.
    void spill();
    // The held data in order, appended to `out` (finish() of a lone frame writes them).
    void heldPieces(std::vector<iovec>* out) const;
    void pad(size_t n);
    // Bytes of another process's frame spill (counted only without pieces: the plain twin).
    void reference(const FileSpan& s);
    // From here on a list of pieces; what the file holds so far is the first.
    void startPieces();
    void piece(const FileSpan& s);
};

// Reads `span` of its frame source into `out` (appended); false with a message.
bool readSpan(const FileSpan& span, void* out, std::string* error);

// Appends `n` bytes of `in` from `offset` to `out` (at its position) by copy_file_range (the kernel
// copies between the two files' pages, no trip through a user buffer); where it cannot (another
// file system, an old kernel), by pread and write. False with a message.
bool copyRange(int in, uint64_t offset, uint64_t n, int out, std::string* error);

// ---- container.cpp ----

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

    int addView(const void* data, size_t n, int target);
    // The same of bytes in a frame source (frames by reference).
    int addView(const FileSpan& span, int target);
    // A view of `local` (this process's vector) or, for a frame by reference, of `span`.
    template <class V>
    int addView(const PrimitiveData& d, const V& local, const FileSpan& span, int target);

    // A new accessor (`vec3`: VEC3, else SCALAR) at `offset` bytes of `view`; with `lo` and `hi`
    // its min and max (`n` values each).
    int addAccessor(int view, int component, bool vec3, size_t count, size_t offset = 0, const double* lo = nullptr,
                    const double* hi = nullptr, int n = 0);
    int addNormalized(int view, int component, bool vec3, size_t count, size_t offset);

    // A plain (uncompressed) primitive; `shared_indices` >= 0: that index accessor instead of a new one.
    // Data grouped by material (PrimitiveData::part_first) with `part_indices`: one index accessor
    // per part into it, on one view (the primitive's own is the first part's).
    gltfjson::Primitive plainPrimitive(const PrimitiveData& d, int shared_indices, std::vector<int>* part_indices = nullptr);

    // An EXT_meshopt_compression primitive: its vertices at `first_vertex` of the frame's vertex
    // view `vview` (records of `layout`, `stride` bytes each) and normal view `nview` (-1: the
    // normals end each record), its indices the accessor `indices` (made by the caller: new or
    // shared).
    gltfjson::Primitive meshoptPrimitive(const PrimitiveData& d, const MeshoptLayout& layout, size_t stride, int vview,
                                         int nview, size_t first_vertex, int indices);

    // A view of the fallback buffer (1, no data) whose EXT_meshopt_compression object points at
    // `encoded` in the BIN chunk. `octahedral`: the view's data went through the OCTAHEDRAL filter.
    int addMeshoptView(const std::vector<unsigned char>& encoded, size_t count, size_t stride, bool indices,
                       bool octahedral = false);
    // The same of an encoded stream in a frame source (frames by reference).
    int addMeshoptView(const FileSpan& encoded, size_t count, size_t stride, bool indices, bool octahedral = false);
    template <class Write>
    int newMeshoptView(size_t length, size_t count, size_t stride, bool indices, bool octahedral, const Write& write);

    // A KHR_draco_mesh_compression primitive from its coding (DracoCoded, made by prepare()), or
    // with `part` >= 0 that material part's mesh; returns false with the message when Draco failed
    // there. `quantization_error` receives the position error bound.
    bool dracoPrimitive(const PrimitiveData& d, gltfjson::Primitive* prim, double* quantization_error,
                        std::string* error, int part = -1);

private:
    // A new view of `n` bytes that `write` puts into the sink, 4-byte aligned for float/uint32.
    template <class Write>
    int newView(size_t n, int target, const Write& write);

    GlbOptions options_;
    BinSink* sink_;

    // Per coordinate, in vertex order (the same bits as any order but for the sign of a zero).
    static void bounds(const std::vector<float>& xyz, double* lo, double* hi);
};

// ---- sequence.cpp, document.cpp ----

// The glTF model of a sequence, built frame by frame: JSON-side objects in `model`, binary data
// streamed to the sink. Two run side by side with Draco: the real one and a plain one that only
// counts, for the size without Draco.
struct SequenceModel {
    SequenceModel(const SequenceInfo& info_, const GlbOptions& options, BinSink* sink);

    // Step: frame k's node (node 1 + k), given each object's primitive data (empty: not shown).
    // The scene's own objects go into the frame node's mesh; reflections (ExportObject::mirror)
    // into one mesh per mirror, whose child node of the frame node is made in finish(), after all
    // frame nodes, so that frame k stays node 1 + k. Meshes are numbered in frame order either way.
    // `scale`: the frame node's scale while shown (meshopt: the quantization step, else 1).
    // `meshopt`: the frame's encoded vertex stream (with meshopt compression).
    bool addFrame(const ExportFrame& f, const std::vector<PrimitiveData>& data, const double origin[3], double scale,
                  const MeshoptFrame* meshopt, GlbStats* stats, std::string* error);
    // The frame node's transform, its scale channel's value and the frame's extras (any frame).
    bool endFrame(const ExportFrame& f, gltfjson::Node* node, const double* origin, double scale);

    // Frame coherence (gltf.h). The objects a frame shows, in order.
    static std::vector<size_t> shownObjects(const ExportFrame& f);
    // Opens a run at the frame just made (its mesh `mesh`) when its layout allows morph targets:
    // records without --attributes or --shade doppler, no reflections. Keeps the frame's records
    // and its normals as a reader decodes them (the octahedral view's int8 output, or the record's).
    void startRun(const ExportFrame& f, const std::vector<PrimitiveData>& data, double step, const MeshoptFrame& mf,
                  const std::vector<int>& groups, int mesh);
    // Makes the frame a morph target of the open run's mesh when it continues the run: the same
    // objects alone (no reflections), each with the previous frame's index list, the same step
    // and vertex count, room for a target, and every difference from the previous frame held by
    // the target's record (int16 steps, an emission time difference exact in float32, int8
    // normal steps). Returns false, having changed nothing, otherwise.
    bool morphTarget(const ExportFrame& f, const std::vector<PrimitiveData>& data, double step, const MeshoptFrame& mf,
                     const std::vector<int>& shared, const std::vector<int>& groups, std::string* error);

    // "frame_00042 mirror backdrop": the node (and mesh) of frame 42's reflections in mirror "backdrop".
    static std::string reflectionName(const std::string& frame, const std::string& mirror);
    int groupOf(size_t object) const { return object < info.objects.size() ? info.objects[object].mirror_index : -1; }
    // The name of mirror `index` (of its first reflection), or "#index" when it has none.
    std::string mirrorName(int index) const;

    // Step: what needs the whole sequence (document.cpp): the camera's clip planes, the animation
    // (at most 3 keys per channel), the scene extras. Returns the JSON chunk's text.
    std::string finish(double far);
    // Its steps: the animation's key times and scales (views and accessors; per frame its
    // sampler's input and output accessors), the reflections' nodes, the target frames' weights.
    std::vector<std::pair<int, int>> animationSamplers();
    void reflectionNodes();
    void morphWeights();

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
    // The objects' looks (surface_look.h) where the file carries them (carriesLook): per object its
    // first material (one each without a look), and per distinct look its first image, texture
    // and sampler in the file; the images' views are written with the first frame.
    std::vector<int> material_first;
    int materials = 0;
    struct LookPlace {
        const SurfaceLook* look;
        int image = 0, texture = 0, sampler = 0;
    };
    std::vector<LookPlace> looks;
    std::vector<int> image_views;
    bool images_written = false;
    std::vector<std::string> extensions_used;  // `extensions` and the looks' (KHR_texture_transform, ...)
    const LookPlace* lookPlace(const SurfaceLook* look) const;
    void writeImages();
};

// The JSON chunk's text of `model` (its keys in byte order at every level, gltf_json.h), once
// SequenceModel::finish has made what needs the whole sequence: `samplers` per frame its key
// times' and scales' accessors, `far` the farthest apparent point's distance (light-seconds).
std::string jsonChunk(const SequenceModel& model, const std::vector<std::pair<int, int>>& samplers, double far);

// ---- write.cpp ----

// Frame buffers given back by released GlbFrameData, shared by every writer of the process
// (write.cpp).
struct FramePool;
std::shared_ptr<FramePool> processFramePool();

}  // namespace apparent::glb

namespace apparent {

struct GlbFrameData : PreparedFrame, std::enable_shared_from_this<GlbFrameData> {
    // The buffers whose bytes may go into the file as they are (BinSink::borrowable).
    std::vector<std::pair<const char*, const char*>> buffers() const;
    // For a frame of `objects` objects, keeping every vector's capacity.
    void reset(size_t objects);
    double origin[3] = {0, 0, 0};
    double step = 0;       // meshopt: the quantization step (0 without meshopt)
    bool clamped = false;  // meshopt: the step grew to fit int16
    glb::MeshoptFrame meshopt;  // with meshopt: the frame's encoded vertex streams
    std::vector<glb::PrimitiveData> data;  // per object; empty when it shows nothing
    double far = 0, max_extent = 0, max_float_error = 0, max_quantization_error = 0;
};

struct GlbSequenceWriter::Impl {
    Impl(const std::string& p, const SequenceInfo& i, const GlbOptions& o);
    ~Impl();
    // Frames by reference: the ranges of the frame sources this sequence used, freed once read.
    void use(const FileSpan& s);
    void releaseUsed();

    std::string path;
    SequenceInfo info;
    GlbOptions options;
    glb::BinSink sink, count_only;
    glb::SequenceModel model;
    std::unique_ptr<glb::SequenceModel> plain;  // with Draco or meshopt: the same sequence without it, counted
    GlbStats stats;
    double far = 0;
    std::shared_ptr<glb::FramePool> pool = glb::processFramePool();
    std::map<int32_t, std::pair<uint64_t, uint64_t>> used;  // per frame source: [first, end) read from it
};

}  // namespace apparent
