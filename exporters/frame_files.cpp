#include "exporters/frame_files.h"

#include "exporters/atomic_file.h"
#include "exporters/frame_spill.h"

#include <algorithm>
#include <cctype>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace apparent {

mesh4d::ApparentMesh mergeObjects(const ExportFrame& frame) {
    mesh4d::ApparentMesh all;  // absolute lab positions and times (origin 0)
    for (const auto& part : frame.objects) {
        const uint32_t base = uint32_t(all.positions.size());
        for (size_t i = 0; i < part.positions.size(); ++i) {
            all.positions.push_back(part.absolutePosition(i));
            all.emission_times.push_back(part.absoluteTime(i));
        }
        for (const auto& t : part.triangles) all.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
        all.rest_points.insert(all.rest_points.end(), part.rest_points.begin(), part.rest_points.end());
        all.clipped_triangles += part.clipped_triangles;
    }
    return all;
}

std::string shortestDecimal(double value) {
#if defined(__cpp_lib_to_chars)
    char buffer[32];
    return std::string(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
#else
    return shortestDecimalByPrintf(value);
#endif
}

std::string shortestDecimalByPrintf(double value) {
    if (!std::isfinite(value)) return std::isnan(value) ? "nan" : value < 0 ? "-inf" : "inf";
    // Step: the fewest significant digits that read back as `value`: at each count the correctly
    // rounded digits ("%.*e"), or the neighbour past `value` when only that one reads back.
    auto readsBack = [&](const std::string& d, int exp) {
        const std::string text = (value < 0 ? "-" : "") + d.substr(0, 1) + "." + d.substr(1) + "e" + std::to_string(exp);
        return std::strtod(text.c_str(), nullptr) == value;
    };
    std::string digits;
    int exponent = 0;
    for (int p = 0; p < 17; ++p) {
        char e_form[40];
        std::snprintf(e_form, sizeof e_form, "%.*e", p, value);
        const char* at = std::strchr(e_form, 'e');
        digits.clear();
        for (const char* c = e_form; c < at; ++c)
            if (std::isdigit((unsigned char)*c)) digits += *c;
        exponent = std::atoi(at + 1);
        if (readsBack(digits, exponent) || p == 16) break;
        bool found = false;
        for (int step : {1, -1}) {
            std::string d = digits;
            int exp = exponent, k = int(d.size()) - 1;
            while (k >= 0 && d[size_t(k)] == (step > 0 ? '9' : '0')) d[size_t(k--)] = step > 0 ? '0' : '9';
            if (k < 0) continue;  // 9...9 + 1 or 0...0 - 1: not a neighbour of this length
            d[size_t(k)] = char(d[size_t(k)] + step);
            if (d[0] == '0') continue;
            if (readsBack(d, exp)) {
                digits = d;
                exponent = exp;
                found = true;
                break;
            }
        }
        if (found) break;
    }
    while (digits.size() > 1 && digits.back() == '0') digits.pop_back();
    const std::string sign = value < 0 || (value == 0 && std::signbit(value)) ? "-" : "";
    // Step: the scientific form as printf writes it (at least two exponent digits) ...
    std::string sci = sign + digits.substr(0, 1) + (digits.size() > 1 ? "." + digits.substr(1) : "") + "e" +
                      (exponent < 0 ? "-" : "+") + (std::abs(exponent) < 10 ? "0" : "") + std::to_string(std::abs(exponent));
    // ... and the fixed form; the shorter, the fixed one on a tie (the rule of std::to_chars).
    std::string fixed;
    const int n = int(digits.size());
    if (exponent >= n - 1) {
        // An integer: its exact digits, as printf's "%.0f" (as long as the shortest ones padded with zeros).
        char integer[400];
        std::snprintf(integer, sizeof integer, "%.0f", std::fabs(value));
        fixed = integer;
    }
    else if (exponent >= 0)
        fixed = digits.substr(0, size_t(exponent + 1)) + "." + digits.substr(size_t(exponent + 1));
    else
        fixed = "0." + std::string(size_t(-exponent - 1), '0') + digits;
    fixed = sign + fixed;
    return fixed.size() <= sci.size() ? fixed : sci;
}

std::vector<std::string> frameFileComments(const ExportFrame& frame, const SequenceInfo& info) {
    std::vector<std::string> lines;
    if (!frame.units.empty()) lines.push_back("units: " + frame.units);
    if (!info.model.empty()) lines.push_back("model: " + info.model);
    if (!info.scene_path.empty()) {
        std::string path = info.scene_path;
        for (char& c : path)
            if ((unsigned char)c < 0x20 || c == 0x7f) c = '_';
        lines.push_back("scene: " + path);
    }
    lines.push_back("camera_time: " + shortestDecimal(frame.t_c));
    const size_t objects = frameObjectCount(frame, info);
    for (size_t i = 0; i < objects; ++i) lines.push_back("object " + std::to_string(i) + " " + frameObjectName(info, i));
    return lines;
}

size_t frameObjectCount(const ExportFrame& frame, const SequenceInfo& info) {
    return std::max(info.objects.size(), frame.objects.size());
}

std::string frameObjectName(const SequenceInfo& info, size_t i) {
    std::string name = i < info.objects.size() ? info.objects[i].name : std::string();
    for (char& c : name)
        if ((unsigned char)c <= 0x20 || c == 0x7f) c = '_';
    return name.empty() ? "object_" + std::to_string(i) : name;
}

long long leastFrameBytes(const ExportFrame& frame) {
    size_t vertices = 0;
    for (const auto& o : frame.objects) vertices += o.positions.size();
    return 12 * (long long)vertices + 12 * (long long)frame.triangleCount();
}

EncodedOutput FrameSink::encode(const ExportFrame&, const PreparedFrame*) const { return {}; }

PendingOutput FrameSink::pendingEncoded(long long index, const EncodedOutput& frame) {
    return {frame.least, "frame " + std::to_string(index)};
}

bool FrameSink::addEncoded(long long index, const EncodedOutput&, std::vector<std::string>*, std::string* error) {
    *error = "frame " + std::to_string(index) + ": this output cannot take frames from another process";
    return false;
}

bool writeUncommitted(AtomicOutput* out, const std::string& bytes, std::string* error) {
    if (out->fd() < 0) {
        *error = out->openError();
        return false;
    }
    const iovec whole{const_cast<char*>(bytes.data()), bytes.size()};
    size_t done = 0;
    std::string why;
    if (!writeWhole(out->fd(), &whole, 1, &why, &done)) {
        *error = out->finalPath() + ": cannot write (" + std::to_string(done) + " of " + std::to_string(bytes.size()) +
                 " bytes written): " + why;
        return false;
    }
    if (::fsync(out->fd()) != 0) {
        *error = out->finalPath() + ": cannot write: " + std::strerror(errno);
        return false;
    }
    return true;
}

bool writeFrameFile(FrameSerializer serialize, const std::string& path, const ExportFrame& frame,
                    const SequenceInfo& info, std::string* error) {
    thread_local std::string bytes;  // kept between frames: no reallocation while frames do not grow
    serialize(frame, info, &bytes);
    AtomicOutput out(path);
    return writeUncommitted(&out, bytes, error) && out.commit(error);
}

FrameFileSink::FrameFileSink(std::string dir, std::string extension, FrameSerializer serialize, bool light_factors)
    : dir_(std::move(dir)), extension_(std::move(extension)), serialize_(serialize), light_factors_(light_factors) {}

std::string FrameFileSink::path(long long k) const {
    return (std::filesystem::path(dir_) / (frameName(k) + "." + extension_)).string();
}

bool FrameFileSink::begin(const SequenceInfo& info, std::string* error) {
    info_ = info;
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) *error = dir_ + ": cannot create output folder: " + ec.message();
    return !ec;
}

