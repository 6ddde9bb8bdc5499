#include "exporters/video.h"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace apparent {

std::string findInPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    if (!path) return "";
    std::stringstream ss(path);
    std::string dir;
    while (std::getline(ss, dir, ':')) {
        if (dir.empty()) continue;
        const std::string candidate = dir + "/" + program;
        if (::access(candidate.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(candidate)) return candidate;
    }
    return "";
}

std::string ffmpegMissingMessage(const std::string& option) {
    return option + ": the ffmpeg program is not in PATH (Debian: apt-get install ffmpeg; scripts/setup.sh installs it)";
}

VideoWriter::~VideoWriter() { stop(); }

void VideoWriter::stop() {
    if (pipe_ >= 0) ::close(pipe_);
    pipe_ = -1;
    if (pid_ > 0) {
        ::kill(pid_, SIGTERM);
        int status = 0;
        while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {}
    }
    pid_ = -1;
    if (log_ >= 0) ::close(log_);
    log_ = -1;
    out_.reset();  // removes the temporary file unless committed
}

bool VideoWriter::open(const std::string& path, int width, int height, double fps, std::string* error) {
    stop();
    path_ = path;
    width_ = width;
    height_ = height;
    frames_ = 0;
    const std::string ffmpeg = findInPath("ffmpeg");
    if (ffmpeg.empty()) {
        *error = ffmpegMissingMessage("--video");
        return false;
    }
    // Step: the temporary file ffmpeg writes (it truncates and rewrites the same inode; faststart
    // reopens it by name to move the index to the front).
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    out_ = std::make_unique<AtomicOutput>(path);
    if (out_->fd() < 0) {
        *error = out_->openError();
        out_.reset();
        return false;
    }
    const std::string dir = parent.empty() ? "." : parent.string();
    log_ = openAnonymousFile(dir, error);
    if (log_ < 0) return false;
    // Step: the pipe, ffmpeg's stdin; our end closed on exec. A dead ffmpeg makes writes fail
    // with EPIPE instead of killing the program.
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
        *error = path + ": cannot create a pipe to ffmpeg: " + std::strerror(errno);
        return false;
    }
    std::signal(SIGPIPE, SIG_IGN);
    std::ostringstream rate, size;
    rate.precision(17);
    rate << fps;
    size << width << "x" << height;
    const std::vector<std::string> args = {
        ffmpeg, "-hide_banner", "-loglevel", "error", "-nostdin", "-y",
        "-f", "rawvideo", "-pix_fmt", "rgb24", "-video_size", size.str(), "-framerate", rate.str(), "-i", "pipe:0",
        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-preset", "medium", "-crf", "20",
        "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4", out_->tempPath()};
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, log_, 2);
    const int rc = posix_spawn(&pid_, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[0]);
    pipe_ = fds[1];
    if (rc != 0) {
        pid_ = -1;
        *error = path + ": cannot start " + ffmpeg + ": " + std::strerror(rc);
        return false;
    }
    return true;
}

bool VideoWriter::addFrame(const RgbImage& frame, std::string* error) {
    if (pipe_ < 0 || frame.width != width_ || frame.height != height_) {
        *error = path_ + ": video frame of the wrong size or after an error";
        return false;
    }
    std::string werr;
    if (!writeAll(pipe_, frame.rgb.data(), frame.rgb.size(), &werr)) {
        ::close(pipe_);
        pipe_ = -1;
        int status = 0;
        while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {}
        pid_ = -1;
        const std::string why = ffmpegError();
        *error = path_ + ": ffmpeg stopped: " + (why.empty() ? werr : why);
        stop();
        return false;
    }
    ++frames_;
    return true;
}

std::string VideoWriter::ffmpegError() const {
    // The last non-empty line ffmpeg wrote to its stderr.
    if (log_ < 0) return "";
    std::string text;
    char buf[4096];
    ssize_t n;
    off_t at = 0;
    while ((n = ::pread(log_, buf, sizeof buf, at)) > 0) {
        text.append(buf, size_t(n));
        at += n;
        if (text.size() > (1u << 20)) text.erase(0, text.size() - 4096);
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    const size_t nl = text.find_last_of('\n');
    return nl == std::string::npos ? text : text.substr(nl + 1);
}

bool VideoWriter::finish(std::string* error) {
    if (pid_ <= 0 || !out_) {
        *error = path_ + ": no video to finish";
        return false;
    }
    ::close(pipe_);
    pipe_ = -1;
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {}
    pid_ = -1;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        const std::string why = ffmpegError();
        *error = path_ + ": ffmpeg failed" + (why.empty() ? std::string() : ": " + why);
        stop();
        return false;
    }
    const bool ok = out_->commit(error);
    stop();
    return ok;
}

}  // namespace apparent
