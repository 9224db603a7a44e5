// Trials and learning between them, driven through the engine like any operator would: the trial
// runner (engine/operator/trial_runner) arms it, starts a trial (the engine settles at the
// trajectory's start, then runs it with the current correction) and waits for the record; the
// learning law makes the next correction from it. The same code runs on a simulated clock
// (headless, deterministic) and on the real-time loop (wall time).
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/rt/engine_driver.hpp"
#include "engine/base/errors.hpp"
#include "engine/learning/joint_learning.hpp"
#include "engine/base/joints.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"
#include "engine/operator/trial_runner.hpp"

namespace bellows {

/// The law and weights that learned the correction a trial applied: a study changes them between
/// trials, and each saved iteration says which it was (the manifest's `learned_with`). An empty law:
/// not learned (iteration 0, a transferred correction) or not recorded (sessions saved before).
struct LearnedWith {
  std::string law;
  std::vector<std::pair<std::string, double>> weights;  // the [ilc] keys the law reads, table order
  bool known() const { return !law.empty(); }
  bool operator==(const LearnedWith&) const = default;
};

/// What one iteration achieved, as the run reports it. With several joints the figures are over
/// every joint (and `joint_rms_deg` has each joint's); with one they are its own.
struct IterationSummary {
  int iteration = 0;
  double rms_deg = 0.0;  // over every joint and sample 1..N
  double max_abs_error_deg = 0.0;
  double max_abs_correction_bar = 0.0;               // of the correction applied in this trial
  int saturated_samples = 0;                         // samples (of any joint) whose total input was clamped
  JointVector joint_rms_deg = JointVector::Zero(1);  // per joint, samples 1..N
  int held_samples = 0;           // samples without a fresh reading (TrialRecord::held): error 0, not learned from
  LearnedWith learned_with = {};  // what learned the correction it applied (callers fill it in)
};

/// `correction_bar`: N values (one joint) or N x J, one column per joint.
IterationSummary summarize_trial(int iteration, const TrialRecord& record,
                                 const Eigen::Ref<const Eigen::MatrixXd>& correction_bar, double ambient_bar,
                                 double p_max_bar);

class LearningSession {
 public:
  /// One joint, learning with `law`.
  LearningSession(EngineDriver& driver, LearningLaw& law, Trajectory trajectory, const TimingParameters& timing,
                  const ControllerParameters& controller);
  /// The trajectory's J joints, learning with `learning` (built for J joints and N samples).
  LearningSession(EngineDriver& driver, JointLearning& learning, Trajectory trajectory, const TimingParameters& timing,
                  const ControllerParameters& controller);

  /// Arms if needed, runs one trial with the current correction and records it. Throws EngineFault
  /// if the engine faults or refuses; the trial is then not counted.
  IterationSummary run_trial();
  /// Replaces the correction by the law's update from the last trial.
  void learn();

  int iteration() const { return iteration_; }
  const Trajectory& trajectory() const { return trajectory_; }
  int joints() const { return trajectory_.joints(); }
  /// The correction the next trial applies: joint 1's (all of it for one joint), and every joint's
  /// (N x J, a column per joint).
  Eigen::VectorXd correction_bar() const { return corrections_.col(0); }
  const Eigen::MatrixXd& joint_corrections_bar() const { return corrections_; }
  /// Replaces the correction: N values (one joint) or N x J.
  void set_correction(const Eigen::Ref<const Eigen::MatrixXd>& correction_bar, int iteration);
  const TrialRecord& last_record() const { return record_; }
  const std::vector<IterationSummary>& history() const { return history_; }
  void set_history(std::vector<IterationSummary> history) { history_ = std::move(history); }
  JointLearning& learning() { return learning_; }
  /// While waiting for the engine, a set flag (a signal arrived) stops the engine at once (vents)
  /// and makes run_trial() throw EngineFault(kEmergencyStop).
  void set_stop_flag(const std::atomic<bool>* stop) { stop_ = stop; }

 private:
  LearningSession(EngineDriver& driver, std::unique_ptr<SingleJointLearning> single, Trajectory trajectory,
                  const TimingParameters& timing, const ControllerParameters& controller);

  EngineDriver& driver_;
  std::unique_ptr<SingleJointLearning> single_;  // the one-joint law's adapter, when given one
  JointLearning& learning_;
  Trajectory trajectory_;
  TimingParameters timing_;
  ControllerParameters controller_;
  Eigen::MatrixXd corrections_;  // N x J
  Eigen::MatrixXd next_corrections_;
  Eigen::MatrixXd feedback_bar_;  // N x J, the last trial's u_pid, for the law's input context
  TrialRecord record_;
  int iteration_ = 0;
  TrialRunner runner_;
  std::vector<IterationSummary> history_;
  const std::atomic<bool>* stop_ = nullptr;
};

}  // namespace bellows
