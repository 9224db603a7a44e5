// What learning does, observed trial by trial: the contraction of the error (||e_j|| / ||e_j-1||),
// how much the correction changed, how many samples the set-point clamp cut, and wind-up: the
// correction growing further into a clamp that already throws the excess away.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "engine/trial/trial_record.hpp"

namespace bellows {

struct IterationDiagnostics {
  int iteration = 0;
  std::optional<double> contraction;   // ||e_j|| / ||e_{j-1}||; empty for the first trial
  double correction_change_bar = 0.0;  // RMS of u_ilc,j - u_ilc,j-1
  int saturated_samples = 0;           // samples with |u_pid + u_ilc| beyond the limit
  double clamped_excess_bar = 0.0;     // largest |u_pid + u_ilc| - limit: what the clamp discarded
  int windup_samples = 0;              // samples clamped by more than the excess threshold whose correction
                                       // grew further into the clamp since the last trial
};

struct WindupSummary {
  bool detected = false;  // wind-up in `persistence` consecutive trials
  int iterations_with_windup = 0;
  std::optional<int> first_iteration;  // first trial of the first persistent stretch
  double max_clamped_excess_bar = 0.0;
  double last_clamped_excess_bar = 0.0;
};

class LearningMonitor {
 public:
  struct Options {
    double growth_threshold_bar = 1e-4;  // smaller growth of a clamped correction is not wind-up
    double excess_threshold_bar = 5e-3;  // a clamp that discards less is the feedback's jitter, not wind-up
    int persistence = 3;                 // consecutive trials with wind-up before it is reported
  };

  /// `input_limit_bar` = p_max - p0: the largest |u_pid + u_ilc| the set points pass.
  LearningMonitor(double input_limit_bar, int samples, Options options);
  LearningMonitor(double input_limit_bar, int samples) : LearningMonitor(input_limit_bar, samples, Options{}) {}

  /// Records a completed trial; its inputs and error come from the record.
  const IterationDiagnostics& observe(int iteration, const TrialRecord& record);

  const std::vector<IterationDiagnostics>& history() const { return history_; }
  const WindupSummary& windup() const { return windup_; }

 private:
  double limit_bar_;
  Options options_;
  Eigen::VectorXd previous_correction_;
  double previous_error_norm_ = 0.0;
  bool has_previous_ = false;
  int windup_streak_ = 0;
  std::vector<IterationDiagnostics> history_;
  WindupSummary windup_;
};

}  // namespace bellows
