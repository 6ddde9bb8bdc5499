#include "pipeline/run/mpi_group.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include <mpi.h>
#include <unistd.h>

#include "pipeline/run/distribute.h"

namespace apparent {

namespace {

// Message tags of the protocol (distribute.h).
constexpr int kTagFrame = 1;  // 8 bytes per part: the parts' sizes; each part follows in kTagChunk messages
constexpr int kTagChunk = 2;
constexpr int kTagError = 3;  // int32 exit code, then the one-line message
constexpr int kTagDone = 4;   // empty: no more frames from this rank
constexpr int kTagEnd = 5;    // int32: rank 0's code for the loop
constexpr int kTagAgree = 6;  // the message of the lowest failing rank, for rank 0
constexpr int kTagPlace = 7;  // the temporary file's path, then (source, offset, length, to) per placement
constexpr int kTagPlaced = 8; // int32 status (0: placed), then the message
constexpr int kTagFrameInOne = 9;  // a frame of at most kInOneBytes: 8 bytes its part count, 8 per part its size, the parts
constexpr size_t kChunk = size_t(1) << 30;  // MPI counts are int: frames go in pieces of 1 GiB
// A frame up to this size in all travels as one message (a description of frames by reference or
// of a file its rank wrote is under 1 KiB an object): rank 0 receives it whole at once, instead of
// its sizes and then each part, each of which it may have to wait for while the rank sends it.
constexpr size_t kInOneBytes = size_t(1) << 20;

class MpiFrameGroup final : public FrameGroup {
public:
    MpiFrameGroup() {
        MPI_Comm_dup(MPI_COMM_WORLD, &comm_);
        MPI_Comm_rank(comm_, &rank_);
        MPI_Comm_size(comm_, &size_);
        done_.assign(size_t(size_), false);
    }
    ~MpiFrameGroup() override = default;

    int rank() const override { return rank_; }
    int size() const override { return size_; }

    int agree(int code, std::string* error) override {
        const int mine = code ? rank_ : size_;
        int lowest = size_;
        MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, comm_);
        if (lowest == size_) return 0;
        int agreed = code;
        MPI_Bcast(&agreed, 1, MPI_INT, lowest, comm_);
        if (lowest != 0 && rank_ == lowest)
            MPI_Send(error->data(), int(std::min(error->size(), size_t(1) << 20)), MPI_CHAR, 0, kTagAgree, comm_);
        if (lowest != 0 && rank_ == 0) {
            *error = receiveBytes(lowest, kTagAgree);
            *error += " (rank " + std::to_string(lowest) + ")";
        }
        return agreed;
    }

    std::string broadcast(const std::string& text) override {
        uint64_t n = text.size();
        MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm_);
        std::string out = rank_ == 0 ? text : std::string(size_t(n), '\0');
        MPI_Bcast(n ? &out[0] : nullptr, int(n), MPI_CHAR, 0, comm_);
        return out;
    }

    bool stopRequested() override {
        int flag = 0;
        MPI_Iprobe(0, kTagEnd, comm_, &flag, MPI_STATUS_IGNORE);
        return flag != 0;
    }

    void sendParts(const std::vector<std::string_view>& parts) override {
        // Synchronous: it returns once rank 0 has started to receive this frame, so a rank is never
        // more than one frame ahead of the writer, however small its frames (a plain send of a
        // message under the eager limit would return at once and let frames pile up on rank 0).
        size_t whole = 8 * (parts.size() + 1);
        for (const std::string_view& p : parts) whole += p.size();
        if (whole <= kInOneBytes) {
            in_one_.clear();
            putU64(&in_one_, parts.size());
            for (const std::string_view& p : parts) putU64(&in_one_, p.size());
            for (const std::string_view& p : parts) in_one_.append(p);
            MPI_Ssend(in_one_.data(), int(in_one_.size()), MPI_BYTE, 0, kTagFrameInOne, comm_);
            return;
        }
        std::vector<uint64_t> sizes;
        for (const std::string_view& p : parts) sizes.push_back(p.size());
        MPI_Ssend(sizes.data(), int(8 * sizes.size()), MPI_BYTE, 0, kTagFrame, comm_);
        for (const std::string_view& p : parts)
            for (size_t at = 0; at < p.size(); at += kChunk)
                MPI_Send(p.data() + at, int(std::min(kChunk, p.size() - at)), MPI_BYTE, 0, kTagChunk, comm_);
    }

    void sendError(int code, const std::string& message) override {
        std::string m(4, '\0');
        const int32_t c = code;
        std::memcpy(&m[0], &c, 4);
        m += message.substr(0, size_t(1) << 20);
        MPI_Send(m.data(), int(m.size()), MPI_CHAR, 0, kTagError, comm_);
    }

