// The .glb writer (GlbSequenceWriter, GlbSink: gltf.h): frames converted on the worker threads
// (prepare), added in order to the model and the BIN chunk (add), the file assembled (finish).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <type_traits>

#include <meshoptimizer.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "exporters/atomic_file.h"
#include "exporters/frame_spill.h"
#include "exporters/glb/glb.h"
#include "mesh4d/box.h"
#include "mesh4d/normals.h"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

namespace apparent::glb {

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

}  // namespace apparent::glb

namespace apparent {

using glb::BinSink;
using glb::copyRange;
using glb::DracoCoded;
using glb::encodeDraco;
using glb::encodeIndexStream;
using glb::encodeMorphRecords;
using glb::FramePool;
using glb::kMeshoptNormalStride;
using glb::kMeshoptViewJsonBytes;
using glb::meshoptStep;
using glb::MeshoptFrame;
using glb::MeshoptLayout;
using glb::morphRecords;
using glb::poolFrames;
using glb::PrepareScratch;
using glb::PrimitiveData;
using glb::runReference;
using glb::SequenceModel;
using glb::toPrimitive;
using mesh4d::Vec3;

namespace {

size_t padded4(size_t n) { return (n + 3) / 4 * 4; }

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

std::vector<std::pair<const char*, const char*>> GlbFrameData::buffers() const {
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
void GlbFrameData::reset(size_t objects) {
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

GlbSequenceWriter::Impl::Impl(const std::string& p, const SequenceInfo& i, const GlbOptions& o)
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

GlbSequenceWriter::Impl::~Impl() {
    if (sink.fd >= 0) ::close(sink.fd);
    releaseUsed();
}

void GlbSequenceWriter::Impl::use(const FileSpan& s) {
    if (s.length == 0) return;
    auto [it, added] = used.emplace(s.source, std::make_pair(s.offset, s.offset + s.length));
    if (!added) {
        it->second.first = std::min(it->second.first, s.offset);
        it->second.second = std::max(it->second.second, s.offset + s.length);
    }
}

void GlbSequenceWriter::Impl::releaseUsed() {
    for (const auto& [source, range] : used) releaseFrameData({source, range.first, range.second - range.first});
    used.clear();
}

GlbSequenceWriter::GlbSequenceWriter(const std::string& path, const SequenceInfo& info, const GlbOptions& options)
    : impl_(std::make_unique<Impl>(path, info, options)) {}

GlbSequenceWriter::~GlbSequenceWriter() = default;

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
        // What add() indexes by: whole vertices, indices within them, the meshopt stream's offsets.
        const size_t nv = p.emission.size();
        ok = ok && p.positions.size() == 3 * nv && p.normals.size() == 3 * nv && p.indices.size() % 3 == 0 &&
             std::all_of(p.indices.begin(), p.indices.end(), [nv](uint32_t i) { return i < nv; }) &&
             p.packed.size() % record == 0 &&
             (!p.ordered || std::all_of(p.ordered->begin(), p.ordered->end(),
                                        [&](uint32_t i) { return size_t(i) < p.packed.size() / record; })) &&
             (!impl_->options.meshopt || f.objects[o].triangles.empty() || p.ordered);
    }
    ok = ok && in.atEnd() && (d.meshopt.first.empty() || d.meshopt.first.size() == d.data.size());
    if (!ok) {
        *error = impl_->path + ": frame data from another process is malformed (frame " + std::to_string(index) + ")";
        return false;
    }
    return add(f, d, error);
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
