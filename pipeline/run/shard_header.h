// The header of a job-array shard file (pipeline/run/shards.h) and the reader of its fields: written
// by a shard's sink, read back by `merge` as untrusted input. The file is the magic line
// "apparent shard 4", then little-endian fields: the fingerprint, part, parts, first and last
// frame (exclusive), the sequence (model, tolerance, fps, scene path, the objects' names, colours,
// material factors and mirrors, the camera, the .glb options, the light, the objects' looks: materials, textures,
// samplers as JSON objects whose references stay within the look, PNG or JPEG images, whether it
// has TEXCOORD_1), then one
// record per frame (tag 1, length, the frame encoded whole: GlbSequenceWriter::encode) and the end
// record (tag 2, the frame count).
// Every field read is checked as the scene's and the command line's are: names against the
// known models, UTF-8 without control characters; finite numbers in range; flags and bits in
// the ranges the options take; lengths and counts against the bytes the file still holds, before
// anything is allocated, read in bounded chunks.
#pragma once

#include <cstdint>
#include <string>

#include "exporters/gltf.h"
#include "pipeline/input/status.h"
#include "pipeline/run/distribute.h"

namespace apparent {

// "I/N" shards: 0 <= I < N <= kMaxShards.
constexpr int kMaxShards = 100000;

extern const std::string kShardMagic;
constexpr uint64_t kShardFrameRecord = 1, kShardEndRecord = 2;

void putShardU64(std::string* out, uint64_t v);
// The sequence and .glb options a shard was made with: merge builds the same .glb writer from them.
void putShardSequence(std::string* out, const SequenceInfo& info, const GlbOptions& o);

// Reads the fields back from a shard file's descriptor (`size`: the file's size); the first
// failure sticks (`ok` false; `overlong` when a length went beyond the limit or the file's end).
class ShardReader {
public:
    ShardReader(int fd, uint64_t size) : fd_(fd), left_(size) {}
    uint64_t u64();
    double real();
    // A length, then that many bytes: at most `limit`, and at most what the file holds.
    std::string bytes(uint64_t limit);
    std::string exact(size_t n);
    uint64_t left() const { return left_; }
    bool ok = true;
    bool overlong = false;

private:
    bool read(void* to, size_t n);
    int fd_;
    uint64_t left_;
};

struct ShardHeader {
    uint64_t fingerprint = 0;
    FrameSplit split;
    long long first = 0, last_excl = 0;
    SequenceInfo info;
    GlbOptions options;
    std::string sequence;  // the sequence's fields as written (putShardSequence)
};

// The header of shard file `path` from `in` (at the file's start), every field checked; fails
// with one line "PATH: ..." naming the field and the problem.
Status readShardHeader(ShardReader* in, const std::string& path, ShardHeader* header);

}  // namespace apparent
