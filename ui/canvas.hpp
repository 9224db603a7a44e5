// A grid of styled character cells: what a screen looks like, independent of ncurses. Renderers
// draw into a Canvas; the terminal copies it to the screen, and tests read it back as text lines.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace bellows::ui {

/// What a cell means; the terminal maps each role to colours, or to attributes without colours.
enum class Role : std::uint8_t {
  kNormal,
  kDim,       // greyed: not available now
  kTitle,     // panel titles, headers
  kSelected,  // the highlighted row of a list
  kKey,       // a key in the function bar or help
  kSafe,      // engine states
  kArmed,
  kRunning,
  kFault,
  kWarning,
  kGood,
  kSeries1,  // plot series: current, previous, chosen
  kSeries2,
  kSeries3,
  kCursor,
};

/// The cell right of a wide glyph (CJK, fullwidth forms: two cells) holds this: it is drawn by the
/// glyph on its left.
inline constexpr char32_t kWideContinuation = 0;

struct Cell {
  char32_t glyph = U' ';
  Role role = Role::kNormal;
  bool bold = false;
};

struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
  int right() const { return x + width; }    // one past the last column
  int bottom() const { return y + height; }  // one past the last row
  bool empty() const { return width <= 0 || height <= 0; }
};

/// The glyphs a screen uses: Unicode box drawing and blocks in a UTF-8 locale, ASCII otherwise.
struct Glyphs {
  bool unicode = true;
  char32_t horizontal, vertical, top_left, top_right, bottom_left, bottom_right, bar_full, bar_empty;
  static Glyphs for_unicode(bool unicode);
};

class Canvas {
 public:
  Canvas(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  Rect bounds() const { return {0, 0, width_, height_}; }

  void clear();
  /// Writes UTF-8 `text` from (x, y), clipped at `clip_right` (default: the canvas edge).
  /// Returns the column after the last cell written.
  int put(int x, int y, std::string_view text, Role role = Role::kNormal, bool bold = false, int clip_right = -1);
  void put_glyph(int x, int y, char32_t glyph, Role role = Role::kNormal, bool bold = false);
  void fill(const Rect& area, char32_t glyph, Role role = Role::kNormal);
  /// Restyles the cells of `area` without changing their glyphs.
  void set_role(const Rect& area, Role role, bool bold = false);
  /// A frame around `area` with `title` in its top edge.
  void frame(const Rect& area, const Glyphs& glyphs, std::string_view title = {}, Role title_role = Role::kTitle);

  const Cell& at(int x, int y) const { return cells_[static_cast<std::size_t>(y * width_ + x)]; }
  /// Row `y` as UTF-8, trailing spaces removed.
  std::string line(int y) const;
  std::vector<std::string> lines() const;
  /// All lines joined with '\n' (for tests and the docs' captures).
  std::string text() const;

 private:
  void set_cell(int x, int y, const Cell& value);
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  Cell& cell(int x, int y) { return cells_[static_cast<std::size_t>(y * width_ + x)]; }

  int width_, height_;
  std::vector<Cell> cells_;
};

/// Decodes UTF-8 (invalid bytes become '?').
std::u32string decode_utf8(std::string_view text);
void append_utf8(std::string& out, char32_t glyph);
/// Cells a glyph takes on a terminal (wcwidth in UTF-8): 1, 2 for wide ones, 0 for combining marks.
int glyph_width(char32_t glyph);
/// Number of cells `text` takes on the screen (its display width: a wide glyph takes two).
int text_width(std::string_view text);
/// The end of `text` that fits in `width` cells (a long prompt shows what was typed last).
std::string tail_fit(std::string_view text, int width);

/// printf into a std::string.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
/// `text` cut or padded with spaces to exactly `width` cells (display width).
std::string fit(std::string_view text, int width);
/// `text` broken into lines of at most `width` cells (display width), at spaces where possible.
std::vector<std::string> wrap(std::string_view text, int width);

}  // namespace bellows::ui