PendingOutput FrameFileSink::pending(const ExportFrame& frame) { return {leastFrameBytes(frame), path(frame.index)}; }

bool FrameFileSink::add(const ExportFrame& frame, const PreparedFrame*, std::vector<std::string>* completed,
                        std::string* error) {
    const std::string p = path(frame.index);
    serialize_(frame, info_, &bytes_);
    auto out = std::make_unique<AtomicOutput>(p);
    if (!writeUncommitted(out.get(), bytes_, error)) return false;
    if (holding_) {
        held_[frame.index] = std::move(out);
        return true;
    }
    if (!out->commit(error)) return false;
    completed->push_back(p);
    return true;
}

void FrameFileSink::holdCommits(bool on) {
    holding_ = on;
    if (!on) held_.clear();  // AtomicOutput removes an uncommitted temporary file
}

bool FrameFileSink::commitHeld(long long index, std::vector<std::string>* completed, std::string* error) {
    auto it = held_.find(index);
    if (it == held_.end()) return true;
    const std::unique_ptr<AtomicOutput> out = std::move(it->second);
    held_.erase(it);
    if (!out->commit(error)) return false;
    completed->push_back(out->finalPath());
    return true;
}

bool FrameFileSink::finish(SinkSummary*, std::string*) { return true; }

