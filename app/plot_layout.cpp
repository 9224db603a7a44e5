#include "app/plot_layout.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace bellows {
namespace {

constexpr double kMarginFraction = 0.04;  // of the data's span, each side of the y axis
// The axes' share of the figure (gnuplot's margins for tick labels, axis labels, a title), and
// the legend's measure in DejaVu Sans: an average glyph, a row, the sample line with its gaps and
// the box's padding (measured on the paper-column figures).
constexpr double kAxesWidthShare = 0.78, kAxesHeightShare = 0.74, kTitleHeightShare = 0.06;
constexpr double kBoxClearance = 0.03;  // of the axes' span, around the legend's box
constexpr double kCharWidthEm = 0.6, kRowHeightEm = 1.0, kBoxHeightEm = 1.0;
constexpr double kEntryChars = 6.5, kBoxChars = 2.0;  // beyond its title: an entry's sample, a box's padding

double transformed(double y, bool log_y) { return log_y ? std::log10(y) : y; }

/// A legend box as shares of the axes' width and height, in `columns` columns.
struct LegendBox {
  double width = 0.0, height = 0.0;
  int columns = 1;
};

LegendBox legend_box(const LegendSize& legend, const FigureStyle& style, int columns) {
  const double em_in = style.font_pt / 72.0;
  const double axes_width_in = style.width_in * kAxesWidthShare;
  const double axes_height_in = style.height_in * (kAxesHeightShare - (style.titles ? kTitleHeightShare : 0.0));
  const int rows = (legend.rows + columns - 1) / std::max(1, columns);
  const double entries_chars = columns * (legend.widest_title + kEntryChars);
  const double width_in = (std::max(entries_chars, legend.heading_chars + 1.0) + kBoxChars) * kCharWidthEm * em_in;
  const double height_in = ((rows + (legend.heading_chars > 0 ? 1 : 0)) * kRowHeightEm + kBoxHeightEm) * em_in;
  return {width_in / axes_width_in, height_in / axes_height_in, columns};
}

struct Candidate {
  const char* corner;
  bool right, top;
  LegendBox box;
  double high = 0.0;  // the top of the y range that leaves the box clear (transformed)
  int covered = 0;    // points under the box at the fitted range
};

/// How `candidate`'s box sits over `series` in x and [low, high]: the points it covers and the top
/// of the range that would leave it clear.
void measure(Candidate& c, const std::vector<SeriesPoints>& series, AxisRange x, double low, double high, double margin,
             bool log_y) {
  const double x_span = x.high - x.low;
  const bool centre = c.box.columns > 1;
  const double box_x0 = centre    ? x.low + 0.5 * (1.0 - c.box.width) * x_span
                        : c.right ? x.high - c.box.width * x_span
                                  : x.low;
  const double box_x1 = box_x0 + c.box.width * x_span;
  // A little beyond the box: a line passing just outside it still looks crowded.
  const double box_y0 = c.top ? high - c.box.height * (high - low) : low;
  const double box_y1 = c.top ? high : low + c.box.height * (high - low);
  double column_top = -std::numeric_limits<double>::infinity();
  c.covered = 0;
  for (const SeriesPoints& s : series) {
    for (Eigen::Index k = 0; k < s.y->size(); ++k) {
      const double px = (*s.x)(k), py = (*s.y)(k);
      if (!std::isfinite(py) || (log_y && py <= 0.0) || px < box_x0 - kBoxClearance * x_span ||
          px > box_x1 + kBoxClearance * x_span)
        continue;
      const double ty = transformed(py, log_y);
      column_top = std::max(column_top, ty);
      const double clearance = kBoxClearance * (high - low);
      if (ty >= box_y0 - clearance && ty <= box_y1 + clearance) ++c.covered;
    }
  }
  // The top that leaves a box at the top clear: column_top + margin <= top - share * (top - low).
  c.high = !c.top || !std::isfinite(column_top) || c.box.height >= 0.9
               ? high
               : std::max(high, (column_top + margin - c.box.height * low) / (1.0 - c.box.height));
}

}  // namespace

