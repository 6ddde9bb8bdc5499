// Job-array shards: `apparent render SCENE --shard I/N --out DIR` renders part I of N of the frames
// (the split of pipeline/run/distribute.h, the one MPI uses) as an independent process, such as one task
// of a Slurm array (docs/slurm_array.sh); `apparent merge DIR` then assembles every model's .glb.
// - PLY and OBJ frames go straight to their final names, DIR/<model>/frame_NNNNN.ply|.obj.
// - The .glb's frames go, encoded (GlbSequenceWriter::encode: the prepared frame, before any
//   cross-frame decision), into DIR/shards/<model>.I-of-N.shard, written under a temporary name and
//   renamed when the shard is complete. merge replays every shard's frames in frame order into the
//   .glb writer, which makes the cross-frame decisions (shared index buffers, Draco) as in one
//   process: the file is byte-identical to a one-process run's.
// - A shard file starts with a fingerprint of the run: the bytes of the scene file and of every mesh
//   it reads, and every setting that changes an output (models, formats, frames, each object's
//   tolerance, --compress and its bits, --attributes, --shade, --cull-view, --max-triangles).
//   merge refuses, with one line and exit code 2, a shard that is missing, duplicated, incomplete,
//   or whose fingerprint differs from the others'.
// - The output budget (--max-output-bytes) and its estimate apply per shard: the estimate from the
//   shard's first 4 frames is scaled to the shard's own frames, and counts what the shard writes
//   (its PLY/OBJ frames and its shard file). merge checks the whole .glb against its own
//   --max-output-bytes before writing it.
// Shard files hold the frames' float32 data and index lists (about the plain .glb's size; meshopt
// frames also their encoded streams); merge keeps one frame at a time in memory.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>

#include "exporters/gltf.h"
#include "pipeline/run/distribute.h"
#include "pipeline/run/shard_header.h"

namespace apparent {

// "I/N" with 0 <= I < N <= kMaxShards into `split`; false when it is not one.
bool parseShard(const std::string& text, FrameSplit* split);

// FNV-1a (64 bits) of the files' bytes and of `settings` (a text listing every setting that changes
// an output), in that order; false with a message naming a file that cannot be read.
bool runFingerprint(const std::vector<std::string>& files, const std::string& settings, uint64_t* fingerprint,
                    std::string* error);

// DIR/shards/<model>.I-of-N.shard
std::string shardPath(const std::string& out_dir, const std::string& model, const FrameSplit& split);

// The .glb's frames of one shard into its shard file (the .glb sink's encoding, appended in order).
std::unique_ptr<FrameSink> glbShardSink(const std::string& out_dir, const std::string& model,
                                        const GlbOptions& options, const FrameSplit& split, uint64_t fingerprint,
                                        long long first, long long last_excl);

struct MergeSettings {
    std::string out_dir;                        // DIR: reads DIR/shards, writes DIR/<model>.glb
    long long max_output_bytes = 2LL << 30;     // the .glb files together (0: no limit)
    bool quiet = false;
    bool verbose = false;
};

// `apparent merge DIR`: every model's shards checked (complete, one of each part, one fingerprint)
// and assembled into DIR/<model>.glb. Exit codes: 0, 2 (a shard missing, duplicated, incomplete or
// foreign: one line naming it), 3 (the .glb cannot be written).
int merge(const MergeSettings& settings, std::ostream& log, std::ostream& err);

}  // namespace apparent
