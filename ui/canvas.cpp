#include "ui/canvas.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cwchar>
#include <locale.h>

#include "engine/base/printable_text.hpp"

namespace bellows::ui {

Glyphs Glyphs::for_unicode(bool unicode) {
  if (unicode) return {true, U'─', U'│', U'┌', U'┐', U'└', U'┘', U'█', U'░'};
  return {false, U'-', U'|', U'+', U'+', U'+', U'+', U'#', U'.'};
}

Canvas::Canvas(int width, int height)
    : width_(std::max(width, 0)), height_(std::max(height, 0)), cells_(static_cast<std::size_t>(width_ * height_)) {}

void Canvas::clear() { std::fill(cells_.begin(), cells_.end(), Cell{}); }

int glyph_width(char32_t glyph) {
  if (glyph >= 0x20 && glyph < 0x7f) return 1;
  if (is_terminal_control(glyph)) return 1;  // shown as '?'
  // wcwidth in a UTF-8 locale of this thread's own, whatever the program's locale is (tests run in "C").
  static const locale_t utf8 = newlocale(LC_CTYPE_MASK, "C.UTF-8", static_cast<locale_t>(nullptr));
  if (utf8 == static_cast<locale_t>(nullptr)) return 1;
  const locale_t previous = uselocale(utf8);
  const int width = wcwidth(static_cast<wchar_t>(glyph));
  uselocale(previous);
  return width < 0 ? 1 : std::min(width, 2);  // unknown: one cell
}

void Canvas::set_cell(int x, int y, const Cell& value) {
  // Overwriting half of a wide glyph blanks its other half: no cell is left pointing at nothing.
  Cell& target = cell(x, y);
  if (target.glyph == kWideContinuation && x > 0) cell(x - 1, y).glyph = U' ';
  if (target.glyph != kWideContinuation && x + 1 < width_ && cell(x + 1, y).glyph == kWideContinuation) {
    cell(x + 1, y).glyph = U' ';
  }
  target = value;
}

int Canvas::put(int x, int y, std::string_view text, Role role, bool bold, int clip_right) {
  const int right = clip_right < 0 ? width_ : std::min(clip_right, width_);
  if (y < 0 || y >= height_) return x;
  for (char32_t glyph : decode_utf8(text)) {
    // Text from files and the bus may hold controls: a cell never sends one to the terminal.
    if (is_terminal_control(glyph)) glyph = U'?';
    const int cells = glyph_width(glyph);
    if (cells == 0) continue;      // a combining mark has no cell of its own
    if (x + cells > right) break;  // a wide glyph that does not fit whole is not drawn
    if (x >= 0) {
      set_cell(x, y, Cell{glyph, role, bold});
      if (cells == 2) set_cell(x + 1, y, Cell{kWideContinuation, role, bold});
    }
    x += cells;
  }
  return x;
}

void Canvas::put_glyph(int x, int y, char32_t glyph, Role role, bool bold) {
  if (inside(x, y)) set_cell(x, y, Cell{glyph, role, bold});
}

void Canvas::fill(const Rect& area, char32_t glyph, Role role) {
  for (int y = area.y; y < area.bottom(); ++y) {
    for (int x = area.x; x < area.right(); ++x) put_glyph(x, y, glyph, role);
  }
}

void Canvas::set_role(const Rect& area, Role role, bool bold) {
  for (int y = std::max(area.y, 0); y < std::min(area.bottom(), height_); ++y) {
    for (int x = std::max(area.x, 0); x < std::min(area.right(), width_); ++x) {
      cell(x, y).role = role;
      cell(x, y).bold = bold;
    }
  }
}

void Canvas::frame(const Rect& area, const Glyphs& g, std::string_view title, Role title_role) {
  if (area.width < 2 || area.height < 2) return;
  const int r = area.right() - 1, b = area.bottom() - 1;
  for (int x = area.x + 1; x < r; ++x) {
    put_glyph(x, area.y, g.horizontal, Role::kDim);
    put_glyph(x, b, g.horizontal, Role::kDim);
  }
  for (int y = area.y + 1; y < b; ++y) {
    put_glyph(area.x, y, g.vertical, Role::kDim);
    put_glyph(r, y, g.vertical, Role::kDim);
  }
  put_glyph(area.x, area.y, g.top_left, Role::kDim);
  put_glyph(r, area.y, g.top_right, Role::kDim);
  put_glyph(area.x, b, g.bottom_left, Role::kDim);
  put_glyph(r, b, g.bottom_right, Role::kDim);
  if (!title.empty()) {
    const int end = put(area.x + 2, area.y, " ", title_role, true, r);
    put(put(end, area.y, title, title_role, true, r), area.y, " ", title_role, true, r);
  }
}

std::string Canvas::line(int y) const {
  std::string out;
  int last = -1;
  for (int x = 0; x < width_; ++x) {
    if (at(x, y).glyph != U' ') last = x;
  }
  for (int x = 0; x <= last; ++x) {
    if (at(x, y).glyph != kWideContinuation) append_utf8(out, at(x, y).glyph);
  }
  return out;
}

std::vector<std::string> Canvas::lines() const {
  std::vector<std::string> out;
  out.reserve(static_cast<std::size_t>(height_));
  for (int y = 0; y < height_; ++y) out.push_back(line(y));
  return out;
}

std::string Canvas::text() const {
  std::string out;
  for (int y = 0; y < height_; ++y) {
    out += line(y);
    out += '\n';
  }
  return out;
}

std::u32string decode_utf8(std::string_view text) {
  std::u32string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const auto byte = static_cast<unsigned char>(text[i]);
    int extra = 0;
    char32_t glyph = 0;
    if (byte < 0x80) {
      glyph = byte;
    } else if ((byte & 0xE0) == 0xC0) {
      extra = 1;
      glyph = byte & 0x1F;
    } else if ((byte & 0xF0) == 0xE0) {
      extra = 2;
      glyph = byte & 0x0F;
    } else if ((byte & 0xF8) == 0xF0) {
      extra = 3;
      glyph = byte & 0x07;
    } else {
      out.push_back(U'?');
      ++i;
      continue;
    }
    if (i + static_cast<std::size_t>(extra) >= text.size()) {  // truncated sequence
      out.push_back(U'?');
      break;
    }
    bool valid = true;
    for (int k = 1; k <= extra; ++k) {
      const auto next = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
      if ((next & 0xC0) != 0x80) {
        valid = false;
        break;
      }
      glyph = (glyph << 6) | (next & 0x3F);
    }
    if (!valid) {
      out.push_back(U'?');
      ++i;
      continue;
    }
    out.push_back(glyph);
    i += static_cast<std::size_t>(extra) + 1;
  }
  return out;
}

