#include "pipeline/run/shards.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <sstream>
#include <vector>

#include <unistd.h>

#include "exporters/atomic_file.h"
#include "pipeline/input/input_file.h"
#include "pipeline/run/frame_loop.h"
#include "pipeline/stage/stage.h"

namespace apparent {

namespace {

class GlbShardSink final : public FrameSink {
public:
    GlbShardSink(const std::string& out_dir, const std::string& model, const GlbOptions& options,
                 const FrameSplit& split, uint64_t fingerprint, long long first, long long last_excl)
        : path_(shardPath(out_dir, model, split)),
          glb_((std::filesystem::path(out_dir) / (model + ".glb")).string(), options, false),
          options_(options), split_(split), fingerprint_(fingerprint), first_(first), last_excl_(last_excl) {}

    bool begin(const SequenceInfo& info, std::string* error) override {
        if (!glb_.beginEncoding(info, error)) return false;
        std::error_code ec;
        std::filesystem::create_directories(std::filesystem::path(path_).parent_path(), ec);
        if (ec) {
            *error = std::filesystem::path(path_).parent_path().string() + ": cannot create output folder: " + ec.message();
            return false;
        }
        out_ = std::make_unique<AtomicOutput>(path_);
        if (out_->fd() < 0) {
            *error = out_->openError();
            return false;
        }
        std::string head = kShardMagic;
        putShardU64(&head, fingerprint_);
        putShardU64(&head, uint64_t(split_.part));
        putShardU64(&head, uint64_t(split_.parts));
        putShardU64(&head, uint64_t(first_));
        putShardU64(&head, uint64_t(last_excl_));
        putShardSequence(&head, info, options_);
        return write(head, error);
    }
    std::shared_ptr<const PreparedFrame> prepare(const ExportFrame& frame) const override { return glb_.prepare(frame); }
    PendingOutput pending(const ExportFrame& frame) override { return {written_ + leastFrameBytes(frame), path_}; }
    long long estimate(const ExportFrame& frame) const override { return leastFrameBytes(frame); }
    bool add(const ExportFrame& frame, const PreparedFrame* prepared, std::vector<std::string>*,
             std::string* error) override {
        const EncodedOutput e = glb_.encode(frame, prepared);
        std::string record;
        putShardU64(&record, kShardFrameRecord);
        putShardU64(&record, e.bytes.size());
        return write(record, error) && write(e.bytes, error) && (++frames_, true);
    }
    bool finish(SinkSummary* summary, std::string* error) override {
        std::string end;
        putShardU64(&end, kShardEndRecord);
        putShardU64(&end, frames_);
        if (!write(end, error)) return false;
        if (::fsync(out_->fd()) != 0) {
            *error = path_ + ": cannot write: " + std::strerror(errno);
            return false;
        }
        if (check_ && !check_(0, path_, error)) return false;
        if (!out_->commit(error)) return false;
        summary->completed.push_back(path_);
        summary->text = ", " + path_ + " (shard " + std::to_string(split_.part) + "/" + std::to_string(split_.parts) +
                        ": " + std::to_string(frames_) + " of " + std::to_string(last_excl_ - first_) + " frames)";
        return true;
    }
    void setFinishCheck(OutputCheck check) override { check_ = std::move(check); }
    bool readsLightFactors() const override { return glb_.readsLightFactors(); }
    bool readsRestPoints() const override { return glb_.readsRestPoints(); }
    bool canHoldCommits() const override { return true; }  // the shard appears in finish() only

private:
    bool write(const std::string& bytes, std::string* error) {
        std::string e;
        if (!writeAll(out_->fd(), bytes.data(), bytes.size(), &e)) {
            *error = path_ + ": cannot write: " + e;
            return false;
        }
        written_ += (long long)bytes.size();
        return true;
    }

