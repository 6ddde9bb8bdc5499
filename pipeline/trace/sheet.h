// A sheet of equal panels in a grid with optional text around it: the layout `apparent figure`
// uses for its comparison sheet and its side-by-side video frames (figure.h). Bands: a title on
// top (wrapped onto more lines when it is wider than the sheet), column labels under it, row
// labels on the left; panels separated by kGap grey pixels. Text through exporters/text.h (FreeType).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "exporters/png.h"
#include "exporters/text.h"

namespace apparent {

// What a sheet writes around its panels (empty: no band for it).
struct SheetText {
    std::string title;
    std::vector<std::string> row_labels, column_labels;
};

// Where a sheet's bands and panels go: a title band on top, a band of column labels under it, a
// band of row labels on the left (sized by drawSheet), panels separated by kGap grey pixels. The
// title band holds one line until drawSheet wraps a title wider than the sheet less 2 pad onto
// more (title_lines; each further line adds title_step pixels), and at least min_title_lines (a
// video's frames, whose titles differ, keep one size).
struct SheetLayout {
    static constexpr int kGap = 4;
    static constexpr uint8_t kGapGrey = 96;
    SheetLayout(int rows, int columns, int panel_width, int panel_height, const SheetText& text, bool with_text);
    int rows, columns, panel_width, panel_height;
    int font_px = 12, title_px = 16, pad = 6;  // label and title pixel heights: a ninth of the panel, 11..32
    int title_band = 0, top_band = 0, left_band = 0;
    int width = 0, height = 0;
    std::vector<std::string> title_lines;  // drawSheet: the title as drawn, one entry per line
    int min_title_lines = 1;
    int titleStep() const { return title_px * 6 / 5; }
    int panelX(int column) const;
    int panelY(int row) const;
};

// The sheet's background with its text drawn (painter null: no text, the bands stay empty);
// completes `layout` (the left band's width, the title's lines and band).
RgbImage drawSheet(const SheetText& text, const TextPainter* painter, SheetLayout* layout);

// `text` in lines of at most max_width pixels at pixel height px: broken at spaces (dropped at a
// break), a word wider than max_width broken between characters (at least one a line).
std::vector<std::string> wrapText(const TextPainter& painter, const std::string& text, int px, int max_width);

// Copies `panel` (panel_width x panel_height) into the sheet at row r, column c.
void placePanel(RgbImage* sheet, const SheetLayout& layout, int r, int c, const RgbImage& panel);

}  // namespace apparent
