// Videos of the raytracer's frames: H.264 in MP4 that browsers play (yuv420p, even sizes,
// "faststart": the index before the data), encoded by Debian's `ffmpeg` program, found in PATH at
// run time and fed raw RGB frames through a pipe. The file is written under a temporary name in
// the target's folder and renamed into place when ffmpeg succeeds (atomic_file.h), so a failed or
// interrupted run leaves no partial video. Odd image sizes are padded by one dark pixel to even.
#pragma once

#include <memory>
#include <string>
#include <sys/types.h>

#include "exporters/atomic_file.h"
#include "exporters/png.h"

namespace apparent {

// The full path of `program` found in the PATH environment variable, or "" when absent.
std::string findInPath(const std::string& program);

// The one-line message for a missing ffmpeg, naming `option` (e.g. "--video").
std::string ffmpegMissingMessage(const std::string& option);

class VideoWriter {
public:
    VideoWriter() = default;
    ~VideoWriter();  // an unfinished video: ffmpeg is stopped and the temporary file removed
    VideoWriter(const VideoWriter&) = delete;
    VideoWriter& operator=(const VideoWriter&) = delete;

    // Starts ffmpeg for a width x height video at `fps` frames per second to be named `path`.
    // False with one line in `error` when ffmpeg is not in PATH or cannot be started. From here
    // on SIGPIPE is ignored in the process: a write to an ffmpeg that died fails with EPIPE.
    bool open(const std::string& path, int width, int height, double fps, std::string* error);
    // Sends one frame (its size must be the one given to open).
    bool addFrame(const RgbImage& frame, std::string* error);
    // Closes the pipe, waits for ffmpeg and renames the video into place; false with ffmpeg's
    // last message line when it failed.
    bool finish(std::string* error);

    long long frames() const { return frames_; }

private:
    void stop();
    std::string ffmpegError() const;

    std::unique_ptr<AtomicOutput> out_;
    std::string path_;
    int width_ = 0, height_ = 0;
    int pipe_ = -1;     // write end of ffmpeg's stdin
    int log_ = -1;      // anonymous file holding ffmpeg's stderr
    pid_t pid_ = -1;
    long long frames_ = 0;
};

}  // namespace apparent
