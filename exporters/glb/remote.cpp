// Frames across processes (GlbSequenceWriter::encode, addEncoded: gltf.h): a prepared frame as
// bytes, whole or by reference to the arrays in its process's frame spill, and the frame such
// bytes stand for, added where the file is written.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <type_traits>

#include "exporters/frame_spill.h"
#include "exporters/glb/glb.h"

#include <sys/uio.h>

namespace apparent {

using glb::DracoCoded;
using glb::encodeIndexStream;
using glb::encodeMorphRecords;
using glb::MeshoptFrame;
using glb::MeshoptLayout;
using glb::morphRecords;
using glb::PrimitiveData;
using glb::runReference;

namespace {

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

}  // namespace

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
    out->put(dc.texcoord_error);
    out->put(uint64_t(dc.parts.size()));
    for (const DracoCoded::Part& p : dc.parts) {
        for (uint64_t v : {p.offset, p.length, p.points, p.faces}) out->put(v);
        for (int c = 0; c < 3; ++c) out->put(p.lo[c]);
        for (int c = 0; c < 3; ++c) out->put(p.hi[c]);
    }
    putText(out, dc.error);
}
bool getText(FrameBytesIn* in, std::string* text) {
    std::vector<char> v;
    if (!in->getVector(&v)) return false;
    text->assign(v.begin(), v.end());
    return true;
}
// putDracoFacts' facts back; the parts must lie one after another within the `length` bytes of
// the coding.
bool getDracoFacts(FrameBytesIn* in, DracoCoded* dc, uint64_t length) {
    bool ok = in->get(&dc->points) && in->get(&dc->faces);
    for (int c = 0; ok && c < 3; ++c) ok = in->get(&dc->lo[c]);
    for (int c = 0; ok && c < 3; ++c) ok = in->get(&dc->hi[c]);
    for (int a = 0; ok && a < DracoCoded::kIds; ++a) ok = in->get(&dc->ids[a]);
    uint64_t parts = 0;
    ok = ok && in->get(&dc->quantization_error) && in->get(&dc->texcoord_error) && in->get(&parts) && parts <= length;
    uint64_t end = 0;
    for (uint64_t i = 0; ok && i < parts; ++i) {
        DracoCoded::Part& p = dc->parts.emplace_back();
        ok = in->get(&p.offset) && in->get(&p.length) && in->get(&p.points) && in->get(&p.faces) && p.offset == end &&
             p.length <= length - end;
        end += ok ? p.length : 0;
        for (int c = 0; ok && c < 3; ++c) ok = in->get(&p.lo[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in->get(&p.hi[c]);
    }
    return ok && getText(in, &dc->error);
}

// The materials of object `o`'s look the file carries (0: none, so no parts).
size_t lookMaterials(const SequenceInfo& info, const GlbOptions& options, size_t o) {
    return o < info.objects.size() && glb::carriesLook(options, info.objects[o]) ? info.objects[o].look->materials.size() : 0;
}

// A frame's material parts as add() takes them (PrimitiveData::part_first): none, or increasing
// triangle offsets from 0 to the index count's triangles, each part in one of `materials`.
bool validParts(const PrimitiveData& p, uint64_t index_count, size_t materials) {
    if (p.part_first.empty()) return p.part_material.empty();
    if (p.part_first.size() != p.part_material.size() + 1 || p.part_first.front() != 0 ||
        3 * uint64_t(p.part_first.back()) != index_count)
        return false;
    for (size_t i = 0; i + 1 < p.part_first.size(); ++i)
        if (p.part_first[i + 1] <= p.part_first[i] || p.part_material[i] >= materials) return false;
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
        piece(p.texcoords);
        piece(p.texcoords1);
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
        for (int i = 0; i < 11; ++i) putSpan(&out, spans[k++]);
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
        out.putVector(p.part_first);
        out.putVector(p.part_material);
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
                            &r.draco, &r.ordered, &r.texcoords, &r.texcoords1})
            ok = ok && getSpan(&in, s);
        ok = ok && in.get(&r.vertices) && in.get(&r.index_count) && in.get(&r.packed_vertices) &&
             in.get(&r.ordered_count);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&r.lo[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&r.hi[c]);
        ok = ok && in.get(&r.index_hash[0]) && in.get(&r.index_hash[1]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmin[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmax[c]);
        ok = ok && getDracoFacts(&in, &p.draco, r.draco.length) && in.getVector(&p.part_first) &&
             in.getVector(&p.part_material) && validParts(p, r.index_count, lookMaterials(impl_->info, impl_->options, o)) &&
             (p.draco.parts.empty() || p.draco.parts.size() == p.part_material.size());
        // What add() takes of the spans: whole vertices and triangles, every source known.
        const uint64_t nv = r.vertices;
        auto optional = [nv](const FileSpan& s, uint64_t per) { return s.length == 0 || s.length == per * nv; };
        ok = ok && r.positions.length == 12 * nv && r.normals.length == 12 * nv && r.emission.length == 4 * nv &&
             optional(r.doppler, 4) && optional(r.proper_time, 4) && optional(r.colors, 12) && optional(r.texcoords, 8) &&
             optional(r.texcoords1, 8) &&
             r.indices.length == 4 * r.index_count && r.index_count % 3 == 0 &&
             (r.ordered.length == 0 || r.ordered.length == 4 * r.ordered_count);
        for (const FileSpan* s : {&r.positions, &r.normals, &r.emission, &r.doppler, &r.proper_time, &r.colors,
                                  &r.indices, &r.draco, &r.ordered, &r.texcoords, &r.texcoords1})
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
        for (const auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors, &p.texcoords,
                                &p.texcoords1})
            out.putVector(*v);
        out.putVector(p.indices);
        out.putVector(p.part_first);
        out.putVector(p.part_material);
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
        for (auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors, &p.texcoords,
                                &p.texcoords1})
            ok = ok && in.getVector(v);
        uint8_t has_ordered = 0;
        ok = ok && in.getVector(&p.indices) && in.getVector(&p.part_first) && in.getVector(&p.part_material) &&
             validParts(p, p.indices.size(), lookMaterials(impl_->info, impl_->options, o)) && in.getVector(&p.packed) && in.getVector(&p.packed_normals) &&
             in.getVector(&p.packed_snorm) && in.get(&has_ordered);
        if (ok && has_ordered) {
            auto ordered = std::make_shared<std::vector<uint32_t>>();
            ok = in.getVector(ordered.get());
            p.ordered = std::move(ordered);
        }
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmin[c]);
        for (int c = 0; ok && c < 3; ++c) ok = in.get(&p.qmax[c]);
        DracoCoded& dc = p.draco;
        ok = ok && in.getVector(&dc.bytes) && getDracoFacts(&in, &dc, dc.bytes.size()) &&
             (dc.parts.empty() || dc.parts.size() == p.part_material.size());
        // What add() writes as it is: finite attributes (a NaN gives an invalid accessor).
        for (const auto* v : {&p.positions, &p.normals, &p.emission, &p.doppler, &p.proper_time, &p.colors, &p.texcoords,
                                &p.texcoords1})
            ok = ok && std::all_of(v->begin(), v->end(), [](float x) { return std::isfinite(x); });
        // What add() indexes by: whole vertices, indices within them, the meshopt stream's offsets.
        const size_t nv = p.emission.size();
        auto optional = [nv](const std::vector<float>& v, size_t per) { return v.empty() || v.size() == per * nv; };
        ok = ok && p.positions.size() == 3 * nv && p.normals.size() == 3 * nv && p.indices.size() % 3 == 0 &&
             optional(p.doppler, 1) && optional(p.proper_time, 1) && optional(p.colors, 3) &&
             optional(p.texcoords, 2) && optional(p.texcoords1, 2) &&
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

}  // namespace apparent
