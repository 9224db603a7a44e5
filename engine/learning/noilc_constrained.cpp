#include "engine/learning/noilc_constrained.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {
// Over-relaxation of ADMM: 1.5-1.8 is the usual sweet spot (Boyd et al., section 3.4.3).
constexpr double kRelaxation = 1.6;
}  // namespace

NormOptimalConstrained::NormOptimalConstrained(const DiscreteArmModel& model, const IlcParameters& parameters,
                                               int samples)
    : model_(model),
      parameters_(parameters),
      recovery_samples_(static_cast<int>(std::lround(parameters.limit_recovery_s / model.sample_time_s))),
      free_(model, parameters, samples),
      proximal_(model, parameters, samples, parameters.admm_rho),
      lower_(Eigen::VectorXd::Constant(samples, -std::numeric_limits<double>::infinity())),
      upper_(Eigen::VectorXd::Constant(samples, std::numeric_limits<double>::infinity())),
      x_(samples),
      z_(samples),
      z_previous_(samples),
      dual_(Eigen::VectorXd::Zero(samples)),
      target_(samples),
      feedback_(Eigen::VectorXd::Zero(samples)),
      weighted_error_(samples),
      previous_lower_(lower_),
      previous_upper_(upper_) {
  if (!(parameters.admm_rho > 0.0)) throw InputError("[ilc] admm_rho must be positive");
  if (parameters.admm_max_iterations < 1) throw InputError("[ilc] admm_max_iterations must be at least 1");
  if (!(parameters.admm_tolerance > 0.0)) throw InputError("[ilc] admm_tolerance must be positive");
  if (!(parameters.limit_recovery_s >= 0.0) || !std::isfinite(parameters.limit_recovery_s)) {
    throw InputError("[ilc] limit_recovery_s must be a finite, non-negative time");
  }
}

void NormOptimalConstrained::set_input_context(const Eigen::Ref<const Eigen::VectorXd>& feedback_bar,
                                               double input_limit_bar) {
  if (feedback_bar.size() != samples()) {
    throw InputError("noilc-constrained: feedback has " + std::to_string(feedback_bar.size()) + " samples, expected " +
                     std::to_string(samples()));
  }
  const double reach = input_limit_bar - parameters_.limit_margin_bar;
  if (!(reach > 0.0)) throw InputError("[ilc] limit_margin_bar leaves no room below the pressure limit");
  previous_lower_.swap(lower_);  // u_j was planned against these
  previous_upper_.swap(upper_);
  lower_ = -reach - feedback_bar.array();
  upper_ = reach - feedback_bar.array();
  feedback_ = feedback_bar;
  reach_bar_ = reach;
  has_trial_context_ = true;
}

void NormOptimalConstrained::set_bounds(const Eigen::Ref<const Eigen::VectorXd>& lower_bar,
                                        const Eigen::Ref<const Eigen::VectorXd>& upper_bar) {
  if (lower_bar.size() != samples() || upper_bar.size() != samples()) {
    throw InputError("noilc-constrained: bounds must have " + std::to_string(samples()) + " samples");
  }
  if ((lower_bar.array() > upper_bar.array()).any())
    throw InputError("noilc-constrained: a lower bound exceeds its upper bound");
  lower_ = lower_bar;
  upper_ = upper_bar;
  has_trial_context_ = false;
}

void NormOptimalConstrained::leave_out_limited_errors(const Eigen::Ref<const Eigen::VectorXd>& u_j) {
  if (!has_trial_context_ || recovery_samples_ == 0) return;
  const double tolerance = parameters_.admm_tolerance;
  const int n = samples();
  int left_out_until = 0;  // error entries below this index are already zero
  for (int i = 0; i < n; ++i) {
    // Input i sat on the limit: planned on a bound by the last update, or its set point reached the
    // limit in the trial (the feedback moved it there).
    const bool planned = u_j(i) <= previous_lower_(i) + tolerance || u_j(i) >= previous_upper_(i) - tolerance;
    const bool reached = std::abs(feedback_(i) + u_j(i)) >= reach_bar_ - tolerance;
    if (!planned && !reached) continue;
    // Entry k of the error is the output at sample k+1, the first that input i moves.
    const int end = std::min(n, i + recovery_samples_);
    for (int k = std::max(i, left_out_until); k < end; ++k) {
      weighted_error_(k) = 0.0;
      ++report_.unweighted_errors;
    }
    left_out_until = std::max(left_out_until, end);
  }
}

void NormOptimalConstrained::update(const Eigen::Ref<const Eigen::VectorXd>& u_j,
                                    const Eigen::Ref<const Eigen::VectorXd>& e_j, Eigen::Ref<Eigen::VectorXd> u_next) {
  report_ = {};
  weighted_error_ = e_j;
  leave_out_limited_errors(u_j);
  const Eigen::VectorXd& e = weighted_error_;
  free_.solve(u_j, e, u_j, x_);
  const bool feasible = (x_.array() >= lower_.array()).all() && (x_.array() <= upper_.array()).all();
  if (feasible) {
    u_next = x_;
    return;
  }
  // ADMM on  min J(x) + I_box(z)  s.t.  x = z, warm-started at the last correction (projected) and the
  // last update's scaled dual (consecutive trials ask nearly the same question).
  const double rho = parameters_.admm_rho;
  z_ = u_j.cwiseMax(lower_).cwiseMin(upper_);
  if (!dual_.allFinite()) dual_.setZero();
  for (int k = 1; k <= parameters_.admm_max_iterations; ++k) {
    target_ = z_ - dual_;
    proximal_.solve(u_j, e, target_, x_);
    z_previous_.swap(z_);
    target_ = kRelaxation * x_ + (1.0 - kRelaxation) * z_previous_;  // the relaxed x
    z_ = (target_ + dual_).cwiseMax(lower_).cwiseMin(upper_);
    dual_ += target_ - z_;
    report_.admm_iterations = k;
    report_.primal_residual = (x_ - z_).cwiseAbs().maxCoeff();
    report_.dual_residual = rho * (z_ - z_previous_).cwiseAbs().maxCoeff();
    if (report_.primal_residual <= parameters_.admm_tolerance && report_.dual_residual <= parameters_.admm_tolerance)
      break;
  }
  report_.converged =
      report_.primal_residual <= parameters_.admm_tolerance && report_.dual_residual <= parameters_.admm_tolerance;
  report_.active_samples = static_cast<int>(((z_.array() <= lower_.array()) || (z_.array() >= upper_.array())).count());
  u_next = z_;
}

std::optional<LawFrequencyResponse> NormOptimalConstrained::frequency_response(double theta_rad_per_sample) const {
  return norm_optimal_frequency_response(model_, parameters_, theta_rad_per_sample);  // with no bound active
}

std::size_t NormOptimalConstrained::memory_bytes() const {
  return free_.memory_bytes() + proximal_.memory_bytes() + sizeof(double) * 11 * static_cast<std::size_t>(samples());
}

}  // namespace bellows
