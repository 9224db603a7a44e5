#include "app/plot_console.hpp"

#include <cstdio>

#include "app/plot_command.hpp"
#include "engine/base/errors.hpp"
#include "sessions/file_access.hpp"
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

std::string write_console_figures(const std::string& session_location, int iterations, const fs::path& root,
                                  const QuietRead& quietly) {
  if (session_location.empty() || iterations <= 0) throw InputError("no saved trial to draw yet");
  if (root.empty()) throw InputError("no folder for figures (set HOME or XDG_DATA_HOME)");
  FigureRequest request;  // sessions plot's defaults
  Session session;
  PaperCurve paper;
  quietly([&] {
    paper = add_paper_curve(request, load_manifest(session_location).trajectory_name, {}, false);
    session = read_figure_session(session_location, request, iterations);
  });
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_iteration_%04d", iterations - 1);
  std::error_code error;
  fs::create_directories(root, error);
  if (error) throw_file_error("cannot create " + root.string(), error.value());
  const std::string stem = fs::path(session_location).filename().string() + suffix;
  fs::path directory = root / stem;
  for (int n = 2; fs::exists(directory, error); ++n)
    directory = root / (stem + "_" + std::to_string(n));  // drawn again
  write_session_figures(session, request, directory, false);
  const bool paper_missing = paper.file.empty() && !paper.note.empty();
  return directory.string() + (paper_missing ? "; " + paper.note : std::string());
}

}  // namespace bellows
