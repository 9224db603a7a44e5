// What the operator has done with one trajectory: every trial in order (its correction, record and
// summary) and the correction the next trial will apply. Iterations are numbered in the order the
// trials ran; going back to an earlier correction or repeating a trial adds a new iteration whose
// origin says where its correction came from, so the history is never rewritten.
#pragma once

#include <any>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "engine/operator/learning_session.hpp"
#include "engine/config/joint_transfer.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/rt/engine_messages.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows::ui {

struct Trial {
  int iteration = 0;
  Eigen::MatrixXd correction_bar;         // u_ilc(0..N-1) the trial applied, one column per joint (N x J);
                                          // empty once released
  TrialRecord record;                     // empty once released (saved, and older than the kept window)
  IterationSummary summary;               // rms_deg over every joint and sample, joint_rms_deg per joint
  std::string origin;                     // "feedback only", "learned from 3", "correction of 2", "loaded"
  std::optional<ModelCheck> model_check;  // the law's model against this trial (laws that learn
                                          // their model); the session's model-refit events hold it
  std::any end_state;                     // --clock sim: the engine's and arm's state at its end (saved for an
                                          // exact resume; the app's type, opaque here); empty: none

  /// False once its record and correction were released: they are in the session on disk only.
  bool in_memory() const { return record.learning_samples > 0; }
};

/// A fault's black box, kept with the experiment so that saving stores it in the session.
struct FaultRecord {
  std::string fault;              // fault_name(), e.g. "overpressure"
  int iteration = 0;              // the iteration running or next when it fired
  std::vector<TickRecord> ticks;  // oldest first, ending with the fault tick; empty once released
};

/// A source of a learning transfer, as the session that started from it records it.
struct TransferSourceNote {
  std::string name;       // the saved session's name, or the trajectory taught in this console
  std::string directory;  // where it is saved ("" if it never was)
  std::string trajectory;
  int trials = 0;
  double last_rms_deg = 0.0;
};

/// Where the first correction came from when a learning transfer gave it (issue 13): the session
/// records it as its manifest's `first_correction`, like `bellows run --transfer-from`.
struct FirstCorrection {
  std::vector<TransferSourceNote> sources;
  JointTransferResult result;  // every joint's
};

struct Experiment {
  /// Full records (tick-rate telemetry, hundreds of kB each) kept in memory for the newest trials
  /// only: a lab day of thousands of iterations must not grow without bound; the session on disk
  /// holds every one. Summaries (RMS history) stay for all.
  static constexpr int kTrialsKeptInMemory = 8;

  std::shared_ptr<const Trajectory> trajectory;
  std::vector<Trial> trials;
  Eigen::MatrixXd next_correction_bar;  // what the next trial applies, N x J
  std::string next_origin = "feedback only";
  LearnedWith next_learned_with;    // the law and weights that learned it (empty: not learned)
  bool next_tried = false;          // a trial already ran with it: a step learns first
  int saved_trials = 0;             // trials already in the saved session
  bool settings_changed = false;    // gains or weights changed since the last save
  bool next_unsaved = false;        // the next correction changed since the last trial was saved
  std::uint64_t next_revision = 0;  // bumped by every set_next()
  std::string session_location;     // where it was saved or opened from; empty if never
  std::size_t saved_events = 0;     // log entries (EventLog::total()) already in that session
  std::vector<FaultRecord> faults;  // black boxes, in the order the faults fired
  int saved_faults = 0;             // black boxes already in the saved session
  /// Set when the operator takes a transfer (T) before iteration 0; null: feedback only.
  std::shared_ptr<const FirstCorrection> first_correction;

  /// A fresh experiment on `trajectory`: zero correction, no trials.
  static Experiment start(std::shared_ptr<const Trajectory> trajectory);

  int samples() const { return trajectory ? trajectory->learning_samples() : 0; }
  int joints() const { return trajectory ? trajectory->joints() : 1; }
  int next_iteration() const { return static_cast<int>(trials.size()); }
  bool unsaved() const {
    return static_cast<int>(trials.size()) > saved_trials || static_cast<int>(faults.size()) > saved_faults ||
           settings_changed || (next_unsaved && !trials.empty());
  }
  /// Releases the records and corrections of saved trials older than the kept window, and the
  /// ticks of saved black boxes (the session on disk has them).
  void release_saved_history();
  /// What is not on disk (what a save would add), as a sentence naming the trials: "iteration 4
  /// is not saved.", "2 iterations (3-4), 1 fault's black box and changed settings are not saved.",
  /// "the correction learned from iteration 4 is not saved."; empty when nothing is unsaved. The
  /// quit confirmation, the failed save's message and the exit report say this.
  std::string unsaved_sentence() const;
  /// Appends a finished trial (numbered next_iteration()); its correction was the next one.
  void add_trial(Trial trial);
  /// The correction the next trial applies, from `origin`.
  void set_next(Eigen::MatrixXd correction_bar, std::string origin, LearnedWith learned_with = {});
  /// RMS per trial, in order (over every joint).
  std::vector<double> rms_history_deg() const;
  /// Joint `joint`'s RMS per trial, in order (0-based; with one joint the same as rms_history_deg();
  /// NaN where a trial's per-joint RMS is not known).
  std::vector<double> joint_rms_history_deg(int joint) const;
  /// Lowest RMS so far; negative without trials.
  double best_rms_deg() const;
  /// True when each of the last `count` trials had a higher RMS than the one before it.
  bool rms_rising(int count) const;
};

}  // namespace bellows::ui
