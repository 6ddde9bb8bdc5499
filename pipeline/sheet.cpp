#include "pipeline/sheet.h"

#include <algorithm>

namespace apparent {

SheetLayout::SheetLayout(int rows_, int columns_, int panel_w, int panel_h, const SheetText& text, bool with_text)
    : rows(rows_), columns(columns_), panel_width(panel_w), panel_height(panel_h) {
    font_px = std::clamp(panel_h / 9, 11, 32);
    title_px = font_px * 4 / 3;
    pad = font_px / 2;
    if (with_text) {
        if (!text.title.empty()) title_band = title_px * 8 / 5;
        if (!text.column_labels.empty()) top_band = font_px * 8 / 5;
    }
    width = left_band + columns * panel_width + (columns + 1) * kGap;
    height = title_band + top_band + rows * panel_height + (rows + 1) * kGap;
}

int SheetLayout::panelX(int c) const { return left_band + kGap + c * (panel_width + kGap); }
int SheetLayout::panelY(int r) const { return title_band + top_band + kGap + r * (panel_height + kGap); }

RgbImage drawSheet(const SheetText& text, const TextPainter* painter, SheetLayout* layout) {
    // Step: the left band fits the widest row label; then the background and the labels.
    if (painter && !text.row_labels.empty()) {
        int widest = 0;
        for (const std::string& l : text.row_labels) widest = std::max(widest, painter->width(l, layout->font_px));
        layout->left_band = widest + 2 * layout->pad;
        layout->width += layout->left_band;
    }
    RgbImage sheet(layout->width, layout->height);
    std::fill(sheet.rgb.begin(), sheet.rgb.end(), SheetLayout::kGapGrey);
    if (!painter) return sheet;
    const std::array<uint8_t, 3> ink{240, 240, 240};
    if (!text.title.empty()) {
        const int w = painter->width(text.title, layout->title_px);
        painter->draw(&sheet, std::max(layout->pad, (layout->width - w) / 2), layout->title_px * 5 / 4, text.title,
                      layout->title_px, ink);
    }
    for (size_t c = 0; c < text.column_labels.size() && int(c) < layout->columns; ++c) {
        const int w = painter->width(text.column_labels[c], layout->font_px);
        painter->draw(&sheet, layout->panelX(int(c)) + (layout->panel_width - w) / 2,
                      layout->title_band + layout->font_px * 5 / 4, text.column_labels[c], layout->font_px, ink);
    }
    for (size_t r = 0; r < text.row_labels.size() && int(r) < layout->rows; ++r)
        painter->draw(&sheet, layout->pad, layout->panelY(int(r)) + layout->panel_height / 2 + layout->font_px / 3,
                      text.row_labels[r], layout->font_px, ink);
    return sheet;
}

void placePanel(RgbImage* sheet, const SheetLayout& layout, int r, int c, const RgbImage& panel) {
    for (int y = 0; y < layout.panel_height; ++y)
        std::copy_n(panel.pixel(0, y), 3 * layout.panel_width, sheet->pixel(layout.panelX(c), layout.panelY(r) + y));
}

}  // namespace apparent
