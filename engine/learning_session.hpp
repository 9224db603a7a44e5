// Trials and learning between them, on simulated time: the headless counterpart of the real-time
// engine. Each trial settles at the trajectory's start with the PID alone, runs the trajectory
// with the current correction, and hands the record to the learning law for the next correction.
#pragma once

#include <utility>
#include <vector>

#include "engine/control_core.hpp"
#include "engine/device.hpp"
#include "engine/learning_law.hpp"
#include "engine/trajectory.hpp"
#include "engine/trial_record.hpp"

namespace bellows {

/// What one iteration achieved, as the run reports it.
struct IterationSummary {
  int iteration = 0;
  double rms_deg = 0.0;
  double max_abs_error_deg = 0.0;
  double max_abs_correction_bar = 0.0;  // of the correction applied in this trial
  int saturated_samples = 0;            // samples whose total input was clamped
};

IterationSummary summarize_trial(int iteration, const TrialRecord& record, const Eigen::VectorXd& correction_bar,
                                 double ambient_bar, double p_max_bar);

/// Runs `ticks` ticks of `core` on `device`, advancing device time by one tick after each.
void run_ticks_simulated(Device& device, ControlCore& core, long ticks, double tick_s);

class LearningSession {
 public:
  LearningSession(Device& device, ControlCore& core, LearningLaw& law, Trajectory trajectory,
                  const TimingParameters& timing, const ControllerParameters& controller);

  /// Settles, runs one trial with the current correction and records it. Returns its summary.
  IterationSummary run_trial();
  /// Replaces the correction by the law's update from the last trial.
  void learn();

  int iteration() const { return iteration_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const Eigen::VectorXd& correction_bar() const { return correction_; }
  void set_correction(const Eigen::VectorXd& correction_bar, int iteration);
  const TrialRecord& last_record() const { return record_; }
  const std::vector<IterationSummary>& history() const { return history_; }
  /// Restores the summaries of earlier trials, e.g. when a saved session is resumed.
  void set_history(std::vector<IterationSummary> history) { history_ = std::move(history); }

 private:
  Device& device_;
  ControlCore& core_;
  LearningLaw& law_;
  Trajectory trajectory_;
  TimingParameters timing_;
  ControllerParameters controller_;
  Eigen::VectorXd correction_;
  Eigen::VectorXd next_correction_;
  TrialRecord record_;
  int iteration_ = 0;
  std::vector<IterationSummary> history_;
};

}  // namespace bellows
