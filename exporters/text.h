// Text on the raytracer's images (figure labels and titles), rendered by FreeType from Debian's
// DejaVu Sans (package fonts-dejavu-core), anti-aliased and blended into 8-bit RGB (png.h).
// Latin-1 text; a character the font lacks draws as the font's missing-glyph box.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "exporters/png.h"

namespace apparent {

// Where the font is looked for (Debian's fonts-dejavu-core).
constexpr const char* kLabelFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

class TextPainter {
public:
    TextPainter();
    ~TextPainter();
    TextPainter(const TextPainter&) = delete;
    TextPainter& operator=(const TextPainter&) = delete;

    // Loads the font at `path`. False with one line in `error` ("PATH: font not found (Debian
    // package fonts-dejavu-core)" or FreeType's complaint) otherwise.
    bool open(const std::string& path, std::string* error);

    // Width in pixels of `text` at a pixel height of `px` (the em size).
    int width(const std::string& text, int px) const;
    // Draws `text` with its baseline at y and its left edge at x, clipped to the image.
    void draw(RgbImage* image, int x, int baseline, const std::string& text, int px, std::array<uint8_t, 3> color) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace apparent
