#include "sessions/session_writer.hpp"

#include <ctime>
#include <functional>
#include <optional>
#include <utility>
#include <stdexcept>

#include "engine/base/errors.hpp"
#include "sessions/file_access.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/session_directory.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace fs = std::filesystem;

SessionWriter::SessionWriter(DirectoryHandle directory, SessionManifest manifest, SessionLock lock)
    : directory_(std::move(directory)),
      iterations_(directory_.make_subdirectory(session_layout::kIterations)),
      manifest_(std::move(manifest)),
      lock_(std::move(lock)) {}

SessionWriter SessionWriter::create(const fs::path& data_dir, const std::string& name, SessionManifest header,
                                    const Trajectory& trajectory, const std::string& purpose) {
  if (!header.iterations.empty()) throw std::invalid_argument("SessionWriter::create: a new session has no iterations");
  header.schema_version = kSessionSchemaVersion;
  if (header.program_version.empty()) header.program_version = program_version();
  if (header.started_utc.empty()) header.started_utc = utc_now();
  header.trajectory_name = trajectory.name;
  header.trajectory_samples = trajectory.learning_samples();
  header.joints = trajectory.joints();
  if (!name.empty()) {
    validate_session_name(name);
    header.name = name;
    CreatedSession created = create_session_directory(data_dir / name, header, trajectory, {}, purpose);
    return SessionWriter(std::move(created.directory), std::move(created.manifest), std::move(created.lock));
  }
  // Two runs started in the same second with the same trajectory: the second gets a suffix, also
  // when both looked before either created its directory (the creation itself is exclusive).
  constexpr int kMostSuffixes = 100;
  const std::string stem = default_session_name(std::time(nullptr), trajectory.name);
  for (int attempt = 1;; ++attempt) {
    header.name = attempt == 1 ? stem : stem + "_" + std::to_string(attempt);
    fs::path directory = data_dir / header.name;
    try {
      CreatedSession created = create_session_directory(directory, header, trajectory, {}, purpose);
      return SessionWriter(std::move(created.directory), std::move(created.manifest), std::move(created.lock));
    } catch (const SessionExistsError&) {
      if (attempt >= kMostSuffixes) throw;
    }
  }
}

SessionWriter SessionWriter::open(const fs::path& directory, const std::string& purpose, Session& loaded) {
  DirectoryHandle session = open_session_directory(directory);
  SessionLock lock(session, purpose);  // before loading: nobody changes it under us
  loaded = load_session(session);
  remove_temporary_files(session);
  SessionManifest manifest = loaded.manifest;
  // What it writes is this bellows' format (what an older version lacked has its default now).
  manifest.schema_version = kSessionSchemaVersion;
  SessionWriter writer(std::move(session), std::move(manifest), std::move(lock));
  // Files of an iteration whose manifest update a crash prevented: not part of the session.
  const auto name_in_folder = [](const std::string& relative) { return session_layout::folder_and_name(relative).second; };
  remove_temporary_files(writer.iterations_);
  for (int i = static_cast<int>(loaded.iterations.size());; ++i) {
    const bool samples = remove_file_at(writer.iterations_, name_in_folder(session_layout::samples_file(i)));
    const bool telemetry = remove_file_at(writer.iterations_, name_in_folder(session_layout::telemetry_file(i)));
    if (!samples && !telemetry) break;
  }
  if (const std::optional<DirectoryHandle> faults = writer.directory_.subdirectory(session_layout::kFaults)) {
    remove_temporary_files(*faults);
    for (int i = static_cast<int>(loaded.black_boxes.size());; ++i) {  // likewise for a black box
      if (!remove_file_at(*faults, name_in_folder(session_layout::black_box_file(i)))) break;
    }
  }
  return writer;
}

void SessionWriter::check_fits(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar,
                               const char* what) const {
  if (!record.complete || record.learning_samples != manifest_.trajectory_samples ||
      next_corrections_bar.rows() != manifest_.trajectory_samples) {
    throw std::invalid_argument(std::string("SessionWriter::") + what + ": the record does not match the session's trajectory");
  }
  if (record.joints() != manifest_.joints || next_corrections_bar.cols() != manifest_.joints) {
    throw std::invalid_argument(std::string("SessionWriter::") + what + ": the session has " +
                                std::to_string(manifest_.joints) + " joints, the record " + std::to_string(record.joints()) +
                                " and the correction " + std::to_string(next_corrections_bar.cols()));
  }
}

