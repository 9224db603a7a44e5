#include "app/plot_style.hpp"

#include <cmath>
#include <cstdio>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// Paul Tol's "muted" scheme without its pale colours (sand, cyan, teal: under 3:1 against white),
// ordered so that the first four (the default choice of iterations) differ most.
constexpr const char* kIterationPalette[] = {"#CC6677", "#332288", "#117733", "#999933", "#AA4499", "#882255"};
constexpr int kPaletteSize = static_cast<int>(sizeof kIterationPalette / sizeof kIterationPalette[0]);

// A paper's figure: IEEE/IFAC columns are 3.5 in and 7.16 in wide; captions and axis text ~8 pt.
const FigureStyle kStyles[] = {
    {"screen", 10.0, 6.25, 13.0, 120.0, 1.0, true},
    {"paper-column", 3.5, 2.45, 8.0, 300.0, 0.75, false},
    {"paper-wide", 7.16, 2.6, 8.0, 300.0, 0.75, false},
};

std::string formatted(const char* format, double a, double b, double c, double d = 0.0) {
  char text[200];
  std::snprintf(text, sizeof text, format, a, b, c, d);
  return text;
}

}  // namespace

FigureStyle figure_style(const std::string& name) {
  for (const FigureStyle& style : kStyles) {
    if (style.name == name) return style;
  }
  throw InputError("figure style must be screen, paper-column or paper-wide, not '" + name + "'");
}

const std::vector<std::string>& figure_style_names() {
  static const std::vector<std::string> names = {"screen", "paper-column", "paper-wide"};
  return names;
}

std::string figure_terminal(const FigureStyle& s, const std::string& format) {
  // svg measures in points (1/72 in); pngcairo in pixels, its fonts at 96 per inch: a PNG of
  // png_dpi scales lines and points by dpi/72 and fonts by dpi/96. pdfcairo draws a font at 2/3
  // of the size it is given (measured: 72 gives a 48 pt cap height): given 3/2 of it.
  if (format == "png") {
    const double scale = s.png_dpi / 72.0;
    char text[240];
    std::snprintf(
        text, sizeof text,
        "set terminal pngcairo size %.0f,%.0f enhanced font 'DejaVu Sans,%.3g' linewidth %.3g pointscale %.3g",
        s.width_in * s.png_dpi, s.height_in * s.png_dpi, s.font_pt * s.png_dpi / 96.0, s.line_scale * scale, scale);
    return text;
  }
  if (format == "pdf") {
    return formatted("set terminal pdfcairo size %.3gin,%.3gin enhanced font 'DejaVu Sans,%.3g' linewidth %.3g",
                     s.width_in, s.height_in, s.font_pt * 1.5,
                     s.line_scale * 2.0);  // pdfcairo's line is half a point wide
  }
  if (format == "svg") {
    return formatted("set terminal svg size %.0f,%.0f dynamic enhanced font 'DejaVu Sans,%.3g' linewidth %.3g",
                     s.width_in * 72.0, s.height_in * 72.0, s.font_pt, s.line_scale);
  }
  throw InputError("figure format must be png, svg or pdf, not '" + format + "'");
}

std::string iteration_colour(int position) {
  return kIterationPalette[(position % kPaletteSize + kPaletteSize) % kPaletteSize];
}

int iteration_dash(int position) { return 1 + std::abs(position) / kPaletteSize; }

int iteration_colours() { return kPaletteSize; }

}  // namespace bellows
