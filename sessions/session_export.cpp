#include "sessions/session_export.hpp"

#include <string>

#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/file_access.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/iteration_files.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

/// Stacks tables of the same columns under a leading `key` column holding each table's index.
std::string stacked(const std::string& key, const std::vector<std::string>& tables) {
  std::string out;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    const std::string& table = tables[i];
    const std::size_t header_end = table.find('\n');
    if (i == 0) out += key + "," + table.substr(0, header_end + 1);
    const std::string prefix = std::to_string(i) + ",";
    std::size_t line = header_end + 1;
    while (line < table.size()) {
      const std::size_t end = table.find('\n', line);
      out += prefix;
      out.append(table, line, end - line + 1);
      line = end + 1;
    }
  }
  return out;
}

fs::path sibling(const fs::path& path, const std::string& suffix) {
  return path.parent_path() / (path.stem().string() + suffix + path.extension().string());
}

}  // namespace

void check_export_targets(const Session& session, const std::vector<fs::path>& paths, const std::string& extension,
                          bool force) {
  const fs::path& first = paths.front();
  if (first.extension() != extension) {
    throw InputError("the output " + first.string() + " must end in " + extension + " for this format" +
                     (first.extension().empty() ? "" : " (not " + first.extension().string() + ")"));
  }
  const fs::path folder = first.parent_path().empty() ? fs::path(".") : first.parent_path();
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    throw InputError("cannot write " + first.string() + ": the folder " + folder.string() +
                     (fs::exists(folder, error) ? " is not a directory" : " does not exist"));
  }
  for (const fs::path& path : paths) {
    if (!session.directory.empty() && is_inside(path, session.directory)) {
      throw InputError("will not write " + path.string() + " inside the session " + session.directory.string() +
                       " it exports (choose another --output)");
    }
    if (!force && fs::symlink_status(path, error).type() != fs::file_type::not_found) {
      throw InputError(path.string() + " exists already (--force replaces it)");
    }
  }
}

std::vector<fs::path> csv_export_paths(const Session& session, const fs::path& samples_path) {
  std::vector<fs::path> paths = {samples_path, sibling(samples_path, "_telemetry"), sibling(samples_path, "_summary")};
  if (!session.black_boxes.empty()) paths.push_back(sibling(samples_path, "_blackbox"));
  return paths;
}

std::vector<fs::path> export_session_csv(const Session& session, const fs::path& samples_path, bool force) {
  std::vector<fs::path> paths = csv_export_paths(session, samples_path);  // not const: returned by move
  check_export_targets(session, paths, ".csv", force);
  std::vector<std::string> samples, telemetry;
  for (const IterationData& data : session.iterations) {
    samples.push_back(format_samples_csv(data.record, data.next_corrections_bar()));
    telemetry.push_back(format_telemetry_csv(data.record));
  }
  if (samples.empty()) {  // the header alone, of every joint
    TrialRecord empty;    // no rows: every joint's columns empty
    empty.joints.resize(static_cast<std::size_t>(session.manifest.joints));
    samples.push_back(format_samples_csv(empty, Eigen::MatrixXd{}));
    telemetry.push_back(format_telemetry_csv(empty));
  }
  std::string summary = "iteration,rms_deg,max_abs_error_deg,max_abs_correction_bar,saturated_samples\n";
  for (const IterationEntry& entry : session.manifest.iterations) {
    const nlohmann::json row = {entry.summary.iteration, entry.summary.rms_deg, entry.summary.max_abs_error_deg,
                                entry.summary.max_abs_correction_bar, entry.summary.saturated_samples};
    std::string line = row.dump();  // "[0,12.3,...]": numbers in shortest round-trip form
    summary += line.substr(1, line.size() - 2) + "\n";
  }
  const Replace replace = force ? Replace::kAllowed : Replace::kRefused;
  write_file_atomic(paths[0], stacked("iteration", samples), DirectorySync::kNow, replace);
  write_file_atomic(paths[1], stacked("iteration", telemetry), DirectorySync::kNow, replace);
  write_file_atomic(paths[2], summary, DirectorySync::kNow, replace);
  if (!session.black_boxes.empty()) {
    std::vector<std::string> boxes;
    for (const std::vector<TickRecord>& ticks : session.black_boxes) boxes.push_back(format_black_box_csv(ticks));
    write_file_atomic(paths[3], stacked("black_box", boxes), DirectorySync::kNow, replace);
  }
  return paths;
}

}  // namespace bellows
