#include "ui/trial_diagnostics.hpp"

#include <stdexcept>

namespace bellows::ui {

const IterationDiagnostics& TrialDiagnostics::observe_latest(const Experiment& experiment) {
  if (experiment.trials.empty()) throw std::logic_error("TrialDiagnostics: the experiment has no trial");
  const std::size_t seen = monitor_ ? monitor_->history().size() : 0;
  const bool same_experiment =
      monitor_ && trajectory_ == experiment.trajectory.get() && seen + 1 == experiment.trials.size();
  const bool was_detected = same_experiment && monitor_->windup().detected;
  std::vector<bool> joints_before;  // several joints: which had wound up before this trial
  if (!same_experiment) {
    monitor_.emplace(input_limit_bar_, experiment.samples(), experiment.joints());
    trajectory_ = experiment.trajectory.get();
    for (std::size_t i = 0; i + 1 < experiment.trials.size(); ++i) {
      if (!experiment.trials[i].in_memory()) continue;  // released: on disk only
      monitor_->observe(experiment.trials[i].iteration, experiment.trials[i].record);
    }
  }
  const bool detected_before = same_experiment ? was_detected : monitor_->windup().detected;
  for (const WindupSummary& joint : monitor_->windup().joints) joints_before.push_back(joint.detected);
  const Trial& latest = experiment.trials.back();
  const IterationDiagnostics& d = monitor_->observe(latest.iteration, latest.record);
  windup_just_detected_ = !detected_before && monitor_->windup().detected;
  windup_just_detected_joints_.clear();
  for (std::size_t j = 0; j < joints_before.size(); ++j) {
    if (!joints_before[j] && monitor_->windup().joints[j].detected)
      windup_just_detected_joints_.push_back(static_cast<int>(j));
  }
  return d;
}

}  // namespace bellows::ui
