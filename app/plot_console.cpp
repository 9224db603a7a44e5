#include "app/plot_console.hpp"

#include <cstdio>

#include "app/plot_command.hpp"
#include "engine/base/errors.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace fs = std::filesystem;

fs::path default_figures_root() {
  try {
    return default_data_dir().parent_path() / "figures";
  } catch (const InputError&) {
    return {};
  }
}

std::string write_console_figures(const ui::SessionSnapshot& snapshot, const fs::path& root) {
  const ui::Experiment& e = snapshot.experiment;
  if (!e.trajectory || e.trials.empty()) throw InputError("no trial to draw yet");
  if (root.empty()) throw InputError("no folder for figures (set HOME or XDG_DATA_HOME)");
  // The plotting code reads a Session: build one in memory from the console's trials.
  Session session;
  session.manifest.name = e.session_location.empty() ? "console" : fs::path(e.session_location).filename().string();
  session.manifest.trajectory_name = e.trajectory->name;
  session.manifest.trajectory_samples = e.samples();
  session.manifest.configuration = snapshot.config;
  session.trajectory = *e.trajectory;
  for (std::size_t i = 0; i < e.trials.size(); ++i) {
    const ui::Trial& trial = e.trials[i];
    IterationSummary summary = trial.summary;
    summary.iteration = static_cast<int>(i);
    session.manifest.iterations.push_back({summary, {}});
    const Eigen::MatrixXd& next = i + 1 < e.trials.size() ? e.trials[i + 1].correction_bar : e.next_correction_bar;
    session.iterations.push_back({trial.record, next.col(0)});  // the figures draw joint 1
  }
  FigureRequest request;
  if (session.manifest.trajectory_name == "paper") {
    const fs::path paper = default_paper_rms_path();
    if (!paper.empty()) request.paper_rms = read_paper_rms(paper);
  }
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_iteration_%04zu", e.trials.size() - 1);
  std::error_code error;
  fs::create_directories(root, error);
  if (error) throw InputError("cannot create " + root.string() + ": " + error.message());
  fs::path directory = root / (session.manifest.name + suffix);
  for (int n = 2; fs::exists(directory, error); ++n) {  // the same trials drawn again: a new folder
    directory = root / (session.manifest.name + suffix + "_" + std::to_string(n));
  }
  write_session_figures(session, request, directory, false);
  return directory.string();
}

}  // namespace bellows