EncodedOutput FrameFileSink::encode(const ExportFrame& frame, const PreparedFrame*) const {
    EncodedOutput e;
    e.least = e.estimate = leastFrameBytes(frame);
    serialize_(frame, info_, &e.bytes);
    return e;
}

PendingOutput FrameFileSink::pendingEncoded(long long index, const EncodedOutput& frame) {
    return {frame.least, path(index)};
}

namespace {

// A frame file written by the rank that cut the frame, as it travels: the marker (a NUL first: no
// PLY or OBJ file starts so), the file's size and inode, then the write's error (empty: written).
constexpr char kWrittenMarker[8] = {'\0', 'A', 'F', 'F', 'I', 'L', 'E', '1'};

void putU64(std::string* out, uint64_t v) {
    for (int i = 0; i < 8; ++i) out->push_back(char((v >> (8 * i)) & 0xff));
}

uint64_t getU64(const std::string& in, size_t at) {
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(in[at + size_t(i)])) << (8 * i);
    return v;
}

bool isWrittenFrame(const std::string& bytes) {
    return bytes.size() >= sizeof kWrittenMarker + 16 &&
           std::memcmp(bytes.data(), kWrittenMarker, sizeof kWrittenMarker) == 0;
}

// The test hook (kKillAfterWritingVariable): whether this rank dies after writing `final_path`.
bool killAfterWriting(const std::string& final_path) {
    static const char* const victim = std::getenv(kKillAfterWritingVariable);
    return victim != nullptr && final_path == victim;
}

// A rank's removal of every rank's temporaries on an interrupt (removeFrameTemporariesOnInterrupt):
// fixed storage a signal handler reads; the folder count is published after the folders.
constexpr int kFolders = 8;
constexpr size_t kMaxPath = 4096;
char g_folders[kFolders][kMaxPath];
char g_infix[64];  // ".tmp-TOKEN."
std::atomic<int> g_folder_count{0};
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
struct sigaction g_previous[std::size(kSignals)];

// One entry as the getdents64 system call returns it (the kernel's struct linux_dirent64).
struct DirectoryEntry {
    uint64_t ino;
    int64_t offset;
    unsigned short length;
    unsigned char type;
    char name[1];
};

bool isRunTemporary(const char* name, const char* infix) {
    return std::strncmp(name, ".frame_", 7) == 0 && std::strstr(name, infix) != nullptr;
}

// Async-signal-safe (system calls and string functions only): unlinks every run temporary in
// `folder`, scanning again after a scan that removed some (entries removed during a scan may hide
// others from it), at most four times.
void removeRunTemporaries(const char* folder, const char* infix) {
    const int fd = ::open(folder, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    alignas(8) char buffer[8192];
    bool removed = true;
    for (int scan = 0; removed && scan < 4; ++scan) {
        removed = false;
        if (::lseek(fd, 0, SEEK_SET) != 0) break;
        for (;;) {
#if defined(__EMSCRIPTEN__)
            const long n = 0;  // the WebAssembly module has no signals to clean up after
            (void)buffer;
#else
            const long n = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
#endif
            if (n <= 0) break;
            for (long at = 0; at < n;) {
                const auto* e = reinterpret_cast<const DirectoryEntry*>(buffer + at);
                if (isRunTemporary(e->name, infix) && ::unlinkat(fd, e->name, 0) == 0) removed = true;
                at += e->length;
            }
        }
    }
    ::close(fd);
}

void onInterrupt(int sig) {
    const int saved = errno;
    const int folders = g_folder_count.load();
    for (int i = 0; i < folders; ++i) removeRunTemporaries(g_folders[i], g_infix);
    errno = saved;
    for (size_t i = 0; i < std::size(kSignals); ++i) {
        if (kSignals[i] != sig) continue;
        const struct sigaction& before = g_previous[i];
        if (before.sa_handler == SIG_DFL) {
            ::signal(sig, SIG_DFL);
            ::raise(sig);
        } else if (before.sa_handler != SIG_IGN) {
            before.sa_handler(sig);
        }
    }
}

}  // namespace

std::string FrameFileSink::temporaryPath(long long k) const {
    return (std::filesystem::path(dir_) / ("." + frameName(k) + ".tmp-" + frameRunToken() + "." + extension_)).string();
}

bool FrameFileSink::beginEncoding(const SequenceInfo& info, std::string* error) {
    // The rank writes into DIR, possibly before rank 0's begin() made it.
    info_ = info;
    return !frameSpillInstalled() || begin(info, error);
}