PlotLayout plot_layout(const std::vector<SeriesPoints>& series, AxisRange x, const LegendSize& legend,
                       const FigureStyle& style, bool log_y) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const SeriesPoints& s : series) {
    for (Eigen::Index k = 0; k < s.y->size(); ++k) {
      const double px = (*s.x)(k), py = (*s.y)(k);
      if (!std::isfinite(py) || px < x.low || px > x.high || (log_y && py <= 0.0)) continue;
      low = std::min(low, transformed(py, log_y));
      high = std::max(high, transformed(py, log_y));
    }
  }
  if (!std::isfinite(low)) low = 0.0, high = 1.0;
  if (high - low < 1e-9) {  // a flat curve (u_ilc of a feedback-only trial): a span around it
    const double half = log_y ? 0.1 : std::max(0.5, std::abs(low) * 0.1);
    low -= half, high += half;
  }
  const double margin = (high - low) * kMarginFraction;
  low -= margin, high += margin;

  // A column in a corner where it covers no point; else the top raised for whichever needs the
  // least: that column at the top, or the entries side by side in rows across the top.
  const LegendBox column = legend_box(legend, style, 1);
  std::vector<Candidate> candidates = {{"top right", true, true, column},
                                       {"top left", false, true, column},
                                       {"bottom right", true, false, column},
                                       {"bottom left", false, false, column}};
  for (int columns = 2; columns <= legend.rows; ++columns) {
    const LegendBox across = legend_box(legend, style, columns);
    if (across.width > 1.0) break;
    candidates.push_back({"top center", false, true, across});
  }
  for (Candidate& c : candidates) measure(c, series, x, low, high, margin, log_y);
  const Candidate* chosen = nullptr;
  for (const Candidate& c : candidates) {
    if (c.covered == 0 && c.box.columns == 1) {
      chosen = &c;
      break;
    }
  }
  if (chosen == nullptr) {
    for (const Candidate& c : candidates) {
      if (c.top && (chosen == nullptr || c.high < chosen->high)) chosen = &c;
    }
  }
  PlotLayout layout;
  layout.x = x;
  layout.key_corner = chosen->corner;
  layout.key_columns = chosen->box.columns;
  const double top = chosen->covered == 0 && chosen->box.columns == 1 ? high : chosen->high;
  layout.y = log_y ? AxisRange{std::pow(10.0, low), std::pow(10.0, top)} : AxisRange{low, top};
  return layout;
}

std::string layout_commands(const PlotLayout& layout) {
  char text[600];
  std::snprintf(
      text, sizeof text,
      "set xrange [%.9g:%.9g]\nset yrange [%.9g:%.9g]\n"
      "set key inside %s %s reverse Left samplen 2 spacing 1.0 width 1 opaque box linecolor rgb '#b0b0b0'%s\n",
      layout.x.low, layout.x.high, layout.y.low, layout.y.high, layout.key_corner.c_str(),
      layout.key_columns > 1 ? ("horizontal maxcols " + std::to_string(layout.key_columns)).c_str() : "vertical",
      layout.key_heading.empty() ? "" : (" title '" + layout.key_heading + "' noenhanced").c_str());
  return text;
}

std::string log_tics(AxisRange range) {
  std::vector<double> tics;
  for (const std::vector<double>& steps : {std::vector<double>{1, 2, 5},
                                           {1, 1.5, 2, 3, 4, 5, 6, 8},
                                           {1, 1.2, 1.4, 1.6, 1.8, 2, 2.5, 3, 3.5, 4, 5, 6, 7, 8, 9}}) {
    tics.clear();
    for (int power = static_cast<int>(std::floor(std::log10(range.low))) - 1;
         power <= static_cast<int>(std::ceil(std::log10(range.high))); ++power) {
      for (double step : steps) {
        const double tic = step * std::pow(10.0, power);
        if (tic >= range.low && tic <= range.high) tics.push_back(tic);
      }
    }
    if (tics.size() >= 3) break;
  }
  std::string out = "set ytics (";
  for (std::size_t i = 0; i < tics.size(); ++i) {
    char tic[32];
    std::snprintf(tic, sizeof tic, "%s%.6g", i > 0 ? ", " : "", tics[i]);
    out += tic;
  }
  return out + ")\n";
}

}  // namespace bellows
