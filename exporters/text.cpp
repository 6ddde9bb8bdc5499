#include "exporters/text.h"

#include <algorithm>
#include <filesystem>

#include <ft2build.h>
#include FT_FREETYPE_H

namespace apparent {

struct TextPainter::Impl {
    FT_Library library = nullptr;
    FT_Face face = nullptr;
};

TextPainter::TextPainter() : impl_(std::make_unique<Impl>()) {}

TextPainter::~TextPainter() {
    if (impl_->face) FT_Done_Face(impl_->face);
    if (impl_->library) FT_Done_FreeType(impl_->library);
}

bool TextPainter::open(const std::string& path, std::string* error) {
    if (!std::filesystem::exists(path)) {
        *error = path + ": font not found (Debian package fonts-dejavu-core; scripts/setup.sh installs it)";
        return false;
    }
    if (!impl_->library && FT_Init_FreeType(&impl_->library) != 0) {
        *error = "FreeType: cannot initialise the library";
        return false;
    }
    if (impl_->face) FT_Done_Face(impl_->face);
    impl_->face = nullptr;
    if (FT_New_Face(impl_->library, path.c_str(), 0, &impl_->face) != 0) {
        impl_->face = nullptr;
        *error = path + ": FreeType cannot read the font";
        return false;
    }
    return true;
}

namespace {

// The 8-bit character as a Unicode code point (Latin-1).
FT_ULong codePoint(char c) { return FT_ULong(static_cast<unsigned char>(c)); }

}  // namespace

int TextPainter::width(const std::string& text, int px) const {
    FT_Face face = impl_->face;
    if (!face || FT_Set_Pixel_Sizes(face, 0, FT_UInt(px)) != 0) return 0;
    long advance = 0;
    for (char c : text)
        if (FT_Load_Char(face, codePoint(c), FT_LOAD_DEFAULT) == 0) advance += face->glyph->advance.x;
    return int((advance + 63) >> 6);
}

void TextPainter::draw(RgbImage* image, int x, int baseline, const std::string& text, int px,
                       std::array<uint8_t, 3> color) const {
    FT_Face face = impl_->face;
    if (!face || FT_Set_Pixel_Sizes(face, 0, FT_UInt(px)) != 0) return;
    long pen = long(x) << 6;  // 26.6 fixed point
    for (char c : text) {
        if (FT_Load_Char(face, codePoint(c), FT_LOAD_RENDER) != 0) continue;
        const FT_GlyphSlot g = face->glyph;
        const FT_Bitmap& bm = g->bitmap;
        const int left = int(pen >> 6) + g->bitmap_left, top = baseline - g->bitmap_top;
        // Step: blend the glyph's coverage over the image, in 8-bit sRGB (as text usually is).
        for (unsigned row = 0; row < bm.rows; ++row) {
            const int y = top + int(row);
            if (y < 0 || y >= image->height) continue;
            for (unsigned col = 0; col < bm.width; ++col) {
                const int xx = left + int(col);
                if (xx < 0 || xx >= image->width) continue;
                const unsigned a = bm.buffer[row * unsigned(std::abs(bm.pitch)) + col];
                if (a == 0) continue;
                uint8_t* p = image->pixel(xx, y);
                for (size_t k = 0; k < 3; ++k) p[k] = uint8_t((color[k] * a + p[k] * (255 - a) + 127) / 255);
            }
        }
        pen += g->advance.x;
    }
}

}  // namespace apparent
