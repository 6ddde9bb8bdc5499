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
using glb::encodeDraco;
using glb::encodeFrameStreams;
using glb::FramePool;
using glb::meshoptStep;
using glb::MeshoptFrame;
using glb::MeshoptLayout;
using glb::poolFrames;
using glb::PrepareScratch;
using glb::PrimitiveData;
using glb::SequenceModel;
using glb::toPrimitive;
using mesh4d::Vec3;

namespace {

size_t padded4(size_t n) { return (n + 3) / 4 * 4; }

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
    : path(p), info(i), options(glb::withMeshoptLooks(o, i)), model(info, options, &sink) {
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
                            impl_->info.objects[o]);
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
            encodeFrameStreams(d->data, MeshoptLayout(impl_->options).stride, &scratch->meshopt, &d->meshopt);
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
    reads_rest_points_ = false;
    for (const ExportObject& o : info.objects) reads_rest_points_ = reads_rest_points_ || glb::carriesLook(options_, o);
    options_ = glb::withMeshoptLooks(options_, info);
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
    if (options_.draco && verbose_ && stats.texcoords)
        os << "; Draco texture-coordinate error <= " << stats.max_texcoord_error;
    if (options_.meshopt && verbose_) os << "; meshopt position error <= " << stats.max_quantization_error << " ls";
    if (options_.meshopt && verbose_ && stats.texcoords) os << "; meshopt texture coordinates float32 (error 0)";
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

bool writeAnimatedGlb(const std::string& path, const std::vector<ExportFrame>& frames, const SequenceInfo& info,
                      const GlbOptions& options, GlbStats* stats, std::string* error) {
    GlbSequenceWriter writer(path, info, options);
    for (const ExportFrame& f : frames)
        if (!writer.add(f, error)) return false;
    return writer.finish(stats, error);
}

}  // namespace apparent
