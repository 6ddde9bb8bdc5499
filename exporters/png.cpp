#include "exporters/png.h"

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

#include <unistd.h>

#include <png.h>

#include "exporters/atomic_file.h"

namespace apparent {

namespace {

// libpng reports errors through a callback that must not return; we longjmp back (the libpng
// manual's "Setting up error handling"), keeping the message for the caller.
struct PngErrorState {
    std::string message;
};

void onPngError(png_structp png, png_const_charp msg) {
    auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
    if (state) state->message = msg;
    png_longjmp(png, 1);
}

void onPngWarning(png_structp, png_const_charp) {}

// One PNG file being written or read: the FILE and libpng's structures, released on every way
// out (structures first, then the file). They are set up before the caller's setjmp and not
// changed after it, so a longjmp back leaves them valid.
class PngSession {
public:
    // Reading opens `file_path`; writing writes to a copy of `write_fd` (an AtomicOutput's file,
    // created exclusively), never to a name opened again.
    PngSession(const std::string& file_path, bool writing, int write_fd = -1) : writing_(writing) {
        if (writing) {
            const int copy = write_fd >= 0 ? ::dup(write_fd) : -1;
            file = copy >= 0 ? ::fdopen(copy, "wb") : nullptr;
            if (copy >= 0 && !file) ::close(copy);
            if (write_fd < 0) errno = EBADF;
        } else {
            file = std::fopen(file_path.c_str(), "rb");
        }
        if (!file) {
            open_errno_ = errno;
            return;
        }
        png = writing ? png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, onPngError, onPngWarning)
                      : png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, onPngError, onPngWarning);
        info = png ? png_create_info_struct(png) : nullptr;
        if (png && info) png_init_io(png, file);
    }
    ~PngSession() {
        if (png && writing_) png_destroy_write_struct(&png, &info);
        if (png && !writing_) png_destroy_read_struct(&png, &info, nullptr);
        if (file) std::fclose(file);
    }
    PngSession(const PngSession&) = delete;
    PngSession& operator=(const PngSession&) = delete;

    // False with "NAME: cannot open...: reason" or "NAME: libpng could not start".
    bool started(const std::string& name, std::string* error) const {
        if (!file) *error = name + (writing_ ? ": cannot open for writing: " : ": cannot open: ") + std::strerror(open_errno_);
        else if (!png || !info) *error = name + ": libpng could not start";
        return file && png && info;
    }
    // Writing: flushes, syncs and closes the file, each checked; 0 or the errno of the first failure.
    int closeChecked() {
        int failed = (std::fflush(file) != 0 || std::ferror(file)) ? (errno ? errno : EIO) : 0;
        if (!failed && ::fsync(fileno(file)) != 0) failed = errno;
        if (std::fclose(file) != 0 && !failed) failed = errno;
        file = nullptr;
        return failed;
    }

    PngErrorState state;
    std::FILE* file = nullptr;
    png_structp png = nullptr;
    png_infop info = nullptr;

private:
    bool writing_;
    int open_errno_ = 0;
};

}  // namespace

bool writePng(const std::string& path, const RgbImage& image, std::string* error) {
    if (image.width <= 0 || image.height <= 0 || image.rgb.size() != size_t(3) * image.width * image.height) {
        *error = path + ": image has no pixels or a wrong buffer size";
        return false;
    }
    AtomicOutput out(path);
    if (out.fd() < 0) {
        *error = out.openError();
        return false;
    }
    PngSession session(out.tempPath(), /*writing=*/true, out.fd());
    if (!session.started(path, error)) return false;
    png_structp png = session.png;
    png_infop info = session.info;
    std::vector<png_bytep> rows(size_t(image.height));
    for (int y = 0; y < image.height; ++y) rows[size_t(y)] = const_cast<png_bytep>(image.pixel(0, y));
    if (setjmp(png_jmpbuf(png))) {
        *error = path + ": libpng: " + session.state.message;
        return false;
    }
    png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, info);
    // Flushed, synced and closed, each checked (as every output: docs/HOSTILE_INPUT.md).
    if (const int failed = session.closeChecked()) {
        *error = path + ": write failed: " + std::strerror(failed);
        return false;
    }
    return out.commit(error);
}

bool readPng(const std::string& path, RgbImage* image, std::string* error) {
    PngSession session(path, /*writing=*/false);
    if (!session.started(path, error)) return false;
    png_structp png = session.png;
    png_infop info = session.info;
    // Buffers filled after setjmp live on the heap behind a pointer set before it: locals changed
    // between setjmp and longjmp have indeterminate values afterwards (C11 7.13.2.1).
    struct Buffers {
        std::vector<png_bytep> rows;
        std::vector<uint8_t> rgba;
    };
    const std::unique_ptr<Buffers> buffers = std::make_unique<Buffers>();
    if (setjmp(png_jmpbuf(png))) {
        *error = path + ": libpng: " + session.state.message;
        return false;
    }
    png_read_info(png, info);
    const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    const int color = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
    if (depth != 8 || (color != PNG_COLOR_TYPE_RGB && color != PNG_COLOR_TYPE_RGB_ALPHA) || w > 1u << 15 ||
        h > 1u << 15) {
        *error = path + ": not an 8-bit RGB(A) PNG of at most 32768 x 32768 pixels";
        return false;
    }
    const size_t channels = color == PNG_COLOR_TYPE_RGB ? 3 : 4;
    std::vector<uint8_t>& rgba = buffers->rgba;
    rgba.resize(size_t(w) * h * channels);
    buffers->rows.resize(h);
    for (png_uint_32 y = 0; y < h; ++y) buffers->rows[y] = &rgba[size_t(y) * w * channels];
    png_read_image(png, buffers->rows.data());
    png_read_end(png, nullptr);
    RgbImage result{static_cast<int>(w), static_cast<int>(h)};
    for (size_t i = 0; i < size_t(w) * h; ++i)
        for (size_t c = 0; c < 3; ++c) result.rgb[3 * i + c] = rgba[channels * i + c];
    *image = std::move(result);
    return true;
}

}  // namespace apparent