    int finishSending() override {
        MPI_Send(nullptr, 0, MPI_BYTE, 0, kTagDone, comm_);
        // Until END: rank 0 may have this rank place its frames' data into a file (placeOnRanks).
        for (;;) {
            MPI_Status status;
            MPI_Probe(0, MPI_ANY_TAG, comm_, &status);
            if (status.MPI_TAG != kTagPlace) break;
            const std::string job = receiveBytes(0, kTagPlace);
            std::string path, error;
            std::vector<Placement> placements;
            bool ok = parsePlace(job, &path, &placements);
            if (!ok) error = "internal: a malformed placement from rank 0";
            ok = ok && placeHere(path, placements, &error);
            std::string reply(4, '\0');
            const int32_t c = ok ? 0 : 1;
            std::memcpy(&reply[0], &c, 4);
            reply += error.substr(0, size_t(1) << 20);
            MPI_Send(reply.data(), int(reply.size()), MPI_CHAR, 0, kTagPlaced, comm_);
        }
        int32_t code = 0;
        MPI_Recv(&code, 1, MPI_INT32_T, 0, kTagEnd, comm_, MPI_STATUS_IGNORE);
        return code;
    }

    bool placeOnRanks(const std::string& path, const std::vector<Placement>& placements, std::string* error) override {
        // Step: each rank's placements to it (sources are ranks), then rank 0's own, then the answers.
        std::vector<std::vector<Placement>> by_rank(static_cast<size_t>(size_));
        for (const Placement& p : placements) {
            if (p.from.source < 0 || p.from.source >= size_) {
                *error = "internal: frame data of an unknown rank (" + std::to_string(p.from.source) + ")";
                return false;
            }
            by_rank[size_t(p.from.source)].push_back(p);
        }
        std::vector<int> asked;
        for (int r = 1; r < size_; ++r) {
            if (by_rank[size_t(r)].empty()) continue;
            std::string job;
            putU64(&job, path.size());
            job += path;
            for (const Placement& p : by_rank[size_t(r)])
                for (uint64_t v : {uint64_t(uint32_t(p.from.source)), p.from.offset, p.from.length, p.to}) putU64(&job, v);
            MPI_Send(job.data(), int(job.size()), MPI_BYTE, r, kTagPlace, comm_);
            asked.push_back(r);
        }
        bool ok = placeHere(path, by_rank[0], error);
        for (const int r : asked) {
            const std::string reply = receiveBytes(r, kTagPlaced);
            int32_t c = 1;
            if (reply.size() >= 4) std::memcpy(&c, reply.data(), 4);
            if (c != 0 && ok) {
                *error = (reply.size() > 4 ? reply.substr(4) : std::string("failed")) + " (rank " + std::to_string(r) + ")";
                ok = false;
            }
        }
        return ok;
    }

    void awaitFrame(int from) override { MPI_Probe(from, MPI_ANY_TAG, comm_, MPI_STATUS_IGNORE); }

    bool receiveParts(int from, std::vector<std::string>* parts, int* code, std::string* error) override {
        MPI_Status status;
        MPI_Probe(from, MPI_ANY_TAG, comm_, &status);
        if (status.MPI_TAG == kTagFrame || status.MPI_TAG == kTagFrameInOne) {
            receiveFrameBody(from, status.MPI_TAG, parts);
            return true;
        }
        if (status.MPI_TAG == kTagError) {
            const std::string m = receiveBytes(from, kTagError);
            int32_t c = 1;
            if (m.size() >= 4) std::memcpy(&c, m.data(), 4);
            *code = c ? c : 1;
            *error = m.size() > 4 ? m.substr(4) : "rank " + std::to_string(from) + " failed";
            return false;
        }
        // DONE before its frames: a protocol error (a rank that stopped early without ERROR).
        receiveBytes(from, status.MPI_TAG);
        if (status.MPI_TAG == kTagDone) done_[size_t(from)] = true;
        *code = 1;
        *error = "internal: rank " + std::to_string(from) + " stopped sending frames";
        return false;
    }

