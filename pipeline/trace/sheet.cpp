#include "pipeline/trace/sheet.h"

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

std::vector<std::string> wrapText(const TextPainter& painter, const std::string& text, int px, int max_width) {
    std::vector<std::string> lines;
    auto fits = [&](size_t from, size_t to) { return painter.width(text.substr(from, to - from), px) <= max_width; };
    size_t start = 0;
    while (start < text.size()) {
        if (!lines.empty())
            while (start < text.size() && text[start] == ' ') ++start;  // the break's spaces
        if (start == text.size()) break;
        size_t end = text.size();
        if (!fits(start, end)) {
            // Step: the longest run of words that fits; else as many characters as fit, one at least.
            end = std::string::npos;
            for (size_t i = start + 1; i < text.size(); ++i) {
                if (text[i] != ' ' || text[i - 1] == ' ') continue;
                if (!fits(start, i)) break;
                end = i;
            }
            if (end == std::string::npos)
                for (end = start + 1; end < text.size() && fits(start, end + 1);) ++end;
        }
        lines.push_back(text.substr(start, end - start));
        start = end;
    }
    return lines;
}

RgbImage drawSheet(const SheetText& text, const TextPainter* painter, SheetLayout* layout) {
    // Step: the left band fits the widest row label; then the title's lines; then the background
    // and the text.
    if (painter && !text.row_labels.empty()) {
        int widest = 0;
        for (const std::string& l : text.row_labels) widest = std::max(widest, painter->width(l, layout->font_px));
        layout->left_band = widest + 2 * layout->pad;
        layout->width += layout->left_band;
    }
    layout->title_lines.clear();
    if (painter && !text.title.empty()) {
        layout->title_lines = wrapText(*painter, text.title, layout->title_px, layout->width - 2 * layout->pad);
        const int more = std::max(int(layout->title_lines.size()), layout->min_title_lines) - 1;
        layout->title_band += more * layout->titleStep();
        layout->height += more * layout->titleStep();
    }
    RgbImage sheet(layout->width, layout->height);
    std::fill(sheet.rgb.begin(), sheet.rgb.end(), SheetLayout::kGapGrey);
    if (!painter) return sheet;
    const std::array<uint8_t, 3> ink{240, 240, 240};
    for (size_t i = 0; i < layout->title_lines.size(); ++i) {
        const std::string& line = layout->title_lines[i];
        const int w = painter->width(line, layout->title_px);
        painter->draw(&sheet, std::max(layout->pad, (layout->width - w) / 2),
                      layout->title_px * 5 / 4 + int(i) * layout->titleStep(), line, layout->title_px, ink);
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
