// The figure's sheet (pipeline/trace/sheet.h): a title wider than the sheet wrapped onto lines that fit it,
// shown whole (its words all there, its ink inside the sheet); `figure --row-labels` and
// `--column-labels` in place of the model names and camera times.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "exporters/png.h"
#include "exporters/text.h"
#include "pipeline/trace/sheet.h"
#include "run_command.h"

using namespace apparent;

namespace {

std::vector<std::string> words(const std::string& text) {
    std::istringstream in(text);
    std::vector<std::string> out;
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

// Pixels of `sheet` in rows y0..y1-1 brighter than the gap grey in every channel (title ink).
int inkIn(const RgbImage& sheet, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const uint8_t* p = sheet.pixel(x, y);
            n += p[0] > 160 && p[1] > 160 && p[2] > 160;
        }
    return n;
}

}  // namespace

// A title twice as wide as the sheet: every line fits the sheet less its pads, the lines hold the
// title's words in order, each line band has ink, and no ink touches the sheet's left or right
// column (text cut off at the edge would). A short title keeps one line and the old band.
TEST(Sheet, ATitleTwiceTheSheetsWidthIsShownWhole) {
    TextPainter painter;
    std::string error;
    ASSERT_TRUE(painter.open(kLabelFontPath, &error)) << error;
    const SheetText probe{"t", {"instant", "relativistic"}, {"t = 1.0 s", "t = 2.0 s", "t = 3.0 s"}};
    SheetLayout sized(2, 3, 96, 54, probe, true);
    drawSheet(probe, &painter, &sized);
    EXPECT_EQ(sized.title_lines.size(), 1u);
    EXPECT_EQ(sized.title_band, sized.title_px * 8 / 5);
    SheetText text = probe;
    const std::vector<std::string> pool = {"Terrell-Penrose", "effect:", "a", "cube", "at", "0.8c", "and", "a",
                                           "sphere", "at", "0.999c", "seen", "by", "the", "camera"};
    for (size_t i = 0; painter.width(text.title, sized.title_px) < 2 * sized.width; ++i)
        text.title = (i ? text.title + " " : "") + pool[i % pool.size()];
    SheetLayout layout(2, 3, 96, 54, text, true);
    const RgbImage sheet = drawSheet(text, &painter, &layout);
    ASSERT_GE(layout.title_lines.size(), 2u);
    std::vector<std::string> drawn;
    for (const std::string& line : layout.title_lines) {
        EXPECT_LE(painter.width(line, layout.title_px), layout.width - 2 * layout.pad) << line;
        for (const std::string& w : words(line)) drawn.push_back(w);
    }
    EXPECT_EQ(drawn, words(text.title));
    EXPECT_EQ(layout.width, sized.width);
    EXPECT_EQ(layout.height - sized.height, int(layout.title_lines.size() - 1) * layout.titleStep());
    EXPECT_EQ(sheet.height, layout.height);
    for (size_t i = 0; i < layout.title_lines.size(); ++i) {
        const int baseline = layout.title_px * 5 / 4 + int(i) * layout.titleStep();
        EXPECT_GT(inkIn(sheet, 0, baseline - layout.title_px, sheet.width, baseline + 1), 20) << "line " << i;
    }
    EXPECT_EQ(inkIn(sheet, 0, 0, 1, layout.title_band), 0);
    EXPECT_EQ(inkIn(sheet, sheet.width - 1, 0, sheet.width, layout.title_band), 0);
    EXPECT_EQ(layout.panelY(0), layout.title_band + layout.top_band + SheetLayout::kGap);
}

// A word wider than the sheet is broken between characters, one line after another, none wider.
TEST(Sheet, AWordWiderThanTheSheetBreaksBetweenCharacters) {
    TextPainter painter;
    std::string error;
    ASSERT_TRUE(painter.open(kLabelFontPath, &error)) << error;
    const std::string word(120, 'W');
    const std::vector<std::string> lines = wrapText(painter, word, 16, 200);
    ASSERT_GE(lines.size(), 2u);
    std::string joined;
    for (const std::string& l : lines) {
        EXPECT_LE(painter.width(l, 16), 200);
        EXPECT_FALSE(l.empty());
        joined += l;
    }
    EXPECT_EQ(joined, word);
}

// --row-labels and --column-labels replace the model names and camera times: the left band fits the
// widest given label (its width by FreeType plus two pads), and a wrong count is refused in one line.
TEST(Sheet, FigureTakesRowAndColumnLabels) {
    using testcli::apparentRun;
    testcli::TempDir dir;
    std::filesystem::create_directories(dir.str());
    const std::string scene = testcli::source("data/scenes/flanges.json");
    const std::vector<std::string> common = {"figure", scene, "--times", "5,10", "--models", "instant,relativistic",
                                             "--size", "96x54", "--quiet"};
    std::vector<std::string> bare = common, named = common;
    bare.insert(bare.end(), {"--out", (dir / "bare.png").string(), "--no-labels", "--samples", "1"});
    named.insert(named.end(), {"--out", (dir / "named.png").string(), "--samples", "1", "--row-labels", "infinite c,what one sees\\, at c",
                               "--column-labels", "before,after"});
    const auto rb = apparentRun(bare), rn = apparentRun(named);
    ASSERT_EQ(rb.code, 0) << rb.err;
    ASSERT_EQ(rn.code, 0) << rn.err;
    RgbImage off, on;
    std::string error;
    ASSERT_TRUE(readPng((dir / "bare.png").string(), &off, &error)) << error;
    ASSERT_TRUE(readPng((dir / "named.png").string(), &on, &error)) << error;
    TextPainter painter;
    ASSERT_TRUE(painter.open(kLabelFontPath, &error)) << error;
    const SheetLayout layout(2, 2, 96, 54, {}, true);
    const int widest = std::max(painter.width("infinite c", layout.font_px), painter.width("what one sees, at c", layout.font_px));
    EXPECT_EQ(on.width - off.width, widest + 2 * layout.pad);
    EXPECT_EQ(on.height - off.height, layout.font_px * 8 / 5);
    const std::pair<std::vector<std::string>, std::string> bad[] = {
        {{"--row-labels", "one"}, "--row-labels: 1 labels for 2 models"},
        {{"--column-labels", "a,b,c"}, "--column-labels: 3 labels for 2 columns"},
        {{"--row-labels", "a,b", "--no-labels"}, "--no-labels: not with --row-labels or --column-labels"},
        {{"--samples", "8"}, "--samples: 8 is not a square from 1 to 256"},
    };
    for (const auto& [extra, expected] : bad) {
        std::vector<std::string> args = common;
        args.insert(args.end(), {"--out", (dir / "bad.png").string()});
        args.insert(args.end(), extra.begin(), extra.end());
        const auto r = apparentRun(args);
        EXPECT_EQ(r.code, 2) << expected;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
    }
}