void SessionWriter::save_iteration(const TrialRecord& record, const IterationSummary& summary,
                                   const Eigen::VectorXd& next_correction_bar, ResumeState resume) {
  save_iteration(record, summary, Eigen::MatrixXd(next_correction_bar), std::move(resume));
}

void SessionWriter::save_iteration(const TrialRecord& record, const IterationSummary& summary,
                                   const Eigen::MatrixXd& next_corrections_bar, ResumeState resume) {
  if (summary.iteration != next_iteration()) {
    throw std::invalid_argument("SessionWriter::save_iteration: expected iteration " + std::to_string(next_iteration()) +
                                ", got " + std::to_string(summary.iteration));
  }
  check_fits(record, next_corrections_bar, "save_iteration");
  const IterationDigests digests = write_iteration_files(iterations_, summary.iteration, record, next_corrections_bar);
  sync(iterations_);
  std::optional<ResumeState> previous_resume = std::move(manifest_.resume);
  manifest_.iterations.push_back({summary, utc_now(), digests.samples_sha256, digests.telemetry_sha256});
  manifest_.resume = std::move(resume);
  rewrite_manifest([&] {  // not on disk: not in the session
    manifest_.iterations.pop_back();
    manifest_.resume = std::move(previous_resume);
  });
}

void SessionWriter::rewrite_manifest(const std::function<void()>& undo) {
  // The manifest is changed in place and the change undone if the write fails: copying it for each
  // write would copy every iteration's entry after every iteration.
  const std::string previous_update = manifest_.updated_utc;
  try {
    write_manifest(directory_, manifest_, &manifest_text_);
  } catch (...) {
    undo();
    manifest_.updated_utc = previous_update;
    throw;
  }
}

void SessionWriter::update_next_correction(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar) {
  update_next_correction(record, Eigen::MatrixXd(next_correction_bar));
}

void SessionWriter::update_next_correction(const TrialRecord& record, const Eigen::MatrixXd& next_correction_bar) {
  if (manifest_.iterations.empty()) {
    throw std::invalid_argument("SessionWriter::update_next_correction: no iteration saved yet");
  }
  check_fits(record, next_correction_bar, "update_next_correction");
  // The rewritten samples file gets its new digest in the manifest, or a resume would refuse it.
  const int iteration = next_iteration() - 1;
  const std::string contents = format_samples_csv(record, next_correction_bar);
  write_file_atomic_at(iterations_, session_layout::folder_and_name(session_layout::samples_file(iteration)).second, contents);
  std::string previous_digest = std::exchange(manifest_.iterations.back().samples_sha256, sha256_hex(contents));
  rewrite_manifest([&] { manifest_.iterations.back().samples_sha256 = std::move(previous_digest); });
}

void SessionWriter::save_black_box(const std::string& fault, const std::vector<TickRecord>& ticks) {
  if (ticks.empty()) throw std::invalid_argument("SessionWriter::save_black_box: no ticks");
  const auto index = static_cast<int>(manifest_.black_boxes.size());
  const std::string digest = write_black_box_file(directory_, index, ticks);
  manifest_.black_boxes.push_back({utc_now(), next_iteration(), fault, static_cast<int>(ticks.size()), digest});
  rewrite_manifest([&] { manifest_.black_boxes.pop_back(); });
}

void SessionWriter::record_event(const std::string& kind, const std::string& message) {
  manifest_.events.push_back({utc_now(), next_iteration(), kind, message});
  rewrite_manifest([&] { manifest_.events.pop_back(); });
}

void SessionWriter::set_configuration(const Configuration& config) {
  Configuration previous = std::exchange(manifest_.configuration, config);
  rewrite_manifest([&] { manifest_.configuration = std::move(previous); });
}

}  // namespace bellows
