#include "ui/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace bellows::ui {
namespace {

constexpr int kLabelWidth = 7;  // y labels, right-aligned, then the axis

// Braille dot bits of a 2x4 cell: [column][row].
constexpr char32_t kBrailleBase = 0x2800;
constexpr unsigned kBrailleBits[2][4] = {{0x01, 0x02, 0x04, 0x40}, {0x08, 0x10, 0x20, 0x80}};

// A grid of dots (braille) or cells (ASCII) with the series role and mark that last touched it.
class DotGrid {
 public:
  DotGrid(int cols, int rows, bool braille)
      : cols_(cols),
        rows_(rows),
        braille_(braille),
        dots_x_(braille ? cols * 2 : cols),
        dots_y_(braille ? rows * 4 : rows),
        bits_(static_cast<std::size_t>(cols * rows), 0u),
        roles_(static_cast<std::size_t>(cols * rows), Role::kNormal),
        marks_(static_cast<std::size_t>(cols * rows), ' ') {}

  int dots_x() const { return dots_x_; }
  int dots_y() const { return dots_y_; }

  void set(int dx, int dy, Role role, char mark) {
    if (dx < 0 || dy < 0 || dx >= dots_x_ || dy >= dots_y_) return;
    const int cx = braille_ ? dx / 2 : dx, cy = braille_ ? dy / 4 : dy;
    const auto i = static_cast<std::size_t>(cy * cols_ + cx);
    bits_[i] |= braille_ ? kBrailleBits[dx % 2][dy % 4] : 1u;
    roles_[i] = role;
    marks_[i] = mark;
  }

  void line(int x0, int y0, int x1, int y1, Role role, char mark) {  // Bresenham
    const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
      set(x0, y0, role, mark);
      if (x0 == x1 && y0 == y1) break;
      const int e2 = 2 * err;
      if (e2 >= dy) {
        err += dy;
        x0 += sx;
      }
      if (e2 <= dx) {
        err += dx;
        y0 += sy;
      }
    }
  }

  void draw(Canvas& canvas, int left, int top) const {
    for (int cy = 0; cy < rows_; ++cy) {
      for (int cx = 0; cx < cols_; ++cx) {
        const auto i = static_cast<std::size_t>(cy * cols_ + cx);
        if (bits_[i] == 0) continue;
        const char32_t glyph = braille_ ? kBrailleBase + bits_[i] : static_cast<char32_t>(marks_[i]);
        canvas.put_glyph(left + cx, top + cy, glyph, roles_[i]);
      }
    }
  }

 private:
  int cols_, rows_;
  bool braille_;
  int dots_x_, dots_y_;
  std::vector<unsigned> bits_;
  std::vector<Role> roles_;
  std::vector<char> marks_;
};

std::string label(const char* fmt, double value) {
  std::string text = format(fmt, value);
  // "-0.0" is a zero that rounding made negative.
  if (!text.empty() && text[0] == '-' && text.find_first_of("123456789") == std::string::npos) text.erase(0, 1);
  return text;
}

}  // namespace

PlotRange plot_range(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  PlotRange r;
  bool any = false;
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;
  for (const PlotSeries& s : series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      if (!any) {
        x_min = x_max = s.x[i];
        y_min = y_max = s.y[i];
        any = true;
      }
      x_min = std::min(x_min, s.x[i]);
      x_max = std::max(x_max, s.x[i]);
      y_min = std::min(y_min, s.y[i]);
      y_max = std::max(y_max, s.y[i]);
    }
  }
  if (any) {
    const double margin = 0.05 * (y_max - y_min);
    r = {x_min, x_max, y_min - margin, y_max + margin};
  }
  if (options.y_min) r.y_min = *options.y_min;
  if (options.y_max) r.y_max = *options.y_max;
  if (r.x_max <= r.x_min) r.x_max = r.x_min + 1.0;
  if (r.y_max <= r.y_min) {
    const double half = std::max(std::abs(r.y_min) * 0.1, 1e-3);
    r.y_min -= half;
    r.y_max += half;
  }
  return r;
}

namespace {
void draw_linear_plot(Canvas& canvas, const Rect& area, const std::vector<PlotSeries>& series,
                      const PlotOptions& options, bool log_labels);
}  // namespace

void draw_plot(Canvas& canvas, const Rect& area, const std::vector<PlotSeries>& series, const PlotOptions& options) {
  if (!options.log_y) {
    draw_linear_plot(canvas, area, series, options, false);
    return;
  }
  // A log scale is a linear plot of log10(y), labelled with the values.
  std::vector<std::vector<double>> logs(series.size());
  std::vector<PlotSeries> logged;
  for (std::size_t i = 0; i < series.size(); ++i) {
    for (double y : series[i].y) logs[i].push_back(std::isfinite(y) && y > 0.0 ? std::log10(y) : std::nan(""));
    logged.push_back({series[i].x, logs[i], series[i].role, series[i].ascii_mark});
  }
  PlotOptions linear = options;
  linear.log_y = false;
  const auto log_of = [](std::optional<double> v) {
    return v && *v > 0.0 ? std::optional<double>(std::log10(*v)) : std::optional<double>();
  };
  linear.y_min = log_of(options.y_min);
  linear.y_max = log_of(options.y_max);
  draw_linear_plot(canvas, area, logged, linear, true);
}