void append_utf8(std::string& out, char32_t glyph) {
  if (glyph < 0x80) {
    out += static_cast<char>(glyph);
  } else if (glyph < 0x800) {
    out += static_cast<char>(0xC0 | (glyph >> 6));
    out += static_cast<char>(0x80 | (glyph & 0x3F));
  } else if (glyph < 0x10000) {
    out += static_cast<char>(0xE0 | (glyph >> 12));
    out += static_cast<char>(0x80 | ((glyph >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (glyph & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (glyph >> 18));
    out += static_cast<char>(0x80 | ((glyph >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((glyph >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (glyph & 0x3F));
  }
}

int text_width(std::string_view text) {
  int width = 0;
  for (char32_t glyph : decode_utf8(text)) width += glyph_width(glyph);
  return width;
}

std::string tail_fit(std::string_view text, int width) {
  const std::u32string glyphs = decode_utf8(text);
  std::size_t start = glyphs.size();
  int used = 0;
  while (start > 0 && used + glyph_width(glyphs[start - 1]) <= width) used += glyph_width(glyphs[--start]);
  std::string out;
  for (std::size_t i = start; i < glyphs.size(); ++i) append_utf8(out, glyphs[i]);
  return out;
}

std::string format(const char* fmt, ...) {
  char buffer[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buffer, sizeof buffer, fmt, args);
  va_end(args);
  return buffer;
}

std::string fit(std::string_view text, int width) {
  std::string out;
  int used = 0;
  for (char32_t glyph : decode_utf8(text)) {
    const int cells = glyph_width(glyph);
    if (used + cells > width) break;
    append_utf8(out, glyph);
    used += cells;
  }
  if (used < width) out.append(static_cast<std::size_t>(width - used), ' ');
  return out;
}

std::vector<std::string> wrap(std::string_view text, int width) {
  std::vector<std::string> lines;
  if (width <= 0) return lines;
  const std::u32string glyphs = decode_utf8(text);
  std::size_t start = 0;
  while (start < glyphs.size()) {
    // As many glyphs as `width` cells hold (at least one), then back to the last space if cut.
    std::size_t end = start;
    int used = 0;
    while (end < glyphs.size() && (end == start || used + glyph_width(glyphs[end]) <= width))
      used += glyph_width(glyphs[end++]);
    if (end < glyphs.size()) {
      const std::size_t space = glyphs.rfind(U' ', end);
      if (space != std::u32string::npos && space > start) end = space;
    }
    std::string line;
    for (std::size_t i = start; i < end; ++i) append_utf8(line, glyphs[i]);
    lines.push_back(line);
    start = end;
    while (start < glyphs.size() && glyphs[start] == U' ') ++start;
  }
  return lines;
}

}  // namespace bellows::ui
