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

// Closes a FILE* on every path out of the writer and reader.
struct FileCloser {
    std::FILE* f = nullptr;
    ~FileCloser() {
        if (f) std::fclose(f);
    }
};

}  // namespace

bool writePng(const std::string& path, const RgbImage& image, std::string* error) {
    if (image.width <= 0 || image.height <= 0 || image.rgb.size() != size_t(3) * image.width * image.height) {
        *error = path + ": image has no pixels or a wrong buffer size";
        return false;
    }
    AtomicOutput out(path);
    FileCloser file{std::fopen(out.tempPath().c_str(), "wb")};
    if (!file.f) {
        *error = path + ": cannot open for writing: " + std::strerror(errno);
        return false;
    }
    PngErrorState state;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, onPngError, onPngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info) {
        png_destroy_write_struct(&png, &info);
        *error = path + ": libpng could not start";
        return false;
    }
    std::vector<png_bytep> rows(size_t(image.height));
    for (int y = 0; y < image.height; ++y) rows[size_t(y)] = const_cast<png_bytep>(image.pixel(0, y));
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        *error = path + ": libpng: " + state.message;
        return false;
    }
    png_init_io(png, file.f);
    png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    // Flushed, synced and closed, each checked (as every output: README "Hostile input").
    int failed = (std::fflush(file.f) != 0 || std::ferror(file.f)) ? (errno ? errno : EIO) : 0;
    if (!failed && ::fsync(fileno(file.f)) != 0) failed = errno;
    if (std::fclose(file.f) != 0 && !failed) failed = errno;
    file.f = nullptr;
    if (failed) {
        *error = path + ": write failed: " + std::strerror(failed);
        return false;
    }
    return out.commit(error);
}

bool readPng(const std::string& path, RgbImage* image, std::string* error) {
    FileCloser file{std::fopen(path.c_str(), "rb")};
    if (!file.f) {
        *error = path + ": cannot open: " + std::strerror(errno);
        return false;
    }
    PngErrorState state;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, onPngError, onPngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info) {
        png_destroy_read_struct(&png, &info, nullptr);
        *error = path + ": libpng could not start";
        return false;
    }
    // Buffers filled after setjmp live on the heap behind a pointer set before it: locals changed
    // between setjmp and longjmp have indeterminate values afterwards (C11 7.13.2.1).
    struct Buffers {
        std::vector<png_bytep> rows;
        std::vector<uint8_t> rgba;
    };
    const std::unique_ptr<Buffers> buffers = std::make_unique<Buffers>();
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        *error = path + ": libpng: " + state.message;
        return false;
    }
    png_init_io(png, file.f);
    png_read_info(png, info);
    const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    const int color = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
    if (depth != 8 || (color != PNG_COLOR_TYPE_RGB && color != PNG_COLOR_TYPE_RGB_ALPHA) || w > 1u << 15 ||
        h > 1u << 15) {
        png_destroy_read_struct(&png, &info, nullptr);
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
    png_destroy_read_struct(&png, &info, nullptr);
    RgbImage result{static_cast<int>(w), static_cast<int>(h)};
    for (size_t i = 0; i < size_t(w) * h; ++i)
        for (size_t c = 0; c < 3; ++c) result.rgb[3 * i + c] = rgba[channels * i + c];
    *image = std::move(result);
    return true;
}

}  // namespace apparent
