// The figures of a session as gnuplot scripts (docs/session-format.md, "Figures"): RMS error per
// iteration on a log scale (optionally over the paper's curve, the drawn iterations marked in their
// colours), angle against set point, the tracking error e(t) and the learned correction u_ilc for
// chosen iterations (the paper's figures), and the pressures of one trial. Tight ranges, legends
// inside the axes where they cover no data, the set point drawn over the curves, one colour per
// iteration in every figure (app/plot_style.hpp). Pure text generation: the data go inline into the
// script as data blocks, so the script alone redraws every figure and tests can read what was
// plotted without running gnuplot.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sessions/session.hpp"

namespace bellows {

struct FigureRequest {
  std::vector<int> iterations;  // angle, error and u_ilc figures; empty: default_plot_iterations()
  int pressure_trial = -1;      // the pressures figure; -1: the last iteration
  std::vector<std::string> formats = {"png", "svg"};                // png, svg, pdf
  std::string style = "screen";                                     // figure_style(): screen, paper-column, paper-wide
  std::optional<std::vector<std::pair<double, double>>> paper_rms;  // (iteration, rms_deg) overlay
};

struct Figure {
  std::string name;                 // file stem: rms, angle, error, u_ilc, pressures
  std::vector<std::string> series;  // titles of the plotted series, in legend order
  std::string data;                 // gnuplot data blocks ($name << EOD ... EOD)
  std::string plot;                 // labels, scales and the plot command (no terminal or output)
};

/// The first, second, middle and last iteration of `count` (fewer when there are fewer).
std::vector<int> default_plot_iterations(int count);

/// The iterations whose records the figures of a session of `count` iterations draw: the chosen
/// ones and the pressure trial (what a reader of the session's files must load).
std::vector<int> figure_iterations(const FigureRequest& request, int count);

/// The figures of `session`. Throws InputError for an iteration or trial the session lacks (or
/// whose record was not loaded), an unknown format or style, or a session with no iteration.
std::vector<Figure> session_figures(const Session& session, const FigureRequest& request);

/// The files `figures` become in `directory`, one per figure and format.
std::vector<std::filesystem::path> figure_files(const std::vector<Figure>& figures,
                                                const std::vector<std::string>& formats,
                                                const std::filesystem::path& directory);

/// One gnuplot script drawing every figure in every format of `style` into the folder it runs in.
std::string gnuplot_script(const std::vector<Figure>& figures, const std::vector<std::string>& formats,
                           const std::string& style = "screen");

/// Reads the paper's curve (`iteration,rms_deg` CSV, e.g. shared/data/paper_rms.csv). Throws InputError.
std::vector<std::pair<double, double>> read_paper_rms(const std::filesystem::path& path);

}  // namespace bellows
