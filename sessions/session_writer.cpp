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
#include "sessions/uncommitted_files.hpp"

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
  if (header.program_version.empty()) header.program_version = program_version();
  if (header.started_utc.empty()) header.started_utc = utc_now();
  header.trajectory_name = trajectory.name;
  header.trajectory_samples = trajectory.learning_samples();
  header.joints = trajectory.joints();
  header.schema_version = session_schema_version_for(header.joints);
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
  std::vector<std::string> kept = keep_interrupted_logs(session);
  remove_temporary_files(session);
  SessionManifest manifest = loaded.manifest;
  // What it writes is this bellows' format (what an older version lacked has its default now).
  manifest.schema_version = session_schema_version_for(manifest.joints);
  SessionWriter writer(std::move(session), std::move(manifest), std::move(lock));
  writer.kept_logs_ = std::move(kept);
  // What an interrupted save wrote but never committed, and files a committed revision superseded:
  // not part of the session.
  remove_uncommitted_files(writer.directory_, find_uncommitted_files(writer.directory_, writer.manifest_));
  return writer;
}

void SessionWriter::check_fits(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar,
                               const char* what) const {
  if (!record.complete || record.learning_samples != manifest_.trajectory_samples ||
      next_corrections_bar.rows() != manifest_.trajectory_samples) {
    throw std::invalid_argument(std::string("SessionWriter::") + what +
                                ": the record does not match the session's trajectory");
  }
  if (record.joint_count() != manifest_.joints || next_corrections_bar.cols() != manifest_.joints) {
    throw std::invalid_argument(std::string("SessionWriter::") + what + ": the session has " +
                                std::to_string(manifest_.joints) + " joints, the record " +
                                std::to_string(record.joint_count()) + " and the correction " +
                                std::to_string(next_corrections_bar.cols()));
  }
}

void SessionWriter::save_iteration(const TrialRecord& record, const IterationSummary& summary,
                                   const Eigen::VectorXd& next_correction_bar, ResumeState resume) {
  save_iteration(record, summary, Eigen::MatrixXd(next_correction_bar), std::move(resume));
}

void SessionWriter::save_iteration(const TrialRecord& record, const IterationSummary& summary,
                                   const Eigen::MatrixXd& next_corrections_bar, ResumeState resume) {
  if (summary.iteration != next_iteration()) {
    throw std::invalid_argument("SessionWriter::save_iteration: expected iteration " +
                                std::to_string(next_iteration()) + ", got " + std::to_string(summary.iteration));
  }
  check_fits(record, next_corrections_bar, "save_iteration");
  const IterationDigests digests = write_iteration_files(iterations_, summary.iteration, record, next_corrections_bar);
  sync(iterations_);
  std::optional<ResumeState> previous_resume = std::move(manifest_.resume);
  manifest_.iterations.push_back({summary, utc_now(), digests.samples_sha256, digests.telemetry_sha256});
  manifest_.resume = std::move(resume);
  rewrite_manifest([this, previous_resume = std::move(previous_resume)]() mutable {  // not on disk: not in the session
    manifest_.iterations.pop_back();
    manifest_.resume = std::move(previous_resume);
  });
}

void SessionWriter::rewrite_manifest(std::function<void()> undo) {
  undo_.push_back(std::move(undo));
  if (batch_open_) return;  // Batch::commit() writes it once for the whole batch
  commit_manifest();
}

void SessionWriter::commit_manifest() {
  // The manifest is changed in place and the changes undone if the write fails: copying it for
  // each write would copy every iteration's entry after every iteration.
  const std::string previous_update = manifest_.updated_utc;
  try {
    write_manifest(directory_, manifest_, &manifest_text_);
  } catch (...) {
    manifest_.updated_utc = previous_update;
    roll_back();
    throw;
  }
  undo_.clear();
  // Committed: the files the manifest no longer names go (a crash before leaves them superseded,
  // which the next writer removes; a failure here loses nothing).
  for (const std::string& name : after_commit_) {
    try {
      remove_file_at(iterations_, name);
    } catch (const InputError&) {
    }
  }
  after_commit_.clear();
}

void SessionWriter::roll_back() {
  for (auto undo = undo_.rbegin(); undo != undo_.rend(); ++undo) (*undo)();
  undo_.clear();
  after_commit_.clear();
  manifest_text_ = {};  // it may hold entries just undone
}

SessionWriter::Batch::Batch(SessionWriter& writer) : writer_(writer) {
  if (writer_.batch_open_) throw std::logic_error("SessionWriter::Batch: a batch is open already");
  writer_.batch_open_ = true;
}

SessionWriter::Batch::~Batch() {
  if (!writer_.batch_open_) return;
  writer_.batch_open_ = false;
  writer_.roll_back();  // not committed: nothing of it is in the session
}

void SessionWriter::Batch::commit() {
  writer_.batch_open_ = false;
  if (!writer_.undo_.empty()) writer_.commit_manifest();
}

void SessionWriter::update_next_correction(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar) {
  update_next_correction(record, Eigen::MatrixXd(next_correction_bar));
}

void SessionWriter::update_next_correction(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar) {
  if (manifest_.iterations.empty()) {
    throw std::invalid_argument("SessionWriter::update_next_correction: no iteration saved yet");
  }
  check_fits(record, next_corrections_bar, "update_next_correction");
  // The committed samples file is never rewritten: the new correction goes into the next revision
  // of it, and the manifest naming that revision (with its digest) is the commit. The old file is
  // removed once the manifest no longer names it.
  const int iteration = next_iteration() - 1;
  IterationEntry& entry = manifest_.iterations.back();
  const std::string contents = format_samples_csv(record, next_corrections_bar);
  const int revision = entry.samples_revision + 1;
  const auto name_of = [&](int r) {
    return session_layout::folder_and_name(session_layout::samples_file(iteration, r)).second;
  };
  write_file_atomic_at(iterations_, name_of(revision), contents);
  std::string previous_digest = std::exchange(entry.samples_sha256, sha256_hex(contents));
  entry.samples_revision = revision;
  after_commit_.push_back(name_of(revision - 1));
  rewrite_manifest([this, previous_digest = std::move(previous_digest)]() mutable {
    manifest_.iterations.back().samples_sha256 = std::move(previous_digest);
    --manifest_.iterations.back().samples_revision;
    after_commit_.pop_back();
  });
}

void SessionWriter::save_black_box(const std::string& fault, const std::vector<TickRecord>& ticks) {
  if (ticks.empty()) throw std::invalid_argument("SessionWriter::save_black_box: no ticks");
  const auto index = static_cast<int>(manifest_.black_boxes.size());
  const std::string digest = write_black_box_file(directory_, index, ticks);
  manifest_.black_boxes.push_back({utc_now(), next_iteration(), fault, static_cast<int>(ticks.size()), digest});
  rewrite_manifest([this] { manifest_.black_boxes.pop_back(); });
}

void SessionWriter::record_event(const std::string& kind, const std::string& message) {
  manifest_.events.push_back({utc_now(), next_iteration(), kind, message});
  rewrite_manifest([this] { manifest_.events.pop_back(); });
}

void SessionWriter::set_configuration(const Configuration& config) {
  Configuration previous = std::exchange(manifest_.configuration, config);
  rewrite_manifest([this, previous = std::move(previous)]() mutable { manifest_.configuration = std::move(previous); });
}

}  // namespace bellows
