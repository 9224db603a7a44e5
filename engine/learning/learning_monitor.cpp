#include "engine/learning/learning_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/base/errors.hpp"

namespace bellows {

LearningMonitor::LearningMonitor(double input_limit_bar, int samples, Options options)
    : limit_bar_(input_limit_bar), options_(options), previous_correction_(Eigen::VectorXd::Zero(samples)) {
  if (!(input_limit_bar > 0.0)) throw InputError("learning monitor: the input limit must be positive");
}

const IterationDiagnostics& LearningMonitor::observe(int iteration, const TrialRecord& record) {
  const Eigen::Index n = record.learning_samples;
  if (n != previous_correction_.size()) {
    throw InputError("learning monitor: trial has " + std::to_string(n) + " samples, expected " +
                     std::to_string(previous_correction_.size()));
  }
  const auto correction = record.joint_samples(0).u_ilc_bar.head(n);
  const auto total = record.joint_samples(0).u_total_bar.head(n);
  const double error_norm = record.joint_samples(0).error_rad.tail(n).norm();

  IterationDiagnostics d;
  d.iteration = iteration;
  if (has_previous_) {
    if (previous_error_norm_ > 0.0) d.contraction = error_norm / previous_error_norm_;
    d.correction_change_bar = std::sqrt((correction - previous_correction_).squaredNorm() / static_cast<double>(n));
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    const double excess = std::abs(total(k)) - limit_bar_;
    if (excess <= 0.0) continue;
    ++d.saturated_samples;
    d.clamped_excess_bar = std::max(d.clamped_excess_bar, excess);
    const double direction = total(k) > 0.0 ? 1.0 : -1.0;
    if (has_previous_ && excess > options_.excess_threshold_bar &&
        direction * (correction(k) - previous_correction_(k)) > options_.growth_threshold_bar) {
      ++d.windup_samples;
    }
  }

  windup_streak_ = d.windup_samples > 0 ? windup_streak_ + 1 : 0;
  if (d.windup_samples > 0) ++windup_.iterations_with_windup;
  if (windup_streak_ >= options_.persistence && !windup_.detected) {
    windup_.detected = true;
    windup_.first_iteration = iteration - options_.persistence + 1;
  }
  windup_.max_clamped_excess_bar = std::max(windup_.max_clamped_excess_bar, d.clamped_excess_bar);
  windup_.last_clamped_excess_bar = d.clamped_excess_bar;

  previous_correction_ = correction;
  previous_error_norm_ = error_norm;
  has_previous_ = true;
  history_.push_back(d);
  return history_.back();
}

}  // namespace bellows
