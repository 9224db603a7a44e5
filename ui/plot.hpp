// Line plots into a Canvas: braille dots (2x4 per cell) in a UTF-8 terminal, one ASCII mark per
// cell otherwise. Each series is drawn as connected segments; the axes are labelled at the
// left (y: max, min, and zero when in range) and at the bottom (x: first and last value).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "ui/canvas.hpp"

namespace bellows::ui {

struct PlotSeries {
  std::span<const double> x;
  std::span<const double> y;
  Role role = Role::kSeries1;
  char ascii_mark = '*';  // the mark in ASCII mode; keeps series apart without colours
};

struct PlotOptions {
  bool braille = true;
  const char* x_unit = "";             // e.g. "s"
  const char* y_format = "%.1f";       // printf format of the y labels
  std::optional<double> cursor_x;      // a vertical cursor line at this x
  std::optional<double> y_min, y_max;  // fixed range; otherwise from the data (with a margin)
  bool integer_x = false;              // x labels as whole numbers (iterations)
  bool log_y = false;                  // y on a log10 scale (values <= 0 are left out); y_min, y_max as values
};

/// The data range the plot would use for `series` (for tests and for sharing scales).
struct PlotRange {
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
};
PlotRange plot_range(const std::vector<PlotSeries>& series, const PlotOptions& options);

/// Draws into `area` (labels included). Does nothing when `area` is too small for a plot.
void draw_plot(Canvas& canvas, const Rect& area, const std::vector<PlotSeries>& series, const PlotOptions& options);

/// A horizontal bar of `fraction` in [0, 1] over `width` cells (eighth blocks in Unicode).
std::string bar(double fraction, int width, const Glyphs& glyphs);

}  // namespace bellows::ui

namespace bellows::ui {

struct LegendItem {
  std::string label;
  Role role;
  char ascii_mark;
};
/// Writes the legend into the right part of a frame's top edge: a mark in each series' role, then
/// its label.
void legend(Canvas& canvas, const Rect& frame, const std::vector<LegendItem>& items, const Glyphs& glyphs);

}  // namespace bellows::ui