    std::string path_;
    GlbSink glb_;  // its encoding only (beginEncoding, prepare, encode)
    GlbOptions options_;
    FrameSplit split_;
    uint64_t fingerprint_;
    long long first_, last_excl_;
    std::unique_ptr<AtomicOutput> out_;
    long long written_ = 0;
    uint64_t frames_ = 0;
    OutputCheck check_;
};

// One shard file opened for merging: its header, then frames read one at a time.
struct OpenShard : ShardHeader {
    std::string path;
    int fd = -1;
    std::unique_ptr<ShardReader> in;
    ~OpenShard() {
        if (fd >= 0) ::close(fd);
    }
};

std::string hex(uint64_t v) {
    std::ostringstream os;
    os << std::hex << v;
    return os.str();
}

}  // namespace

bool parseShard(const std::string& text, FrameSplit* split) {
    const auto slash = text.find('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == text.size()) return false;
    const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
    if (!std::all_of(a.begin(), a.end(), ::isdigit) || !std::all_of(b.begin(), b.end(), ::isdigit) || a.size() > 6 ||
        b.size() > 6)
        return false;
    const int i = std::stoi(a), n = std::stoi(b);
    if (n < 1 || n > kMaxShards || i >= n) return false;
    *split = FrameSplit{i, n};
    return true;
}

bool runFingerprint(const std::vector<std::string>& files, const std::string& settings, uint64_t* fingerprint,
                    std::string* error) {
    uint64_t h = 1469598103934665603ull;  // FNV-1a 64 offset basis
    auto mix = [&h](const char* p, size_t n) {
        for (size_t i = 0; i < n; ++i) {
            h ^= uint8_t(p[i]);
            h *= 1099511628211ull;  // FNV-1a 64 prime
        }
    };
    std::vector<char> buffer(size_t(1) << 20);
    for (const std::string& f : files) {
        std::ifstream in(f, std::ios::binary);
        if (!in) {
            *error = f + ": cannot read it again for the shard's fingerprint";
            return false;
        }
        while (in) {
            in.read(buffer.data(), std::streamsize(buffer.size()));
            mix(buffer.data(), size_t(in.gcount()));
        }
        mix("\0", 1);  // file boundary
    }
    mix(settings.data(), settings.size());
    *fingerprint = h;
    return true;
}

std::string shardPath(const std::string& out_dir, const std::string& model, const FrameSplit& split) {
    return (std::filesystem::path(out_dir) / "shards" /
            (model + "." + std::to_string(split.part) + "-of-" + std::to_string(split.parts) + ".shard"))
        .string();
}

std::unique_ptr<FrameSink> glbShardSink(const std::string& out_dir, const std::string& model,
                                        const GlbOptions& options, const FrameSplit& split, uint64_t fingerprint,
                                        long long first, long long last_excl) {
    return std::make_unique<GlbShardSink>(out_dir, model, options, split, fingerprint, first, last_excl);
}

int merge(const MergeSettings& settings, std::ostream& log, std::ostream& err) {
    const std::filesystem::path folder = std::filesystem::path(settings.out_dir) / "shards";
    auto refuse = [&err](const std::string& message) {
        err << "error: " << message << "\n";
        return kExitBadInput;
    };
    // Step: every shard file's header, grouped by model.
    std::error_code ec;
    std::vector<std::string> names;
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
        if (it->path().extension() == ".shard") names.push_back(it->path().string());
    std::sort(names.begin(), names.end());
    if (names.empty())
        return refuse(folder.string() + ": no shard files (*.shard) to merge; render them with --shard I/N --out " +
                      settings.out_dir);
    std::map<std::string, std::vector<std::unique_ptr<OpenShard>>> models;
    const OpenShard* reference = nullptr;  // the first shard: every other must match its fingerprint
    for (const std::string& name : names) {
        auto s = std::make_unique<OpenShard>();
        s->path = name;
        // Only regular files (a FIFO or device named *.shard is refused, never waited on).
        uint64_t size = 0;
        if (Status st = openRegularFile(name, &s->fd, &size, "shard file"); !st.ok) return refuse(st.message);
        s->in = std::make_unique<ShardReader>(s->fd, size);
        if (Status st = readShardHeader(s->in.get(), name, s.get()); !st.ok) return refuse(st.message);
        if (reference && s->fingerprint != reference->fingerprint)
            return refuse(name + ": from another scene or option set than " + reference->path + " (fingerprint " +
                          hex(s->fingerprint) + ", not " + hex(reference->fingerprint) +
                          "); render every shard with the same scene, meshes and options");
        if (!reference) reference = s.get();
        models[s->info.model].push_back(std::move(s));
    }
    // Step: per model, one shard of each part, all of one split.
    for (auto& [model, shards] : models) {
        const int parts = shards.front()->split.parts;
        std::vector<const OpenShard*> by_part(size_t(parts), nullptr);
        for (const auto& s : shards) {
            if (s->first != shards.front()->first || s->last_excl != shards.front()->last_excl ||
                s->sequence != shards.front()->sequence)
                return refuse(s->path + ": shard header differs from " + shards.front()->path +
                              "'s (frames, camera, objects or options) under the same fingerprint");
            if (s->split.parts != parts)
                return refuse(s->path + ": shard " + std::to_string(s->split.part) + "/" + std::to_string(s->split.parts) +
                              ", but " + shards.front()->path + " is one of " + std::to_string(parts) + " shards");
            if (by_part[size_t(s->split.part)])
                return refuse(s->path + ": shard " + std::to_string(s->split.part) + "/" + std::to_string(parts) +
                              " of model " + model + " again (also " + by_part[size_t(s->split.part)]->path + ")");
            by_part[size_t(s->split.part)] = s.get();
        }
        for (int p = 0; p < parts; ++p)
            if (!by_part[size_t(p)])
                return refuse(folder.string() + ": shard " + std::to_string(p) + "/" + std::to_string(parts) +
                              " of model " + model + " is missing (render it with --shard " + std::to_string(p) + "/" +
                              std::to_string(parts) + ")");
    }
    // Step: per model, the frames in order from their shards into the .glb writer, then the file.
    OutputBudget budget(settings.max_output_bytes);
    for (auto& [model, shards] : models) {
        std::sort(shards.begin(), shards.end(),
                  [](const auto& a, const auto& b) { return a->split.part < b->split.part; });
        const OpenShard& head = *shards.front();
        const std::string path = (std::filesystem::path(settings.out_dir) / (model + ".glb")).string();
        GlbSink sink(path, head.options, settings.verbose);
        std::string error;
        sink.begin(head.info, &error);
        const FrameSplit all{0, head.split.parts};
        for (long long k = head.first; k < head.last_excl; ++k) {
            OpenShard& s = *shards[size_t(all.partOf(k, head.first))];
            ShardReader& r = *s.in;
            const uint64_t tag = r.u64();
            EncodedOutput frame;
            if (tag == kShardFrameRecord) frame.bytes = r.bytes(uint64_t(1) << 40);
            if (r.overlong)
                return refuse(s.path + ": frame " + std::to_string(k) + "'s record claims more bytes than the file holds");
            if (!r.ok || tag != kShardFrameRecord)
                return refuse(s.path + ": incomplete shard: frame " + std::to_string(k) + " is missing");
            // Each record carries its frame: placed by it, so a gap, a repeat or disorder is refused.
            long long carried = 0;
            size_t objects = 0;
            if (!encodedFrameHead(frame.bytes, &carried, &objects))
                return refuse(s.path + ": frame " + std::to_string(k) + "'s record is not a frame of a shard");
            if (carried != k)
                return refuse(s.path + ": frame record " + std::to_string(carried) + " where frame " +
                              std::to_string(k) + " belongs (frames missing, repeated or out of order)");
            if (objects != head.info.objects.size())
                return refuse(s.path + ": frame " + std::to_string(k) + " has " + std::to_string(objects) +
                              " objects, the header " + std::to_string(head.info.objects.size()));
            std::vector<std::string> completed;
            if (!sink.addEncoded(k, frame, &completed, &error)) {
                // A frame the writer cannot read is the shard's fault; a spill-file error is the output's.
                if (error.find("malformed") != std::string::npos) return refuse(s.path + ": " + error);
                err << "error: " << error << "\n";
                return kExitOutputError;
            }
        }
        for (const auto& s : shards) {
            ShardReader& r = *s->in;
            const uint64_t tag = r.u64(), frames = r.u64();
            if (!r.ok || tag != kShardEndRecord || frames != uint64_t(s->split.count(s->first, s->last_excl)) ||
                r.left() != 0)
                return refuse(s->path + ": shard does not end after its " +
                              std::to_string(s->split.count(s->first, s->last_excl)) + " frames");
        }
        sink.setFinishCheck([&budget](long long bytes, const std::string& name, std::string* e) {
            return budget.fits(bytes, name, e);
        });
        SinkSummary summary;
        if (!sink.finish(&summary, &error) || !budget.count(path, &error)) {
            err << "error: " << error << "\n";
            return kExitOutputError;
        }
        if (!settings.quiet) {
            for (const std::string& w : summary.warnings) err << "warning: " << w << "\n";
            log << model << ": " << (head.last_excl - head.first) << " frames merged from " << head.split.parts
                << " shards" << summary.text << "\n";
        }
    }
    return kExitOk;
}

}  // namespace apparent
