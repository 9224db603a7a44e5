// What learning does, observed trial by trial: the contraction of the error (||e_j|| / ||e_j-1||),
// how much the correction changed, how many samples the set-point clamp cut, and wind-up: the
// correction growing further into a clamp that already throws the excess away. Every joint is
// watched on its own (its correction against its own clamp); the arm's figures gather the joints'
// (with one joint they are that joint's, as they always were).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "engine/trial/trial_record.hpp"

namespace bellows {

/// One trial's diagnostics of one joint, or of the arm (every joint together).
struct LearningDiagnostics {
  std::optional<double> contraction;   // ||e_j|| / ||e_{j-1}||; empty for the first trial
  double correction_change_bar = 0.0;  // RMS of u_ilc,j - u_ilc,j-1
  int saturated_samples = 0;           // samples with |u_pid + u_ilc| beyond the limit
  double clamped_excess_bar = 0.0;     // largest |u_pid + u_ilc| - limit: what the clamp discarded
  int windup_samples = 0;              // samples clamped by more than the excess threshold whose correction
                                       // grew further into the clamp since the last trial
};

/// The arm's diagnostics (norms over every joint and sample, counts summed, the largest excess) and,
/// with several joints, each joint's (`joints` is empty for one joint).
struct IterationDiagnostics : LearningDiagnostics {
  int iteration = 0;
  std::vector<LearningDiagnostics> joints;
};

/// Wind-up of one joint. The arm's: any joint's (detected when one joint's persisted, from the
/// earliest such joint's first iteration; trials counted when any joint wound up; the largest excess),
/// with each joint's in `joints` when there are several (empty for one joint).
struct WindupSummary {
  bool detected = false;  // wind-up in `persistence` consecutive trials
  int iterations_with_windup = 0;
  std::optional<int> first_iteration;  // first trial of the first persistent stretch
  double max_clamped_excess_bar = 0.0;
  double last_clamped_excess_bar = 0.0;
  std::vector<WindupSummary> joints;
};

class LearningMonitor {
 public:
  struct Options {
    double growth_threshold_bar = 1e-4;  // smaller growth of a clamped correction is not wind-up
    double excess_threshold_bar = 5e-3;  // a clamp that discards less is the feedback's jitter, not wind-up
    int persistence = 3;                 // consecutive trials with wind-up before it is reported
  };

  /// `input_limit_bar` = p_max - p0: the largest |u_pid + u_ilc| the set points pass, for every joint.
  LearningMonitor(double input_limit_bar, int samples, Options options, int joints = 1);
  LearningMonitor(double input_limit_bar, int samples, int joints = 1)
      : LearningMonitor(input_limit_bar, samples, Options{}, joints) {}

  /// Records a completed trial of every joint; its inputs and error come from the record.
  const IterationDiagnostics& observe(int iteration, const TrialRecord& record);

  const std::vector<IterationDiagnostics>& history() const { return history_; }
  const WindupSummary& windup() const { return windup_; }
  int joints() const { return static_cast<int>(joints_.size()); }

 private:
  struct JointState {  // what one joint's next trial is compared with
    Eigen::VectorXd previous_correction;
    double previous_error_squared = 0.0;
    int windup_streak = 0;
    WindupSummary windup;
  };
  LearningDiagnostics observe_joint(int iteration, const TrialSamples& samples, Eigen::Index n, JointState& state,
                                    double& error_squared, double& change_squared);

  double limit_bar_;
  Options options_;
  std::vector<JointState> joints_;
  double previous_error_squared_ = 0.0;  // every joint's
  bool has_previous_ = false;
  std::vector<IterationDiagnostics> history_;
  WindupSummary windup_;
};

}  // namespace bellows
