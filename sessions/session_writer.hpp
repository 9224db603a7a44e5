// Saving a session as it happens: a run (or the console) creates or reopens a session, then saves
// after every completed iteration and records events (faults, operator actions) as they occur.
// Every save writes new files under new names first and then the manifest that names them: the
// manifest's rename is the single commit point, so a crash at any moment leaves a session that
// loads with every iteration whose save returned, and a file already committed is never rewritten. The writer holds the
// session's lock for its lifetime: one writer per session.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

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
  /// The LCM logs of runs killed while they wrote one (`run --lcm-log` into the session): open()
  /// keeps each under a free name of its own (telemetry-N.lcmlog, its events up to the kill), not as
  /// an unfinished write it removes. Their names, for the operator.
  const std::vector<std::string>& kept_logs() const { return kept_logs_; }
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
  /// the operator chose another): writes that iteration's samples file (`record` is its record)
  /// again as its next revision and commits the manifest naming it, so the learned correction is
  /// on disk before the next trial starts and the file committed before is never rewritten.
  void update_next_correction(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar);
  void update_next_correction(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar);
  /// Keeps a fault's black box (`ticks` oldest first, ending with the fault tick): writes its file,
  /// then lists it in the manifest. Throws std::invalid_argument when `ticks` is empty.
  void save_black_box(const std::string& fault, const std::vector<TickRecord>& ticks);
  /// Appends an event and saves the manifest at once.
  void record_event(const std::string& kind, const std::string& message);
  /// Replaces the configuration (e.g. the operator changed gains); saved at once.
  void set_configuration(const Configuration& config);

  /// Several of the calls above as one save: while a Batch is open they write their files (under
  /// new names only) but not the manifest; commit() writes the manifest once, and that rename
  /// commits all of them. A batch destroyed uncommitted (or whose commit throws) undoes them all:
  /// the writer is as before it, and a retry writes them again.
  class Batch {
   public:
    explicit Batch(SessionWriter& writer);
    ~Batch();
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;
    void commit();

   private:
    SessionWriter& writer_;
  };

 private:
  SessionWriter(DirectoryHandle directory, SessionManifest manifest, SessionLock lock);
  int next_iteration() const { return static_cast<int>(manifest_.iterations.size()); }
  /// Throws std::invalid_argument unless `record` and the corrections fit the session (`what` names the caller).
  void check_fits(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar, const char* what) const;

  DirectoryHandle directory_;  // every file is written relative to it, never through a link
  std::vector<std::string> kept_logs_;
  DirectoryHandle iterations_;
  /// Writes manifest_ (changed in place) unless a batch is open; if that fails, `undo` (and those
  /// of the batch) put the changes back and it throws.
  void rewrite_manifest(std::function<void()> undo);
  void commit_manifest();
  void roll_back();

  std::vector<std::function<void()>> undo_;  // of the changes not committed yet, oldest first
  std::vector<std::string> after_commit_;    // iterations/ files a commit supersedes (removed after it)
  bool batch_open_ = false;

  SessionManifest manifest_;
  ManifestTextCache manifest_text_;  // what of manifest_'s lists is serialized already
  SessionLock lock_;
};

}  // namespace bellows
