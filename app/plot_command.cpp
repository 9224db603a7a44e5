#include "app/plot_command.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/plot_gnuplot.hpp"
#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/file_access.hpp"
#include "sessions/session_store.hpp"

#ifndef BELLOWS_PAPER_RMS_CSV
#define BELLOWS_PAPER_RMS_CSV ""
#endif

namespace bellows {
namespace fs = std::filesystem;
namespace {

constexpr const char* kScriptName = "figures.gp";

}  // namespace

fs::path default_paper_rms_path() { return fs::path(BELLOWS_PAPER_RMS_CSV).lexically_normal(); }

PaperCurve add_paper_curve(FigureRequest& request, const std::string& trajectory_name, const std::string& paper,
                           bool no_paper) {
  if (no_paper && !paper.empty()) throw InputError("--paper and --no-paper exclude each other");
  if (no_paper) return {};
  fs::path file = paper;
  if (file.empty()) {
    if (trajectory_name != "paper") return {};  // the paper's curve is of its own trajectory
    file = default_paper_rms_path();
    std::error_code error;
    if (file.empty() || !fs::is_regular_file(file, error)) {
      return {{},
              "paper's RMS curve: not overlaid, " +
                  (file.empty() ? std::string("no default file") : file.string() + " is not there") +
                  " (--paper FILE gives one)"};
    }
  }
  request.paper_rms = read_paper_rms(file);
  return {file, "paper's RMS curve from " + file.string()};
}

Session read_figure_session(const fs::path& directory, const FigureRequest& request, int iterations) {
  int count = static_cast<int>(load_manifest(directory).iterations.size());
  if (iterations >= 0) count = std::min(count, iterations);
  std::vector<int> wanted = figure_iterations(request, count);
  Session session = load_session_iterations(directory, wanted);
  if (iterations >= 0 && static_cast<int>(session.iterations.size()) > count) {
    // Saved after the key was pressed: not in these figures (their folder is named after `count`).
    session.iterations.resize(static_cast<std::size_t>(count));
    session.manifest.iterations.resize(static_cast<std::size_t>(count));
  }
  return session;
}

std::vector<fs::path> write_session_figures(const Session& session, const FigureRequest& request,
                                            const fs::path& directory, bool force) {
  const std::vector<Figure> figures = session_figures(session, request);  // checks the request first
  if (!session.directory.empty() && is_inside(directory, session.directory)) {
    throw InputError("will not write figures inside the session " + session.directory.string() +
                     " (choose another --output)");
  }
  std::error_code error;
  const fs::path parent = directory.parent_path().empty() ? fs::path(".") : directory.parent_path();
  if (!fs::is_directory(parent, error)) {
    throw InputError("cannot write figures into " + directory.string() + ": the folder " + parent.string() +
                     " does not exist");
  }
  if (fs::exists(directory, error) && !fs::is_directory(directory, error)) {
    throw InputError("cannot write figures into " + directory.string() + ": it is not a directory");
  }
  std::vector<fs::path> files = figure_files(figures, request.formats, directory);
  files.insert(files.begin(), directory / kScriptName);
  for (const fs::path& file : files) {
    if (!force && fs::symlink_status(file, error).type() != fs::file_type::not_found) {
      throw InputError(file.string() + " exists already (--force replaces it)");
    }
  }
  fs::create_directory(directory, error);
  if (error) throw_file_error("cannot create " + directory.string(), error.value());
  const DirectoryHandle folder = DirectoryHandle::open(directory);
  const Replace replace = force ? Replace::kAllowed : Replace::kRefused;
  write_file_atomic_at(folder, kScriptName, gnuplot_script(figures, request.formats, request.style),
                       DirectorySync::kNow, replace);
  // gnuplot opens its outputs by name (truncating, following links): it draws into a folder made
  // for it alone, and each figure leaves it by the safe writer's last steps (fsync, a rename that
  // replaces only with --force, fsync of the folder), so a crash leaves whole figures or none.
  const PrivateTemporaryDirectory drawing(folder, kScriptName);
  run_gnuplot(directory / kScriptName, drawing.path());
  for (std::size_t f = 1; f < files.size(); ++f) {
    const std::string name = files[f].filename().string();
    const std::optional<FileDescriptor> drawn = open_regular_file_at(drawing.handle(), name, O_RDONLY);
    struct stat info {};
    if (!drawn || ::fstat(drawn->get(), &info) != 0 || info.st_size == 0)
      throw InputError("gnuplot wrote no " + files[f].string());
    if (::fsync(drawn->get()) != 0) throw_file_error("cannot flush " + files[f].string(), errno);
  }
  for (std::size_t f = 1; f < files.size(); ++f) {
    const std::string name = files[f].filename().string();
    publish_file_at(drawing.handle(), name, folder, name, replace);
  }
  sync(folder);
  return files;
}

int sessions_plot_command(const PlotOptions& options, std::ostream& out) {
  fs::path data_dir = options.data_dir.empty() ? fs::path() : given_data_dir(options.data_dir);  // a typo: refused
  try {
    if (data_dir.empty()) data_dir = default_data_dir();
  } catch (const InputError&) {
    // Then only a path can name the session; resolve_session_dir() says so if it is not one.
  }
  const fs::path session_dir = resolve_session_dir(options.session, data_dir);
  FigureRequest request;
  request.iterations = options.iterations;
  request.pressure_trial = options.trial;
  request.formats = options.formats;
  request.style = options.style;
  const PaperCurve paper =
      add_paper_curve(request, load_manifest(session_dir).trajectory_name, options.paper, options.no_paper);
  const Session session = read_figure_session(session_dir, request);
  const fs::path directory =
      options.output.empty() ? fs::path(session.directory.filename().string() + "_figures") : fs::path(options.output);
  const std::vector<fs::path> files = write_session_figures(session, request, directory, options.force);
  if (options.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const fs::path& file : files) list.push_back(file.string());
    out << nlohmann::json{{"directory", directory.string()},
                          {"style", request.style},
                          {"paper", paper.file.string()},
                          {"paper_note", paper.note},
                          {"files", list}}
               .dump()
        << std::endl;
    return 0;
  }
  for (const fs::path& file : files) out << "wrote " << file.string() << "\n";
  if (!paper.note.empty()) out << paper.note << "\n";
  out << std::flush;
  return 0;
}

}  // namespace bellows
