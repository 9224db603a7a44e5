// Learning diagnostics for the console's experiment: the engine's LearningMonitor (contraction,
// change of the correction, saturated samples, wind-up; every joint on its own) fed with the
// experiment's trials in order.
// The experiment can change under it (a trajectory chosen, a session opened); it then starts over
// and replays the trials the experiment holds.
#pragma once

#include <optional>
#include <vector>

#include "engine/learning/learning_monitor.hpp"
#include "ui/experiment.hpp"

namespace bellows::ui {

class TrialDiagnostics {
 public:
  /// `input_limit_bar` = p_max - p0, the largest input the set points pass.
  explicit TrialDiagnostics(double input_limit_bar) : input_limit_bar_(input_limit_bar) {}

  /// The diagnostics of the experiment's newest trial (which must exist).
  const IterationDiagnostics& observe_latest(const Experiment& experiment);
  /// True once, for the trial at which wind-up was first reported (any joint's).
  bool windup_just_detected() const { return windup_just_detected_; }
  /// Several joints: the joints (0-based) whose wind-up was first reported at the newest trial.
  const std::vector<int>& windup_just_detected_joints() const { return windup_just_detected_joints_; }
  const WindupSummary& windup() const { return monitor_->windup(); }

 private:
  double input_limit_bar_;
  std::optional<LearningMonitor> monitor_;
  const Trajectory* trajectory_ = nullptr;  // the experiment the monitor has seen
  bool windup_just_detected_ = false;
  std::vector<int> windup_just_detected_joints_;
};

}  // namespace bellows::ui
