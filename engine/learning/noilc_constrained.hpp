// Constraint-aware norm-optimal ILC (`noilc-constrained`). The set points are
// pA = clamp(p0 + u_tot), pB = clamp(p0 - u_tot) with u_tot = u_pid + u_ilc, so only
// |u_tot| <= p_max - p0 reaches the arm. The paper's update ignores this: where the clamp saturates,
// its correction keeps growing trial after trial (wind-up). This law minimizes the same cost subject
// to the bounds
//     -(limit - margin) - u_pid_j(t) <= u_{j+1}(t) <= (limit - margin) - u_pid_j(t)
// built from the last trial's feedback u_pid_j. It first takes the exact unconstrained optimum (one
// O(N) sweep); only if that violates a bound it runs ADMM (over-relaxed, scaled form), whose inner
// step is the O(N) Riccati sweep with a proximal term and whose projection is a clamp. The result is
// always the projected iterate, so the returned correction is feasible whatever the iteration count.
//
// With a trial context (set_input_context), the errors of the outputs within `limit_recovery_s` after
// an input whose set point sat on the pressure limit in that trial are set to zero (not given zero
// weight in M: the update keeps those outputs where they are rather than being free to move them):
// there the valves' flow limit and the bellows' bounce-back shaped the response, which the linear model mispredicts;
// fitting those errors by pushing the neighbouring samples makes tracking worse on the arm
// (docs/learning-laws.md has the measurements). Without a context (set_bounds) the update is the
// plain bounded optimum.
#pragma once

#include "engine/learning/noilc_riccati.hpp"

namespace bellows {

class NormOptimalConstrained final : public LearningLaw {
 public:
  struct Report {
    int admm_iterations = 0;    // 0 when the unconstrained optimum was feasible
    bool converged = true;      // residuals below tolerance within the iteration limit
    int active_samples = 0;     // samples on a bound
    int unweighted_errors = 0;  // error samples left out after inputs on the pressure limit
    double primal_residual = 0.0;
    double dual_residual = 0.0;
  };

  NormOptimalConstrained(const DiscreteArmModel& model, const IlcParameters& parameters, int samples);

  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override;
  std::string name() const override { return "noilc-constrained"; }
  int samples() const override { return free_.samples(); }
  void set_input_context(const Eigen::Ref<const Eigen::VectorXd>& feedback_bar, double input_limit_bar) override;
  std::optional<LawFrequencyResponse> frequency_response(double theta_rad_per_sample) const override;

  /// Bounds for the next update directly (instead of from the feedback); lower <= upper elementwise.
  /// Drops the trial context: the next update is the plain bounded optimum.
  void set_bounds(const Eigen::Ref<const Eigen::VectorXd>& lower_bar,
                  const Eigen::Ref<const Eigen::VectorXd>& upper_bar);
  const Eigen::VectorXd& lower_bound() const { return lower_; }
  const Eigen::VectorXd& upper_bound() const { return upper_; }
  const Report& last_report() const { return report_; }
  /// Forgets the last update's ADMM dual: the next update starts cold (as the first after construction).
  void forget_warm_start() { dual_.setZero(); }
  std::size_t memory_bytes() const;

 private:
  /// Zeroes, in weighted_error_, the errors after the inputs u_j that sat on the limit in the last trial.
  void leave_out_limited_errors(const Eigen::Ref<const Eigen::VectorXd>& u_j);

  DiscreteArmModel model_;
  IlcParameters parameters_;
  int recovery_samples_;         // outputs left out after an input on the limit
  RiccatiNoilcSolver free_;      // rho = 0: the unconstrained optimum
  RiccatiNoilcSolver proximal_;  // rho = admm_rho: the ADMM step
  Eigen::VectorXd lower_, upper_;
  Eigen::VectorXd x_, z_, z_previous_, dual_, target_;
  Eigen::VectorXd feedback_, weighted_error_;
  double reach_bar_ = 0.0;
  bool has_trial_context_ = false;
  Eigen::VectorXd previous_lower_, previous_upper_;  // the bounds u_j was planned against
  Report report_;
};

}  // namespace bellows