    void endFrames(int code) override {
        // END to every rank first (a rank stuck in a send is unblocked by the drain below).
        const int32_t c = code;
        std::vector<MPI_Request> requests;
        for (int r = 1; r < size_; ++r) {
            requests.emplace_back();
            MPI_Isend(&c, 1, MPI_INT32_T, r, kTagEnd, comm_, &requests.back());
        }
        for (int r = 1; r < size_; ++r) {
            while (!done_[size_t(r)]) {
                MPI_Status status;
                MPI_Probe(r, MPI_ANY_TAG, comm_, &status);
                if (status.MPI_TAG == kTagFrame || status.MPI_TAG == kTagFrameInOne) {
                    std::vector<std::string> discarded;
                    receiveFrameBody(r, status.MPI_TAG, &discarded);
                } else {
                    receiveBytes(r, status.MPI_TAG);
                    if (status.MPI_TAG == kTagDone) done_[size_t(r)] = true;
                }
            }
        }
        MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
        done_.assign(size_t(size_), false);  // the next model's loop
    }

private:
    static void putU64(std::string* out, uint64_t v) {
        for (int i = 0; i < 8; ++i) out->push_back(char((v >> (8 * i)) & 0xff));
    }
    static uint64_t getU64(const std::string& in, size_t at) {
        uint64_t v = 0;
        for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(in[at + size_t(i)])) << (8 * i);
        return v;
    }
    // A PLACE message (placeOnRanks) back into its path and placements.
    static bool parsePlace(const std::string& job, std::string* path, std::vector<Placement>* placements) {
        if (job.size() < 8) return false;
        const uint64_t n = getU64(job, 0);
        if (n > job.size() - 8 || (job.size() - 8 - n) % 32 != 0) return false;
        *path = job.substr(8, size_t(n));
        for (size_t at = 8 + size_t(n); at < job.size(); at += 32) {
            Placement p;
            p.from.source = int32_t(uint32_t(getU64(job, at)));
            p.from.offset = getU64(job, at + 8);
            p.from.length = getU64(job, at + 16);
            p.to = getU64(job, at + 24);
            placements->push_back(p);
        }
        return true;
    }

    // A whole message of `tag` from `from` (its size probed first).
    std::string receiveBytes(int from, int tag) {
        MPI_Status status;
        MPI_Probe(from, tag, comm_, &status);
        int n = 0;
        MPI_Get_count(&status, MPI_BYTE, &n);
        std::string s(size_t(n), '\0');
        MPI_Recv(n ? &s[0] : nullptr, n, MPI_BYTE, from, tag, comm_, MPI_STATUS_IGNORE);
        return s;
    }
    // A frame of `tag`: in one message, its parts copied out (none when the message is malformed:
    // frameFromParts then refuses it); else the sizes message, then each part's pieces, received
    // into the part's own string.
    void receiveFrameBody(int from, int tag, std::vector<std::string>* parts) {
        if (tag == kTagFrameInOne) {
            const std::string m = receiveBytes(from, kTagFrameInOne);
            parts->clear();
            const uint64_t count = m.size() >= 8 ? getU64(m, 0) : 0;
            if (count == 0 || count > (m.size() - 8) / 8) return;
            size_t at = 8 + 8 * size_t(count);
            parts->resize(size_t(count));
            for (size_t i = 0; i < parts->size(); ++i) {
                const uint64_t n = getU64(m, 8 + 8 * i);
                if (n > m.size() - at) {
                    parts->clear();
                    return;
                }
                (*parts)[i].assign(m, at, size_t(n));
                at += size_t(n);
            }
            if (at != m.size()) parts->clear();
            return;
        }
        const std::string sizes = receiveBytes(from, kTagFrame);
        parts->resize(sizes.size() / 8);
        for (size_t i = 0; i < parts->size(); ++i) {
            uint64_t n = 0;
            std::memcpy(&n, sizes.data() + 8 * i, 8);
            std::string& part = (*parts)[i];
            part.resize(size_t(n));
            for (size_t at = 0; at < part.size(); at += kChunk)
                MPI_Recv(&part[at], int(std::min(kChunk, part.size() - at)), MPI_BYTE, from, kTagChunk, comm_,
                         MPI_STATUS_IGNORE);
        }
    }

    MPI_Comm comm_ = MPI_COMM_NULL;
    int rank_ = 0, size_ = 1;
    std::vector<bool> done_;  // per rank: its DONE received in this loop
    std::string in_one_;      // a rank: its last frame sent in one message (kept: no allocation per frame)
};

bool started = false;

}  // namespace

bool launchedByMpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(v)) return true;
    return false;
}

void startMpiGroup(int* argc, char*** argv) {
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
    started = true;
    setFrameGroup(std::make_unique<MpiFrameGroup>());
}

bool mpiRankZero() { return frameGroup().rank() == 0; }

int finishMpiGroup(int code) {
    if (!started) return code;
    std::cout.flush();
    std::cerr.flush();
    // Every rank that got this far meets in a barrier: then the job ends as one, each rank with
    // the code rank 0 gave it (after END or the stage agreement). A rank that does not arrive
    // within kSettleSeconds is stuck where rank 0 left the protocol (an exception on rank 0):
    // rank 0 then aborts the job with its code.
    constexpr double kSettleSeconds = 10;
    MPI_Request barrier;
    MPI_Ibarrier(MPI_COMM_WORLD, &barrier);
    int arrived = 0;
    const double start = MPI_Wtime();
    while (!arrived) {
        MPI_Test(&barrier, &arrived, MPI_STATUS_IGNORE);
        if (!arrived && frameGroup().rank() == 0 && code != 0 && MPI_Wtime() - start > kSettleSeconds)
            MPI_Abort(MPI_COMM_WORLD, code);
        if (!arrived) usleep(1000);
    }
    MPI_Finalize();
    return code;
}

}  // namespace apparent
