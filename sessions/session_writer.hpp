// Saving a session as it happens: a run (or the console) creates or reopens a session, then saves
// after every completed iteration and records events (faults, operator actions) as they occur.
// Every save writes the iteration's files first and then the manifest that lists them, each
// atomically, so a crash at any moment leaves a session that loads with every iteration whose
// save returned. The writer holds the session's lock for its lifetime: one writer per session.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "sessions/file_access.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/session.hpp"
#include "sessions/session_lock.hpp"

namespace bellows {

class SessionWriter {
 public:
  /// Creates a session in `data_dir` named `name` (empty: from the start time and the trajectory)
  /// from `header` (device, configuration, trajectory name, first events; no iterations).
  /// Throws InputError when the name is taken or the directory cannot be written.
  static SessionWriter create(const std::filesystem::path& data_dir, const std::string& name, SessionManifest header,
                              const Trajectory& trajectory, const std::string& purpose);
  /// Reopens a session to continue it: takes its lock, loads and checks everything into `loaded`
  /// (digests included), and removes leftovers of an interrupted write (temporary files, files of
  /// an iteration the manifest does not list). Throws InputError (busy, bad session, a link or a
  /// special file where a file or folder of the session should be).
  static SessionWriter open(const std::filesystem::path& directory, const std::string& purpose, Session& loaded);

  const std::filesystem::path& directory() const { return directory_.path(); }
  const SessionManifest& manifest() const { return manifest_; }

  /// Autosave after iteration `summary.iteration` (which must be the next one) completed, with
  /// the correction learned from it and the state to continue from.
  void save_iteration(const TrialRecord& record, const IterationSummary& summary,
                      const Eigen::VectorXd& next_correction_bar, ResumeState resume);
  /// The same for a J-joint session: `record` of J joints, `next_corrections_bar` N x J (one
  /// column per joint). A one-joint session takes N x 1 alike.
  void save_iteration(const TrialRecord& record, const IterationSummary& summary,
                      const Eigen::MatrixXd& next_corrections_bar, ResumeState resume);
  /// The correction learned from the last saved iteration changed (learning ran after the save, or
  /// the operator chose another): rewrites that iteration's samples file (`record` is its record)
  /// atomically, so the learned correction is on disk before the next trial starts.
  void update_next_correction(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar);
  void update_next_correction(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar);
  /// Keeps a fault's black box (`ticks` oldest first, ending with the fault tick): writes its file,
  /// then lists it in the manifest. Throws std::invalid_argument when `ticks` is empty.
  void save_black_box(const std::string& fault, const std::vector<TickRecord>& ticks);
  /// Appends an event and saves the manifest at once.
  void record_event(const std::string& kind, const std::string& message);
  /// Replaces the configuration (e.g. the operator changed gains); saved at once.
  void set_configuration(const Configuration& config);

 private:
  SessionWriter(DirectoryHandle directory, SessionManifest manifest, SessionLock lock);
  int next_iteration() const { return static_cast<int>(manifest_.iterations.size()); }
  /// Throws std::invalid_argument unless `record` and the corrections fit the session (`what` names the caller).
  void check_fits(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar, const char* what) const;

  DirectoryHandle directory_;  // every file is written relative to it, never through a link
  DirectoryHandle iterations_;
  /// Writes manifest_ (changed in place); if that fails, `undo` puts the change back and it throws.
  void rewrite_manifest(const std::function<void()>& undo);

  SessionManifest manifest_;
  ManifestTextCache manifest_text_;  // what of manifest_'s lists is serialized already
  SessionLock lock_;
};

}  // namespace bellows
