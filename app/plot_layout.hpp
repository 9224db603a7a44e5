// Where a figure's axes end and its legend goes (app/plot_figures.hpp): ranges fitted to the data
// with a small margin (not gnuplot's round numbers, which left a 1..100 decade for data of 2.6..15),
// and the legend inside the axes: in a corner where it covers no data point, else at the top
// (in a column, or its entries side by side) with the range's top raised to make room.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "app/plot_style.hpp"

namespace bellows {

struct AxisRange {
  double low = 0.0, high = 1.0;
};

/// One drawn curve's points (x and y of the same length; NaN values are skipped).
struct SeriesPoints {
  const Eigen::VectorXd* x = nullptr;
  const Eigen::VectorXd* y = nullptr;
};

struct LegendSize {
  int rows = 0;           // entries
  int widest_title = 0;   // characters of the longest entry
  int heading_chars = 0;  // characters of the legend's own title (0: none, no row for it)
};

struct PlotLayout {
  AxisRange x, y;
  std::string key_corner;   // "top right", "top left", "bottom right", "bottom left", "top center"
  int key_columns = 1;      // more than one: the entries side by side across the top
  std::string key_heading;  // the legend's own title ("": none)
};

/// The layout of a figure of `series` over `x` in `style` (a log y axis when `log_y`: margins and
/// the legend's room measured in decades).
PlotLayout plot_layout(const std::vector<SeriesPoints>& series, AxisRange x, const LegendSize& legend,
                       const FigureStyle& style, bool log_y);

/// gnuplot's commands for `layout`: the ranges and the legend inside the axes.
std::string layout_commands(const PlotLayout& layout);

/// Labelled ticks of a log axis over `range`: 1, 2, 5 times the powers of ten within it, or finer
/// steps when those give fewer than three. As a `set ytics (...)` line.
std::string log_tics(AxisRange range);

}  // namespace bellows
