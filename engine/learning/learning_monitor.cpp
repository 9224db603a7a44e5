#include "engine/learning/learning_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/base/errors.hpp"

namespace bellows {

LearningMonitor::LearningMonitor(double input_limit_bar, int samples, Options options, int joints)
    : limit_bar_(input_limit_bar), options_(options) {
  if (!(input_limit_bar > 0.0)) throw InputError("learning monitor: the input limit must be positive");
  if (joints < 1) throw InputError("learning monitor: an arm has at least one joint");
  joints_.resize(static_cast<std::size_t>(joints));
  for (JointState& joint : joints_) joint.previous_correction = Eigen::VectorXd::Zero(samples);
  if (joints > 1) windup_.joints.resize(static_cast<std::size_t>(joints));
}

LearningDiagnostics LearningMonitor::observe_joint(int iteration, const TrialSamples& samples, Eigen::Index n,
                                                   JointState& state, double& error_squared, double& change_squared) {
  const auto correction = samples.u_ilc_bar.head(n);
  const auto total = samples.u_total_bar.head(n);
  error_squared = samples.error_rad.tail(n).squaredNorm();
  change_squared = has_previous_ ? (correction - state.previous_correction).squaredNorm() : 0.0;

  LearningDiagnostics d;
  if (has_previous_) {
    if (state.previous_error_squared > 0.0)
      d.contraction = std::sqrt(error_squared) / std::sqrt(state.previous_error_squared);
    d.correction_change_bar = std::sqrt(change_squared / static_cast<double>(n));
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    const double excess = std::abs(total(k)) - limit_bar_;
    if (excess <= 0.0) continue;
    ++d.saturated_samples;
    d.clamped_excess_bar = std::max(d.clamped_excess_bar, excess);
    const double direction = total(k) > 0.0 ? 1.0 : -1.0;
    if (has_previous_ && excess > options_.excess_threshold_bar &&
        direction * (correction(k) - state.previous_correction(k)) > options_.growth_threshold_bar) {
      ++d.windup_samples;
    }
  }

  WindupSummary& w = state.windup;
  state.windup_streak = d.windup_samples > 0 ? state.windup_streak + 1 : 0;
  if (d.windup_samples > 0) ++w.iterations_with_windup;
  if (state.windup_streak >= options_.persistence && !w.detected) {
    w.detected = true;
    w.first_iteration = iteration - options_.persistence + 1;
  }
  w.max_clamped_excess_bar = std::max(w.max_clamped_excess_bar, d.clamped_excess_bar);
  w.last_clamped_excess_bar = d.clamped_excess_bar;

  state.previous_correction = correction;
  state.previous_error_squared = error_squared;
  return d;
}

const IterationDiagnostics& LearningMonitor::observe(int iteration, const TrialRecord& record) {
  const Eigen::Index n = record.learning_samples;
  if (n != joints_.front().previous_correction.size()) {
    throw InputError("learning monitor: trial has " + std::to_string(n) + " samples, expected " +
                     std::to_string(joints_.front().previous_correction.size()));
  }
  if (record.joint_count() != joints()) {
    throw InputError("learning monitor: trial has " + std::to_string(record.joint_count()) + " joints, expected " +
                     std::to_string(joints()));
  }
  IterationDiagnostics d;
  d.iteration = iteration;
  if (joints() == 1) {  // the arm is its joint, figure for figure
    double error_squared = 0.0, change_squared = 0.0;
    static_cast<LearningDiagnostics&>(d) =
        observe_joint(iteration, record.joint_samples(0), n, joints_.front(), error_squared, change_squared);
    windup_ = joints_.front().windup;
  } else {
    double error_squared = 0.0, change_squared = 0.0;
    bool any_windup = false;
    for (int j = 0; j < joints(); ++j) {
      double joint_error = 0.0, joint_change = 0.0;
      JointState& state = joints_[static_cast<std::size_t>(j)];
      d.joints.push_back(observe_joint(iteration, record.joint_samples(j), n, state, joint_error, joint_change));
      const LearningDiagnostics& joint = d.joints.back();
      error_squared += joint_error;
      change_squared += joint_change;
      d.saturated_samples += joint.saturated_samples;
      d.windup_samples += joint.windup_samples;
      d.clamped_excess_bar = std::max(d.clamped_excess_bar, joint.clamped_excess_bar);
      any_windup = any_windup || joint.windup_samples > 0;
      windup_.joints[static_cast<std::size_t>(j)] = state.windup;
      if (state.windup.detected &&
          (!windup_.first_iteration || *state.windup.first_iteration < *windup_.first_iteration))
        windup_.first_iteration = state.windup.first_iteration;
    }
    if (has_previous_) {
      if (previous_error_squared_ > 0.0) d.contraction = std::sqrt(error_squared) / std::sqrt(previous_error_squared_);
      d.correction_change_bar = std::sqrt(change_squared / static_cast<double>(n * joints()));
    }
    previous_error_squared_ = error_squared;
    windup_.detected = windup_.first_iteration.has_value();
    if (any_windup) ++windup_.iterations_with_windup;
    windup_.max_clamped_excess_bar = std::max(windup_.max_clamped_excess_bar, d.clamped_excess_bar);
    windup_.last_clamped_excess_bar = d.clamped_excess_bar;
  }
  has_previous_ = true;
  history_.push_back(std::move(d));
  return history_.back();
}

}  // namespace bellows
