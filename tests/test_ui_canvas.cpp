// The console's drawing primitives: the canvas as text, UTF-8, clipping, braille and ASCII plots.
#include <gtest/gtest.h>

#include <cmath>

#include "ui/canvas.hpp"
#include "ui/plot.hpp"
#include "tests/test_support.hpp"

namespace bellows::ui {
namespace {

using testing::ascii_only;

int count_braille(const std::string& text) {
  int n = 0;
  for (char32_t g : decode_utf8(text)) n += (g >= 0x2801 && g <= 0x28FF) ? 1 : 0;
  return n;
}

TEST(UiCanvas, WritesClipsAndReadsBackAsText) {
  Canvas c(10, 3);
  c.put(2, 0, "hello world");
  c.put(-2, 1, "abcdef");
  c.put(0, 5, "outside");
  EXPECT_EQ(c.line(0), "  hello wo");
  EXPECT_EQ(c.line(1), "cdef");
  EXPECT_EQ(c.line(2), "");
  EXPECT_EQ(c.text(), "  hello wo\ncdef\n\n");
}

// Issue 23: text is measured by its display width (wcwidth), so a wide glyph takes two cells.
TEST(UiCanvas, WideGlyphsTakeTwoCells) {
  const std::string message = "S: '\uff10.\uff15' is not a number";  // fullwidth 0 and 5
  EXPECT_EQ(text_width("\uff10.\uff15"), 5);
  EXPECT_EQ(text_width(message), 26);
  Canvas c(30, 2);
  EXPECT_EQ(c.put(0, 0, message, Role::kNormal, false, 20), 20);
  EXPECT_EQ(c.line(0), "S: '\uff10.\uff15' is not a");  // cut at 20 cells, not at 20 code points
  EXPECT_EQ(fit("\uff10.\uff15", 4), "\uff10. ");       // the wide 5 does not fit half
  EXPECT_EQ(text_width(fit(message, 11)), 11);
  for (const std::string& line : wrap(message, 12)) EXPECT_LE(text_width(line), 12) << line;
  EXPECT_EQ(tail_fit("ab\uff10", 3), "b\uff10");
  c.put(0, 1, "\uff10x");
  c.put(1, 1, "y");  // over the right half of the wide 0: its left half goes too
  EXPECT_EQ(c.line(1), " yx");
}

TEST(UiCanvas, ControlsFromFilesOrTheBusNeverReachTheTerminal) {
  Canvas canvas(24, 1);
  canvas.put(0, 0,
             "a\x1b[2J\nb\xc2\x9b\xe2\x80\xae"
             "c",
             Role::kNormal);
  EXPECT_EQ(canvas.line(0), "a?[2J?b??c");
}

TEST(UiCanvas, Utf8RoundTripsAndCountsCodePoints) {
  const std::string text = "a\u2800\u2500\u00b0z";
  EXPECT_EQ(text_width(text), 5);
  Canvas c(8, 1);
  c.put(0, 0, text, Role::kTitle, true);
  EXPECT_EQ(c.line(0), text);
  EXPECT_EQ(c.at(1, 0).glyph, U'\u2800');
  EXPECT_EQ(c.at(1, 0).role, Role::kTitle);
  EXPECT_TRUE(c.at(1, 0).bold);
  // Invalid and truncated sequences become '?' instead of breaking the line.
  EXPECT_EQ(decode_utf8("a\xff"
                        "b"),
            U"a?b");
  EXPECT_EQ(decode_utf8("a\xe2\x94"), U"a?");
}

TEST(UiCanvas, FitCutsAndPads) {
  EXPECT_EQ(fit("abc", 5), "abc  ");
  EXPECT_EQ(fit("abcdef", 3), "abc");
  EXPECT_EQ(fit("\u2500\u2500\u2500", 2), "\u2500\u2500");
}

TEST(UiCanvas, WrapBreaksAtSpaces) {
  EXPECT_EQ(wrap("one two three", 7), (std::vector<std::string>{"one two", "three"}));
  EXPECT_EQ(wrap("abcdefghij", 4), (std::vector<std::string>{"abcd", "efgh", "ij"}));
  EXPECT_EQ(wrap("", 4), std::vector<std::string>{});
  EXPECT_EQ(wrap("\u2500\u2500 \u2500", 2), (std::vector<std::string>{"\u2500\u2500", "\u2500"}));
}

TEST(UiCanvas, FrameDrawsBordersAndTitleInBothGlyphSets) {
  Canvas c(12, 4);
  c.frame({0, 0, 12, 4}, Glyphs::for_unicode(false), "T");
  EXPECT_EQ(c.line(0), "+- T ------+");
  EXPECT_EQ(c.line(1), "|          |");
  EXPECT_EQ(c.line(3), "+----------+");
  Canvas u(12, 4);
  u.frame({0, 0, 12, 4}, Glyphs::for_unicode(true), "T");
  EXPECT_EQ(u.line(0), "\u250c\u2500 T \u2500\u2500\u2500\u2500\u2500\u2500\u2510");
}

TEST(UiPlot, ALegendOverALongTitleEndsWithTheFrameLine) {
  Canvas c(24, 4);
  const Rect area{0, 0, 24, 4};
  const Glyphs g = Glyphs::for_unicode(false);
  c.frame(area, g, "Correction u_ilc (bar)");
  legend(c, area, {{"it 5", Role::kSeries1, '.'}, {"next", Role::kSeries2, '*'}}, g);
  EXPECT_EQ(c.line(0), "+- Corre . it 5 * next-+");  // not "...next)+": the title's end is covered
}

TEST(UiPlot, BrailleInUtf8AndOnlyAsciiOtherwise) {
  std::vector<double> x, y;
  for (int i = 0; i <= 100; ++i) {
    x.push_back(i * 0.08);
    y.push_back(30.0 * std::sin(i * 0.1));
  }
  PlotOptions options;
  options.x_unit = "s";
  Canvas braille(60, 12);
  options.braille = true;
  draw_plot(braille, braille.bounds(), {{x, y, Role::kSeries1, '*'}}, options);
  EXPECT_GT(count_braille(braille.text()), 40);

  Canvas ascii(60, 12);
  options.braille = false;
  draw_plot(ascii, ascii.bounds(), {{x, y, Role::kSeries1, '*'}}, options);
  EXPECT_TRUE(ascii_only(ascii.text())) << ascii.text();
  EXPECT_NE(ascii.text().find('*'), std::string::npos);
  // Labels: the range of y (with its margin) and of x.
  EXPECT_EQ(ascii.line(0).rfind("33.0", 0), 0u) << ascii.text();  // 30 deg plus a 5 % margin
  EXPECT_EQ(ascii.line(10).rfind("-33.0", 0), 0u);
  EXPECT_NE(ascii.line(11).find("0.0s"), std::string::npos);
  EXPECT_NE(ascii.line(11).find("8.0s"), std::string::npos);
}

TEST(UiPlot, SeriesLandWhereTheirValuesAre) {
  // A rising line: its first point bottom left, its last top right of the data area.
  const std::vector<double> x = {0.0, 1.0}, y = {0.0, 1.0};
  PlotOptions options;
  options.braille = false;
  options.y_min = 0.0;
  options.y_max = 1.0;
  Canvas c(30, 6);
  draw_plot(c, c.bounds(), {{x, y, Role::kSeries2, 'o'}}, options);
  const int left = 8, right = 29, top = 0, bottom = 4;  // 7 label columns + the axis
  EXPECT_EQ(c.at(left, bottom).glyph, U'o');
  EXPECT_EQ(c.at(right, top).glyph, U'o');
  EXPECT_EQ(c.at(right, top).role, Role::kSeries2);
  EXPECT_EQ(c.at(left, top).glyph, U' ');
}

TEST(UiPlot, CursorAndZeroLineAndNoNegativeZeroLabels) {
  const std::vector<double> x = {0.0, 2.0}, y = {-1e-9, 1e-9};
  PlotOptions options;
  options.braille = false;
  options.cursor_x = 1.0;
  Canvas c(40, 8);
  draw_plot(c, c.bounds(), {{x, y, Role::kSeries1, '*'}}, options);
  EXPECT_EQ(c.text().find("-0.0"), std::string::npos) << c.text();
  const int column = 8 + 16;  // labels and axis, then the middle of 32 data columns (rounded)
  bool cursor = true;
  for (int row = 0; row < 7; ++row) cursor = cursor && c.at(column, row).role == Role::kCursor;
  EXPECT_TRUE(cursor) << c.text();
}

TEST(UiPlot, NonFiniteValuesBreakTheLineInsteadOfCrashing) {
  const std::vector<double> x = {0, 1, 2, 3}, y = {0, NAN, INFINITY, 1};
  Canvas c(30, 6);
  PlotOptions options;
  options.braille = true;
  draw_plot(c, c.bounds(), {{x, y, Role::kSeries1, '*'}}, options);
  EXPECT_EQ(count_braille(c.text()), 2);
}

TEST(UiPlot, TooSmallAreaDrawsNothing) {
  Canvas c(10, 2);
  const std::vector<double> x = {0, 1}, y = {0, 1};
  draw_plot(c, c.bounds(), {{x, y, Role::kSeries1, '*'}}, PlotOptions{});
  EXPECT_EQ(c.text(), "\n\n");
}

TEST(UiPlot, BarsShowTheFraction) {
  EXPECT_EQ(bar(0.5, 10, Glyphs::for_unicode(false)), "#####.....");
  EXPECT_EQ(bar(2.0, 4, Glyphs::for_unicode(false)), "####");
  EXPECT_EQ(bar(NAN, 4, Glyphs::for_unicode(false)), "....");
  EXPECT_EQ(text_width(bar(0.33, 10, Glyphs::for_unicode(true))), 10);
  EXPECT_EQ(bar(1.0, 3, Glyphs::for_unicode(true)), "\u2588\u2588\u2588");
}

}  // namespace
}  // namespace bellows::ui
