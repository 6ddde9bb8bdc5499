// PNG images (8-bit RGB, no interlace), written with Debian's libpng through a temporary file
// (atomic_file.h). Used for the 4D raytracer's frames and the comparison sheet.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace apparent {

// An 8-bit sRGB image, rows top to bottom, 3 bytes per pixel.
struct RgbImage {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgb;  // size 3 * width * height

    RgbImage() = default;
    RgbImage(int w, int h) : width(w), height(h), rgb(size_t(3) * size_t(w) * size_t(h), 0) {}
    uint8_t* pixel(int x, int y) { return &rgb[3 * (size_t(y) * size_t(width) + size_t(x))]; }
    const uint8_t* pixel(int x, int y) const { return &rgb[3 * (size_t(y) * size_t(width) + size_t(x))]; }
};

// Writes `image` to `path` as PNG. Precondition: width, height > 0 and rgb.size() = 3 w h.
// Returns false with "path: problem" in `error` when the file cannot be written.
bool writePng(const std::string& path, const RgbImage& image, std::string* error);

// Reads an 8-bit RGB or RGBA PNG (alpha dropped), as written by writePng; for tests and tools.
// Returns false with "path: problem" in `error` otherwise.
bool readPng(const std::string& path, RgbImage* image, std::string* error);

}  // namespace apparent
