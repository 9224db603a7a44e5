#include "sessions/session_writer.hpp"

#include <ctime>
#include <stdexcept>

#include "engine/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/session_directory.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace fs = std::filesystem;

SessionWriter::SessionWriter(fs::path directory, SessionManifest manifest, SessionLock lock)
    : directory_(std::move(directory)), manifest_(std::move(manifest)), lock_(std::move(lock)) {}

SessionWriter SessionWriter::create(const fs::path& data_dir, const std::string& name, SessionManifest header,
                                    const Trajectory& trajectory, const std::string& purpose) {
  if (!header.iterations.empty()) throw std::invalid_argument("SessionWriter::create: a new session has no iterations");
  header.schema_version = kSessionSchemaVersion;
  if (header.program_version.empty()) header.program_version = program_version();
  if (header.started_utc.empty()) header.started_utc = utc_now();
  header.trajectory_name = trajectory.name;
  header.trajectory_samples = trajectory.learning_samples();
  if (!name.empty()) {
    validate_session_name(name);
    header.name = name;
    fs::path directory = data_dir / name;
    SessionLock lock = create_session_directory(directory, header, trajectory, {}, purpose);
    return SessionWriter(std::move(directory), std::move(header), std::move(lock));
  }
  // Two runs started in the same second with the same trajectory: the second gets a suffix.
  const std::string stem = default_session_name(std::time(nullptr), trajectory.name);
  for (int attempt = 1;; ++attempt) {
    header.name = attempt == 1 ? stem : stem + "_" + std::to_string(attempt);
    fs::path directory = data_dir / header.name;
    std::error_code error;
    if (attempt < 100 && fs::exists(directory, error)) continue;
    SessionLock lock = create_session_directory(directory, header, trajectory, {}, purpose);
    return SessionWriter(std::move(directory), std::move(header), std::move(lock));
  }
}

SessionWriter SessionWriter::open(const fs::path& directory, const std::string& purpose, Session& loaded) {
  std::error_code error;
  if (!fs::is_directory(directory, error)) throw InputError("session " + directory.string() + ": no such directory");
  SessionLock lock(directory, purpose);  // before loading: nobody changes it under us
  loaded = load_session(directory);
  remove_temporary_files(directory);
  remove_temporary_files(directory / session_layout::kIterations);
  // Files of an iteration whose manifest update a crash prevented: not part of the session.
  for (int i = static_cast<int>(loaded.iterations.size());; ++i) {
    const bool samples = fs::remove(directory / session_layout::samples_file(i), error);
    const bool telemetry = fs::remove(directory / session_layout::telemetry_file(i), error);
    if (!samples && !telemetry) break;
  }
  remove_temporary_files(directory / session_layout::kFaults);
  for (int i = static_cast<int>(loaded.black_boxes.size());; ++i) {  // likewise for a black box
    if (!fs::remove(directory / session_layout::black_box_file(i), error)) break;
  }
  return SessionWriter(directory, loaded.manifest, std::move(lock));
}

void SessionWriter::save_iteration(const TrialRecord& record, const IterationSummary& summary,
                                   const Eigen::VectorXd& next_correction_bar, ResumeState resume) {
  if (summary.iteration != next_iteration()) {
    throw std::invalid_argument("SessionWriter::save_iteration: expected iteration " + std::to_string(next_iteration()) +
                                ", got " + std::to_string(summary.iteration));
  }
  if (!record.complete || record.learning_samples != manifest_.trajectory_samples ||
      next_correction_bar.size() != manifest_.trajectory_samples) {
    throw std::invalid_argument("SessionWriter::save_iteration: the record does not match the session's trajectory");
  }
  write_iteration_files(directory_, summary.iteration, record, next_correction_bar);
  sync_directory(directory_ / session_layout::kIterations);
  SessionManifest updated = manifest_;
  updated.iterations.push_back({summary, utc_now()});
  updated.resume = std::move(resume);
  write_manifest(directory_, updated);
  manifest_ = std::move(updated);  // only once it is on disk
}

void SessionWriter::update_next_correction(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar) {
  if (manifest_.iterations.empty()) {
    throw std::invalid_argument("SessionWriter::update_next_correction: no iteration saved yet");
  }
  if (!record.complete || record.learning_samples != manifest_.trajectory_samples ||
      next_correction_bar.size() != manifest_.trajectory_samples) {
    throw std::invalid_argument("SessionWriter::update_next_correction: the record does not match the session's trajectory");
  }
  write_file_atomic(directory_ / session_layout::samples_file(next_iteration() - 1),
                    format_samples_csv(record, next_correction_bar));
}

void SessionWriter::save_black_box(const std::string& fault, const std::vector<TickRecord>& ticks) {
  if (ticks.empty()) throw std::invalid_argument("SessionWriter::save_black_box: no ticks");
  const auto index = static_cast<int>(manifest_.black_boxes.size());
  write_black_box_file(directory_, index, ticks);
  SessionManifest updated = manifest_;
  updated.black_boxes.push_back({utc_now(), next_iteration(), fault, static_cast<int>(ticks.size())});
  write_manifest(directory_, updated);
  manifest_ = std::move(updated);
}

void SessionWriter::record_event(const std::string& kind, const std::string& message) {
  SessionManifest updated = manifest_;
  updated.events.push_back({utc_now(), next_iteration(), kind, message});
  write_manifest(directory_, updated);
  manifest_ = std::move(updated);
}

void SessionWriter::set_configuration(const Configuration& config) {
  SessionManifest updated = manifest_;
  updated.configuration = config;
  write_manifest(directory_, updated);
  manifest_ = std::move(updated);
}

}  // namespace bellows
