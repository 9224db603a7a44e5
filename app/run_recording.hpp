// The session side of `bellows run`: a new session saved as the run goes (unless --no-save), or a
// saved session continued with --resume. Each completed iteration is on disk before its progress
// line is printed; faults are recorded as events before the run gives up.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "app/run_command.hpp"
#include "devices/simulated_arm.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/operator/learning_session.hpp"
#include "sessions/session_writer.hpp"

namespace bellows {

// A simulated run's exact state between trials, for a resume that continues bit for bit: what
// `bellows run` saves after each iteration and `run --resume` puts back, and what `bellows console
// --clock sim` saves with each trial and puts back when it arms a reopened session. One capture and
// one restore for both.

/// The controllers' state, the simulated arm's (one joint: `arm`, several: `chain`; the other null)
/// and the clock's ticks, read on the engine's thread between trials (its state is quiet then).
/// Without a clock or an arm (the wall clock, a rig) nothing is captured: such a session resumes
/// with its correction and freshly armed controllers.
ResumeState capture_resume_state(EngineCore& core, const SimulatedArm* arm, const SimulatedArmChain* chain,
                                 const SimulatedClock* clock);

/// Whether `manifest` holds what restore_resume_state() needs: an exact resume state, after at
/// least one iteration.
bool can_restore_exactly(const SessionManifest& manifest);

/// Before the engine's first tick: the arm (or chain), the clock and the engine (ARMED, with its
/// controllers' state) where the session stopped. `source` prefixes errors ("session DIR:
/// manifest.json"). Throws InputError for a state that does not fit the arm.
void restore_resume_state(const SessionManifest& manifest, SimulatedArm* arm, SimulatedArmChain* chain,
                          EngineCore& core, SimulatedClock* clock, const std::string& source);

class RunRecording {
 public:
  /// With --resume: takes the session's lock and loads it (InputError if busy or bad).
  explicit RunRecording(const RunOptions& options);

  bool resuming() const { return resuming_; }
  /// The session being continued (valid when resuming()).
  const Session& resumed() const { return resumed_; }
  /// The simulated arm's seed the resumed session was started with.
  std::uint64_t resumed_seed() const;
  /// Trials to run for `--iterations K` (docs/iterations.md): K + 1 from scratch (iteration 0 is
  /// feedback only), K when continuing after completed iterations.
  int trials(int iterations) const;

  /// A fresh run: creates the session (nothing with --no-save). `model_source`: where config's
  /// [model] came from (app/learning_model). `first_correction` (null: feedback only) says where the
  /// first trial's correction came from.
  void start(const Configuration& config, const Trajectory& trajectory, const std::string& device, std::uint64_t seed,
             int iterations, const nlohmann::ordered_json& device_info, const std::string& model_source,
             const nlohmann::ordered_json& first_correction = nullptr);
  /// A resumed run, before the engine's first tick: puts the arm, the engine (armed, with its
  /// controllers' state), the clock and the learning where the session stopped, and records the
  /// resumption. Nothing for a fresh run. `clock` is null on the wall clock; `arm` is null for a rig
  /// over LCM (whose sessions are not resumed) and for the J-joint arm (use the SimulatedArmChain
  /// overload below to restore it exactly). Every joint's correction goes to the learning;
  /// InputError when the session's joints are not the learning's.
  void restore(SimulatedArm* arm, EngineCore& core, SimulatedClock* clock, LearningSession& learning);
  /// After a trial and the learning from it. On the wall clock (`clock` null) the loop thread owns
  /// the arm and the controllers, so their state is not captured: such a session resumes with the
  /// correction and freshly armed controllers. `arm` is null for a rig over LCM. Every joint's
  /// correction is saved (N x J); the arm's state only with `arm` (the SimulatedArmChain overload
  /// below saves the J-joint arm's).
  void save(const LearningSession& learning, const IterationSummary& summary, const SimulatedArm* arm, EngineCore& core,
            const SimulatedClock* clock);
  /// A resumed run of J joints (the simulated arm chain of `[arm] preset`), before the engine's
  /// first tick: puts the chain, the engine (armed, every joint's controllers) and the clock where
  /// the session stopped, and records the resumption; nothing for a fresh run. InputError when the
  /// session's joints are not the arm's. The learning is the caller's to set, from
  /// resumed_corrections_bar() and resumed_history(). `clock` null: the wall clock; `arm` null: a
  /// rig over LCM (whose state is not restored).
  void restore(SimulatedArmChain* arm, EngineCore& core, SimulatedClock* clock);
  /// The same, and the learning continues with every joint's saved correction and the history.
  void restore(SimulatedArmChain* arm, EngineCore& core, SimulatedClock* clock, LearningSession& learning);
  /// Every joint's correction learned from the resumed session's last iteration, N x J (one column
  /// per joint); 0 x 0 when it completed none (or for a fresh run).
  Eigen::MatrixXd resumed_corrections_bar() const;
  /// The resumed session's iterations, for the learning's history (empty for a fresh run).
  std::vector<IterationSummary> resumed_history() const;
  /// After a trial of a J-joint run and the learning from it: `record` is the trial's (J joints),
  /// `corrections_bar` the correction learned from it for the next trial (N x J). On the wall clock
  /// (`clock` null) the state of the chain and the controllers is not captured, as for one joint.
  void save(const TrialRecord& record, const Eigen::MatrixXd& corrections_bar, const IterationSummary& summary,
            const SimulatedArmChain* arm, EngineCore& core, const SimulatedClock* clock);
  /// The same with the learning's last record and every joint's correction (N x J).
  void save(const LearningSession& learning, const IterationSummary& summary, const SimulatedArmChain* arm,
            EngineCore& core, const SimulatedClock* clock);
  /// Records a fault; never throws (the fault itself is what the caller reports).
  void fault(const std::string& what) noexcept;
  /// Records an engine fault and keeps its black box (the engine's frozen record, if any).
  void fault(const std::string& what, const EngineCore& core) noexcept;
  /// Records an event of `kind` (e.g. "dropped-events"); never throws, like fault().
  void note(const std::string& kind, const std::string& message) noexcept;
  void finish(int trials_run);

  /// The session directory; empty with --no-save.
  std::filesystem::path directory() const;

 private:
  /// The clock and the controllers where the session stopped (`arm_time_s`: the arm's own time,
  /// for a first-format session without the clock's ticks).
  void record_resumption();
  /// Throws InputError unless the resumed session has `joints` joints (`arm` says which arm).
  void require_joints(int joints, const std::string& arm) const;

  const RunOptions& options_;
  bool resuming_ = false;
  Session resumed_;
  std::optional<SessionWriter> writer_;
};

}  // namespace bellows
