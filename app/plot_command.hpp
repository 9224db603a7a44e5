// `bellows sessions plot SESSION`: the figures of a saved session (app/plot_figures.hpp) drawn by
// gnuplot into a folder, with the generated script beside them. Also used by the console's
// figure key on the session it is running.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "app/plot_figures.hpp"
#include "sessions/session.hpp"

namespace bellows {

struct PlotOptions {
  std::string data_dir;            // empty: the default data directory
  std::string session;             // a directory, or a session name in the data directory
  std::string output;              // the folder; empty: <session name>_figures here
  std::vector<int> iterations;     // angle and u_ilc figures; empty: the default choice
  int trial = -1;                  // the pressures figure; -1: the last iteration
  std::vector<std::string> formats = {"png", "svg"};
  std::string paper;               // the paper's RMS curve (CSV); empty: the default one for the paper trajectory
  bool no_paper = false;
  bool force = false;              // replace existing figures
  bool json = false;
};

/// shared/data/paper_rms.csv beside the source tree this program was built from, if it is there.
std::filesystem::path default_paper_rms_path();

/// Draws the figures of `session` into `directory` (created if missing; its parent must exist):
/// figures.gp and one file per figure and format. Refuses (InputError) to replace an existing
/// file unless `force`, and to write inside the session's own directory. Returns the files.
std::vector<std::filesystem::path> write_session_figures(const Session& session, const FigureRequest& request,
                                                         const std::filesystem::path& directory, bool force);

int sessions_plot_command(const PlotOptions& options, std::ostream& out);

}  // namespace bellows
