// libFuzzer harness for the job-array shard reader (pipeline/run/shard_header.h), what `merge` reads
// first of every shard: the input bytes become a .shard file, opened as merge opens it (a regular
// file, its size known), its header read and checked, then its frame records and end record read
// as merge reads them (lengths bounded by the file). A refusal must be one line starting with the
// path; an accepted header must hold what merge relies on (a known model, finite numbers in range,
// names valid UTF-8 without control characters, a light of finite numbers with its shares in
// [0, 1], a shard I/N, a range of frames). Seeds: the shards
// of data/fixtures/scene_tetra.json in tests/fuzz/shard_seeds (plain, Draco, meshopt).
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <unistd.h>

#include "pipeline/input/input_file.h"
#include "pipeline/input/json_limits.h"
#include "pipeline/input/scene.h"
#include "pipeline/run/shard_header.h"
#include "tests/fuzz/fuzz_input.h"

namespace {

void check(bool condition) {
    if (!condition) std::abort();  // libFuzzer reports the input as a crash
}

void checkName(const std::string& name) {
    check(apparent::isValidUtf8(name));
    for (unsigned char c : name) check(c >= 0x20 && c != 0x7f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    apparent_fuzz::removeInputFolderAtExit();
    const std::string path = apparent_fuzz::writeInput(data, size, ".shard");
    int fd = -1;
    uint64_t bytes = 0;
    check(apparent::openRegularFile(path, &fd, &bytes, "shard file").ok);
    check(bytes == size);
    apparent::ShardReader in(fd, bytes);
    apparent::ShardHeader h;
    const apparent::Status st = apparent::readShardHeader(&in, path, &h);
    if (!st.ok) {
        check(st.message.rfind(path, 0) == 0 && st.message.find('\n') == std::string::npos);
    } else {
        apparent::Model model;
        check(apparent::parseModel(h.info.model, &model));
        check(std::isfinite(h.info.fps) && h.info.fps > 0 && std::isfinite(h.info.tolerance) && h.info.tolerance >= 0);
        check(apparent::isValidUtf8(h.info.scene_path));
        check(!h.info.objects.empty());
        for (const apparent::ExportObject& o : h.info.objects) {
            checkName(o.name);
            checkName(o.mirror);
            for (double c : o.base_color) check(c >= 0 && c <= 1);
            check(o.mirror_index >= -1 && o.mirror_index < int(h.info.objects.size()));
        }
        check(h.info.camera.fov_deg > 0 && h.info.camera.fov_deg < 180);
        const apparent::ExportLight& l = h.info.light;
        for (double c : {l.position.x, l.position.y, l.position.z, l.direction.x, l.direction.y, l.direction.z,
                         l.key_direction.x, l.key_direction.y, l.key_direction.z})
            check(std::isfinite(c));
        check(l.ambient >= 0 && l.ambient <= 1 && l.key_weight >= 0 && l.key_weight <= 1);
        check(h.split.parts >= 1 && h.split.part >= 0 && h.split.part < h.split.parts);
        check(h.first >= 0 && h.last_excl > h.first);
        check(h.options.position_bits >= 1 && h.options.position_bits <= 30 && !(h.options.draco && h.options.meshopt));
        // The records, as merge reads them: never more than the file holds.
        for (long long k = 0; k < h.split.count(h.first, h.last_excl) && in.ok; ++k) {
            const uint64_t tag = in.u64();
            if (tag != apparent::kShardFrameRecord) break;
            const std::string frame = in.bytes(uint64_t(1) << 40);
            check(!in.ok || frame.size() <= size);
        }
        in.u64();
        in.u64();
        check(in.left() <= size);
    }
    ::close(fd);
    return 0;
}
