// How the figures of a session look (docs/session-format.md, "Figures"): a size preset (the screen,
// one column or the full width of a paper), the fonts and line widths that go with it, gnuplot's
// terminal for each format, and the colours: one per drawn iteration, the same in every figure, from
// Paul Tol's colour-blind-safe "muted" scheme (its colours with at least 3:1 contrast on white).
#pragma once

#include <string>
#include <vector>

namespace bellows {

struct FigureStyle {
  std::string name;       // screen, paper-column, paper-wide
  double width_in = 0.0;  // the figure's size as printed (PDF, SVG); PNG: times png_dpi
  double height_in = 0.0;
  double font_pt = 0.0;  // every text: tick labels, axis labels, legend
  double png_dpi = 0.0;
  double line_scale = 1.0;  // gnuplot's linewidth factor at 72 dpi
  bool titles = true;       // a title above each figure (a paper's caption does that job)
};

/// The preset named `name` (screen, paper-column, paper-wide). Throws InputError for another name.
FigureStyle figure_style(const std::string& name);
/// The preset names, for help and messages.
const std::vector<std::string>& figure_style_names();

/// gnuplot's `set terminal ...` line for `format` (png, svg, pdf) in `style`. Throws InputError for
/// another format.
std::string figure_terminal(const FigureStyle& style, const std::string& format);

/// The colour (gnuplot "#rrggbb") of the drawn iteration at `position` (0: the first one drawn,
/// which is iteration 0 whenever it is drawn), and its dash type (1: solid; beyond the palette's
/// colours the colours repeat with another dash).
std::string iteration_colour(int position);
int iteration_dash(int position);
/// How many colours the palette has before they repeat.
int iteration_colours();

/// The colours of the set point and of the two chambers' pressures (not iteration colours).
inline constexpr const char* kSetpointColour = "#000000";
inline constexpr const char* kChamberAColour = "#000000";
inline constexpr const char* kChamberBColour = "#777777";

}  // namespace bellows