void FrameFileSink::beforeSending(long long index, EncodedOutput* frame) {
    if (!frameSpillInstalled()) return;
    const std::string temp = temporaryPath(index), final_path = path(index);
    // Step: the previous frame is with rank 0 (sent), which registered its name: this one instead.
    unregisterTemporary(sent_slot_);
    sent_slot_ = registerTemporary(temp);
    // Step: the file, created exclusively, written, synced and closed, as AtomicOutput does.
    std::string why;
    struct stat st {};
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
        why = final_path + ": cannot create " + temp + ": " + std::strerror(errno);
    } else {
        size_t done = 0;
        std::string w;
        if (!writeAll(fd, frame->bytes.data(), frame->bytes.size(), &w, &done))
            why = final_path + ": cannot write (" + std::to_string(done) + " of " +
                  std::to_string(frame->bytes.size()) + " bytes written): " + w;
        else if (::fsync(fd) != 0 || ::fstat(fd, &st) != 0)
            why = final_path + ": cannot write: " + std::strerror(errno);
        if (::close(fd) != 0 && why.empty()) why = final_path + ": cannot write: " + std::strerror(errno);
        if (!why.empty()) ::unlink(temp.c_str());
    }
    if (why.empty() && killAfterWriting(final_path)) ::raise(SIGKILL);
    // Step: its description replaces the bytes.
    std::string d(kWrittenMarker, sizeof kWrittenMarker);
    putU64(&d, why.empty() ? uint64_t(st.st_size) : 0);
    putU64(&d, why.empty() ? uint64_t(st.st_ino) : 0);
    d += why;
    frame->bytes = std::move(d);
}

void FrameFileSink::dropEncoded(long long first, long long last_excl) {
    if (!frameSpillInstalled() || frameRunToken().empty()) return;
    for (long long k = first; k < last_excl; ++k) ::unlink(temporaryPath(k).c_str());
}

FrameFileSink::~FrameFileSink() { unregisterTemporary(sent_slot_); }

bool FrameFileSink::addEncoded(long long index, const EncodedOutput& frame, std::vector<std::string>* completed,
                               std::string* error) {
    const std::string p = path(index);
    if (isWrittenFrame(frame.bytes)) {
        // Written by its rank: renamed into place when it is still the file the rank wrote.
        const size_t at = sizeof kWrittenMarker;
        const uint64_t size = getU64(frame.bytes, at), ino = getU64(frame.bytes, at + 8);
        if (frame.bytes.size() > at + 16) {
            *error = frame.bytes.substr(at + 16);  // the rank's message, as one process gives it
            return false;
        }
        const std::string temp = temporaryPath(index);
        struct stat st {};
        if (::lstat(temp.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) != size ||
            uint64_t(st.st_ino) != ino) {
            *error = p + ": the temporary file " + temp + " was replaced while writing (not renamed into place)";
            return false;
        }
        if (std::rename(temp.c_str(), p.c_str()) != 0) {
            *error = p + ": cannot rename from " + temp + ": " + std::strerror(errno);
            return false;
        }
        completed->push_back(p);
        return true;
    }
    AtomicOutput out(p);
    if (!out.commitBytes(frame.bytes, error)) return false;
    completed->push_back(p);
    return true;
}

bool removeFrameTemporariesOnInterrupt(const std::string& token, const std::vector<std::string>& folders) {
    const std::string infix = ".tmp-" + token + ".";
    if (folders.size() > size_t(kFolders) || infix.size() >= sizeof g_infix) return false;
    for (const std::string& f : folders)
        if (f.size() >= kMaxPath) return false;
    // Step: the folders, then their count (a handler sees either set whole).
    g_folder_count.store(0);
    std::memcpy(g_infix, infix.c_str(), infix.size() + 1);
    for (size_t i = 0; i < folders.size(); ++i) std::memcpy(g_folders[i], folders[i].c_str(), folders[i].size() + 1);
    g_folder_count.store(int(folders.size()));
    // Step: once per process, the handlers, in front of those installed before.
    static bool installed = false;
    if (installed) return true;
    installed = true;
    for (size_t i = 0; i < std::size(kSignals); ++i) {
        if (::sigaction(kSignals[i], nullptr, &g_previous[i]) != 0 || g_previous[i].sa_handler == SIG_IGN ||
            (g_previous[i].sa_flags & SA_SIGINFO))
            continue;
        struct sigaction sa = g_previous[i];
        sa.sa_handler = &onInterrupt;
        ::sigaction(kSignals[i], &sa, nullptr);
    }
    return true;
}

}  // namespace apparent
