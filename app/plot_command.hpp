// `bellows sessions plot SESSION`: the figures of a saved session (app/plot_figures.hpp) drawn by
// gnuplot into a folder, with the generated script beside them. The console's figure key draws the
// same figures the same way, from the same files (app/plot_console.hpp): read_figure_session, then
// write_session_figures.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "app/plot_figures.hpp"
#include "sessions/session.hpp"

namespace bellows {

struct PlotOptions {
  std::string data_dir;         // empty: the default data directory
  std::string session;          // a directory, or a session name in the data directory
  std::string output;           // the folder; empty: <session name>_figures here
  std::vector<int> iterations;  // angle, error and u_ilc figures; empty: the default choice
  int trial = -1;               // the pressures figure; -1: the last iteration
  std::vector<std::string> formats = {"png", "svg"};
  std::string style = "screen";  // screen, paper-column, paper-wide (app/plot_style.hpp)
  std::string paper;             // the paper's RMS curve (CSV); empty: the default one for the paper trajectory
  bool no_paper = false;
  bool force = false;  // replace existing figures
  bool json = false;
};

/// shared/data/paper_rms.csv beside the source tree this program was built from (where it would
/// be, whether or not it is there).
std::filesystem::path default_paper_rms_path();

/// The paper's RMS curve a figure request overlays: the file (empty: none) and the sentence the
/// output shows about it ("paper's RMS curve from FILE", or why there is none; empty for a
/// trajectory the paper did not run, or --no-paper).
struct PaperCurve {
  std::filesystem::path file;
  std::string note;
};

/// Puts the paper's RMS curve into `request`: from `paper` when given, none when `no_paper`, else
/// the default one for a session of the paper trajectory when it is there. Throws InputError for a
/// file that cannot be read.
PaperCurve add_paper_curve(FigureRequest& request, const std::string& trajectory_name, const std::string& paper,
                           bool no_paper);

/// What the figures need of the saved session in `directory`, read from its files: the manifest
/// (every iteration's RMS), the trajectory and the records of figure_iterations() only, so a long
/// session costs no more than a short one. `iterations` >= 0: its first `iterations` only (what a
/// console had when its key was pressed). Throws InputError.
Session read_figure_session(const std::filesystem::path& directory, const FigureRequest& request, int iterations = -1);

/// Draws the figures of `session` into `directory` (created if missing; its parent must exist):
/// figures.gp and one file per figure and format. Refuses (InputError) to replace an existing
/// file unless `force`, and to write inside the session's own directory. Returns the files.
std::vector<std::filesystem::path> write_session_figures(const Session& session, const FigureRequest& request,
                                                         const std::filesystem::path& directory, bool force);

int sessions_plot_command(const PlotOptions& options, std::ostream& out);

}  // namespace bellows
