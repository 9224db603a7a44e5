#include "engine/config/learning_transfer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "engine/learning/learning_transfer_fit.hpp"

namespace bellows {
namespace {

constexpr TransferMethod kMethods[] = {TransferMethod::kReferenceFir, TransferMethod::kBasis,
                                       TransferMethod::kInverseFir};

Eigen::VectorXd normalized(const Eigen::VectorXd& angle_rad) { return angle_rad / std::numbers::pi; }

double rms_deg(const Eigen::VectorXd& normalized_error) {
  if (normalized_error.size() == 0) return 0.0;
  return 180.0 * std::sqrt(normalized_error.squaredNorm() / static_cast<double>(normalized_error.size()));
}

double input_limit_bar(const ControllerParameters& c) { return c.p_max_bar - c.gas.ambient_bar; }

/// What the PID contributes while it tracks `r` well (e ~ 0): k_ff r - k_d r_dot, u(0..N-1).
Eigen::VectorXd expected_feedback_bar(const Eigen::VectorXd& r, const ControllerParameters& c, double sample_time_s) {
  const Eigen::Index n = r.size() - 1;
  Eigen::VectorXd u(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    const double rate = t > 0 ? (r(t) - r(t - 1)) / sample_time_s : 0.0;
    u(t) = c.k_ff * r(t) - c.k_d_s * rate;
  }
  return u;
}

/// What reached the arm: the total input after the set-point clamp.
Eigen::VectorXd applied_total_bar(const TransferTrial& trial, const ControllerParameters& c) {
  const double limit = input_limit_bar(c);
  return (trial.u_pid_bar + trial.u_ilc_bar).cwiseMax(-limit).cwiseMin(limit);
}

Eigen::VectorXd trial_error(const Trajectory& trajectory, const TransferTrial& trial) {
  const Eigen::Index n = trajectory.learning_samples();
  return normalized(trajectory.joint(0).tail(n) - trial.angle_rad.tail(n));
}

/// "'arm2'" (the arm's name), or "one joint".
std::string arm_words(const ArmParameters& arm) {
  if (!arm.has_chain()) return "one joint";
  std::string words = "'";
  words += arm.name();
  words += "'";
  return words;
}

}  // namespace

std::string rig_profile_mismatch(const std::string& source_profile, const std::string& target_profile) {
  if (target_profile.empty() || source_profile == target_profile) return {};
  return "it was recorded with the rig profile '" + printable(source_profile) + "', this run uses '" +
         printable(target_profile) + "'";
}

std::string transfer_mismatch(const Configuration& source, const std::string& source_device,
                              const Configuration& target, const std::string& target_device) {
  const double theirs = source.timing.sample_s(), ours = target.timing.sample_s();
  char line[200];
  if (std::abs(theirs - ours) > 1e-9 * ours) {
    std::snprintf(line, sizeof line, "it was sampled every %g s, this run every %g s", theirs, ours);
    return line;
  }
  if (source_device != target_device) {
    return "it was recorded on the device '" + source_device + "', this run drives '" + target_device + "'";
  }
  if (source.arm.name() != target.arm.name()) {
    std::string why = "it was recorded on another arm (";
    why += arm_words(source.arm);
    why += " there, ";
    why += arm_words(target.arm);
    why += " here)";
    return why;
  }
  if (target_device != "sim") return {};
  Configuration a = source, b = target;  // the bindings hand out pointers into a mutable configuration
  for (const ParameterBinding& binding : parameter_bindings()) {
    const bool arm_key = binding.section.rfind("arm", 0) == 0;  // [arm], [arm_jointK]: the chain's links
    if ((binding.section != "plant" && !arm_key) || binding.key.rfind("fault", 0) == 0 ||
        binding.key.rfind("spike", 0) == 0)
      continue;
    const bool differs = binding.real ? std::abs(*binding.real(a) - *binding.real(b)) >
                                            1e-9 * std::max(std::abs(*binding.real(a)), std::abs(*binding.real(b)))
                                      : binding.integer && *binding.integer(a) != *binding.integer(b);
    if (differs && binding.real) {
      std::snprintf(line, sizeof line, "it was recorded on another simulated arm ([%s] %s is %g there, %g here)",
                    binding.section.c_str(), binding.key.c_str(), *binding.real(a), *binding.real(b));
      return line;
    }
    if (differs)
      return "it was recorded on another simulated arm ([" + binding.section + "] " + binding.key + " differs)";
  }
  return {};
}

std::string transfer_method_name(TransferMethod method) {
  switch (method) {
    case TransferMethod::kAuto:
      return "auto";
    case TransferMethod::kReferenceFir:
      return "reference-fir";
    case TransferMethod::kBasis:
      return "basis";
    case TransferMethod::kInverseFir:
      return "inverse-fir";
  }
  return "auto";
}

std::string transfer_method_names() {
  std::string names;
  for (std::size_t i = 0; i < kTransferMethods.size(); ++i) {
    names += (i == 0                             ? ""
              : i + 1 == kTransferMethods.size() ? " or "
                                                 : ", ") +
             transfer_method_name(kTransferMethods[i]);
  }
  return names;
}

TransferMethod parse_transfer_method(const std::string& name) {
  for (const TransferMethod m : kTransferMethods) {
    if (transfer_method_name(m) == name) return m;
  }
  throw InputError("transfer method must be " + transfer_method_names() + ", not '" + name + "'");
}

LearningTransfer::LearningTransfer(TransferSettings settings) : settings_(std::move(settings)) {}

namespace {

RegressorShape shape_of(TransferMethod method, const TransferSettings& s) {
  RegressorShape shape;
  shape.lowpass_time_constants_s = s.slow_time_constants_s;
  shape.nonlinear_leads = s.nonlinear_leads;
  if (method == TransferMethod::kBasis) {
    shape.derivatives = 4;
  } else {
    shape.taps_behind = s.taps_behind;
    shape.taps_ahead = s.taps_ahead;
  }
  return shape;
}

}  // namespace

void LearningTransfer::setup(std::vector<TransferSource> sources, const ControllerParameters& target_controller,
                             double sample_time_s) {
  info_ = {};
  sources_.clear();
  for (TransferSource& source : sources) {
    if (std::abs(source.trajectory.sample_time_s - sample_time_s) > 1e-9 * sample_time_s) {
      throw InputError("session '" + source.name + "' was sampled every " +
                       std::to_string(source.trajectory.sample_time_s) + " s, not every " +
                       std::to_string(sample_time_s) + " s: it cannot teach this run");
    }
    const Eigen::Index n = source.trajectory.learning_samples();
    std::erase_if(source.trials, [n](const TransferTrial& t) {
      return t.u_ilc_bar.size() != n || t.u_pid_bar.size() != n || t.angle_rad.size() != n + 1 ||
             !t.angle_rad.allFinite() || !t.u_ilc_bar.allFinite() || !t.u_pid_bar.allFinite();
    });
    if (source.trials.empty()) throw InputError("session '" + source.name + "' has no complete trial to learn from");
    sources_.push_back(std::move(source));
  }
  if (sources_.empty()) throw InputError("transfer needs at least one session");
  target_controller_ = target_controller;
  sample_time_s_ = sample_time_s;
  const int groups = static_cast<int>(sources_.size());

  // G: consecutive trials of a source differ in their corrections; e_{j-1} - e_j = G (u_j - u_{j-1}).
  const int g_params = settings_.closed_loop_taps + static_cast<int>(settings_.slow_time_constants_s.size());
  RidgeAccumulator closed_loop(g_params, groups);
  for (int g = 0; g < groups; ++g) {
    const TransferSource& s = sources_[static_cast<std::size_t>(g)];
    for (std::size_t j = 1; j < s.trials.size(); ++j) {
      const Eigen::VectorXd du = s.trials[j].u_ilc_bar - s.trials[j - 1].u_ilc_bar;
      const Eigen::VectorXd de = trial_error(s.trajectory, s.trials[j - 1]) - trial_error(s.trajectory, s.trials[j]);
      closed_loop.add(
          g, build_causal_regressors(du, settings_.closed_loop_taps, settings_.slow_time_constants_s, sample_time_s),
          de);
    }
  }
  closed_loop_theta_ = closed_loop.solve(settings_.relative_ridge);

  // e0(r): the feedback-only error, reconstructed from every trial as e_j + G u_j.
  const RegressorShape reference_shape = shape_of(TransferMethod::kReferenceFir, settings_);
  RidgeAccumulator feedback_error(reference_shape.count(), groups);
  theta_all_.assign(4, {});
  std::vector<RidgeAccumulator> inverse;
  for (const TransferMethod m : kMethods) inverse.emplace_back(shape_of(m, settings_).count(), groups);
  for (int g = 0; g < groups; ++g) {
    const TransferSource& s = sources_[static_cast<std::size_t>(g)];
    const int n = s.trajectory.learning_samples();
    const Eigen::VectorXd r = normalized(s.trajectory.joint(0));
    if (closed_loop_theta_.size() > 0) {
      const Eigen::MatrixXd phi_r = build_regressors(r, reference_shape, 1, n, sample_time_s);
      for (const TransferTrial& trial : s.trials) {
        feedback_error.add(g, phi_r, trial_error(s.trajectory, trial) + predicted_error_change(trial.u_ilc_bar));
      }
    }
    const TransferTrial& last = s.trials.back();
    for (std::size_t m = 0; m < 2; ++m) {  // reference-fir, basis: r -> the last trial's total input
      inverse[m].add(g, build_regressors(r, shape_of(kMethods[m], settings_), 1, n, sample_time_s),
                     applied_total_bar(last, s.controller));
    }
    for (const TransferTrial& trial : s.trials) {  // inverse-fir: y -> u over every trial
      inverse[2].add(g, build_regressors(normalized(trial.angle_rad), reference_shape, 1, n, sample_time_s),
                     applied_total_bar(trial, s.controller));
      info_.trials += 1;
      info_.fitted_rows += n;
    }
  }
  feedback_error_theta_ = feedback_error.solve(settings_.relative_ridge);
  inverse_fits_ = std::move(inverse);
  for (std::size_t m = 0; m < 3; ++m)
    theta_all_[static_cast<std::size_t>(kMethods[m])] = inverse_fits_[m].solve(settings_.relative_ridge);
  info_.sources = groups;
  info_.ready = true;
}

Eigen::VectorXd LearningTransfer::inverse_theta(TransferMethod method, int left_out) const {
  for (std::size_t m = 0; m < 3; ++m) {
    if (kMethods[m] == method)
      return left_out < 0 ? theta_all_[static_cast<std::size_t>(method)]
                          : inverse_fits_[m].solve(settings_.relative_ridge, left_out);
  }
  return {};
}

Eigen::VectorXd LearningTransfer::predict_correction(TransferMethod method, const Eigen::VectorXd& theta,
                                                     const Trajectory& target, const ControllerParameters& controller,
                                                     int* clamped) const {
  const int n = target.learning_samples();
  const Eigen::VectorXd r = normalized(target.joint(0));
  // inverse-fir maps an angle to the input that produced it: fed the reference, it gives the input
  // that makes the arm follow it.
  const Eigen::VectorXd total = build_regressors(r, shape_of(method, settings_), 1, n, sample_time_s_) * theta;
  const Eigen::VectorXd feedback = expected_feedback_bar(r, controller, sample_time_s_);
  const double reach = std::max(0.0, input_limit_bar(controller) - settings_.limit_margin_bar);
  Eigen::VectorXd u(n);
  int cut = 0;
  for (int t = 0; t < n; ++t) {
    const double lower = std::min(0.0, -reach - feedback(t));
    const double upper = std::max(0.0, reach - feedback(t));
    const double wanted = total(t) - feedback(t);
    u(t) = std::clamp(wanted, lower, upper);
    if (u(t) != wanted) ++cut;
  }
  if (clamped != nullptr) *clamped = cut;
  return u;
}

Eigen::VectorXd LearningTransfer::predicted_error_change(const Eigen::VectorXd& correction) const {
  return build_causal_regressors(correction, settings_.closed_loop_taps, settings_.slow_time_constants_s,
                                 sample_time_s_) *
         closed_loop_theta_;
}

Eigen::VectorXd LearningTransfer::predicted_feedback_error(const Trajectory& target) const {
  const Eigen::VectorXd r = normalized(target.joint(0));
  return build_regressors(r, shape_of(TransferMethod::kReferenceFir, settings_), 1, target.learning_samples(),
                          sample_time_s_) *
         feedback_error_theta_;
}

double LearningTransfer::validation_ratio(TransferMethod method) const {
  const int groups = static_cast<int>(sources_.size());
  double sum = 0.0;
  for (int g = 0; g < groups; ++g) {
    const TransferSource& s = sources_[static_cast<std::size_t>(g)];
    const Eigen::VectorXd theta = inverse_theta(method, groups > 1 ? g : -1);
    if (theta.size() == 0) return INFINITY;
    const TransferTrial& first = s.trials.front();
    const Eigen::VectorXd e0 = trial_error(s.trajectory, first) + predicted_error_change(first.u_ilc_bar);
    const Eigen::VectorXd u = predict_correction(method, theta, s.trajectory, s.controller, nullptr);
    const double before = rms_deg(e0);
    if (!(before > 0.0)) return INFINITY;
    sum += rms_deg(e0 - predicted_error_change(u)) / before;
  }
  return sum / groups;
}

TransferResult LearningTransfer::solve(const Trajectory& target) const {
  TransferResult result;
  const int n = target.learning_samples();
  result.correction_bar = Eigen::VectorXd::Zero(std::max(0, n));
  result.method = transfer_method_name(settings_.method);
  const auto fall_back = [&](std::string why) {
    result.status = TransferStatus::kFallback;
    result.reason = std::move(why);
    result.correction_bar.setZero();
    result.predicted_rms_deg = result.predicted_feedback_only_rms_deg;
    result.clamped_samples = 0;
    return result;
  };
  if (!info_.ready) return fall_back("no sessions were fitted");
  if (std::abs(target.sample_time_s - sample_time_s_) > 1e-9 * sample_time_s_ || n < 1) {
    return fall_back("the trajectory's sample time differs from the sessions'");
  }
  if (closed_loop_theta_.size() == 0 || feedback_error_theta_.size() == 0) {
    return fall_back("no session has two trials with different corrections: nothing predicts what a correction does");
  }
  const Eigen::VectorXd e0 = predicted_feedback_error(target);
  result.predicted_feedback_only_rms_deg = rms_deg(e0);

  TransferMethod method = settings_.method;
  if (method == TransferMethod::kAuto) {
    double best = INFINITY;
    for (const TransferMethod m : kMethods) {
      const double ratio = validation_ratio(m);
      result.method_ratios.emplace_back(transfer_method_name(m), ratio);
      if (ratio < best) best = ratio, method = m;
    }
    if (method == TransferMethod::kAuto) return fall_back("no method could be fitted");
    result.validation_ratio = best;
  } else {
    result.validation_ratio = validation_ratio(method);
  }
  result.method = transfer_method_name(method);
  char line[200];
  if (!(result.validation_ratio <= settings_.largest_accepted_ratio)) {
    std::snprintf(line, sizeof line, "on the sessions it was fitted to, %s predicts %.2f x the feedback-only error",
                  result.method.c_str(), result.validation_ratio);
    return fall_back(line);
  }
  const Eigen::VectorXd theta = inverse_theta(method, -1);
  const Eigen::VectorXd u = predict_correction(method, theta, target, target_controller_, &result.clamped_samples);
  if (!u.allFinite()) return fall_back("the fitted model gave a non-finite correction");
  result.predicted_rms_deg = rms_deg(e0 - predicted_error_change(u));
  if (!(result.predicted_rms_deg <= settings_.largest_accepted_ratio * result.predicted_feedback_only_rms_deg)) {
    std::snprintf(line, sizeof line, "on this trajectory %s predicts %.2f deg RMS, feedback only %.2f deg",
                  result.method.c_str(), result.predicted_rms_deg, result.predicted_feedback_only_rms_deg);
    return fall_back(line);
  }
  result.status = TransferStatus::kTransferred;
  result.correction_bar = u;
  return result;
}

}  // namespace bellows