namespace {
void draw_linear_plot(Canvas& canvas, const Rect& area, const std::vector<PlotSeries>& series,
                      const PlotOptions& options, bool log_labels) {
  const int cols = area.width - kLabelWidth - 1;
  const int rows = area.height - 1;  // the bottom row holds the x labels
  if (cols < 4 || rows < 2) return;
  const PlotRange r = plot_range(series, options);
  const int left = area.x + kLabelWidth + 1;
  const int top = area.y;

  // Axes and labels.
  for (int y = 0; y < rows; ++y) canvas.put_glyph(left - 1, top + y, options.braille ? U'│' : U'|', Role::kDim);
  const auto y_label = [&](double y) {
    return fit(label(options.y_format, log_labels ? std::pow(10.0, y) : y), kLabelWidth);
  };
  canvas.put(area.x, top, y_label(r.y_max), Role::kDim);
  canvas.put(area.x, top + rows - 1, y_label(r.y_min), Role::kDim);
  if (log_labels && rows >= 5) {            // a log axis: its middle too (the geometric mean)
    const int middle_row = (rows - 1) / 2;  // a whole row: the label names that row's value
    canvas.put(area.x, top + middle_row, y_label(r.y_max - (r.y_max - r.y_min) * middle_row / (rows - 1)), Role::kDim);
  }
  if (!log_labels && r.y_min < 0.0 && r.y_max > 0.0) {
    const int zero_row = static_cast<int>(std::lround((r.y_max / (r.y_max - r.y_min)) * (rows - 1)));
    if (zero_row > 0 && zero_row < rows - 1) {
      canvas.put(area.x, top + zero_row, fit("0", kLabelWidth), Role::kDim);
      for (int x = 0; x < cols; ++x)
        canvas.put_glyph(left + x, top + zero_row, options.braille ? U'┈' : U'.', Role::kDim);
    }
  }
  const char* x_fmt = options.integer_x ? "%.0f" : "%.1f";
  const std::string x_lo = label(x_fmt, r.x_min) + options.x_unit;
  const std::string x_hi = label(x_fmt, r.x_max) + options.x_unit;
  canvas.put(left, top + rows, x_lo, Role::kDim);
  canvas.put(left + cols - text_width(x_hi), top + rows, x_hi, Role::kDim);

  DotGrid grid(cols, rows, options.braille);
  const auto to_dx = [&](double x) {
    return static_cast<int>(std::lround((x - r.x_min) / (r.x_max - r.x_min) * (grid.dots_x() - 1)));
  };
  const auto to_dy = [&](double y) {
    const double clamped = std::clamp(y, r.y_min, r.y_max);
    return static_cast<int>(std::lround((r.y_max - clamped) / (r.y_max - r.y_min) * (grid.dots_y() - 1)));
  };
  for (const PlotSeries& s : series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    bool have_previous = false;
    int px = 0, py = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        have_previous = false;
        continue;
      }
      const int dx = to_dx(s.x[i]), dy = to_dy(s.y[i]);
      if (have_previous) grid.line(px, py, dx, dy, s.role, s.ascii_mark);
      else grid.set(dx, dy, s.role, s.ascii_mark);
      px = dx;
      py = dy;
      have_previous = true;
    }
  }
  grid.draw(canvas, left, top);

  if (options.cursor_x && *options.cursor_x >= r.x_min && *options.cursor_x <= r.x_max) {
    const int cx = static_cast<int>(std::lround((*options.cursor_x - r.x_min) / (r.x_max - r.x_min) * (cols - 1)));
    for (int y = 0; y < rows; ++y) {
      const Cell& c = canvas.at(left + cx, top + y);
      if (c.glyph == U' ' || c.role == Role::kDim)
        canvas.put_glyph(left + cx, top + y, options.braille ? U'┆' : U':', Role::kCursor);
      else canvas.set_role({left + cx, top + y, 1, 1}, Role::kCursor, true);
    }
  }
}
}  // namespace

std::string bar(double fraction, int width, const Glyphs& glyphs) {
  if (width <= 0) return {};
  const double f = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  std::string out;
  if (!glyphs.unicode) {
    const int full = static_cast<int>(std::lround(f * width));
    out.append(static_cast<std::size_t>(full), '#');
    out.append(static_cast<std::size_t>(width - full), '.');
    return out;
  }
  static constexpr char32_t kEighths[] = {U' ', U'▏', U'▎', U'▍', U'▌', U'▋', U'▊', U'▉'};
  const int eighths = static_cast<int>(std::lround(f * width * 8));
  const int full = eighths / 8, rest = eighths % 8;
  for (int i = 0; i < full; ++i) append_utf8(out, glyphs.bar_full);
  int used = full;
  if (rest > 0 && used < width) {
    append_utf8(out, kEighths[rest]);
    ++used;
  }
  for (; used < width; ++used) append_utf8(out, glyphs.bar_empty);
  return out;
}

}  // namespace bellows::ui

namespace bellows::ui {

void legend(Canvas& canvas, const Rect& frame, const std::vector<LegendItem>& items, const Glyphs& glyphs) {
  int width = 0;
  for (const LegendItem& item : items) width += text_width(item.label) + 3;
  int x = frame.right() - 2 - width;
  const int title_end = frame.x + 4;  // keep at least the frame's corner and some title
  if (x < title_end) return;
  for (const LegendItem& item : items) {
    x = canvas.put(x, frame.y, " ", Role::kDim);
    canvas.put_glyph(x++, frame.y, glyphs.unicode ? U'■' : static_cast<char32_t>(item.ascii_mark), item.role, true);
    x = canvas.put(x, frame.y, " " + item.label, Role::kDim);
  }
  // Up to the corner: the frame's line again (a long title may have run under the legend).
  const Cell corner = canvas.at(frame.right() - 1, frame.y);
  for (; x < frame.right() - 1; ++x) canvas.put_glyph(x, frame.y, glyphs.horizontal, corner.role, corner.bold);
}

}  // namespace bellows::ui
