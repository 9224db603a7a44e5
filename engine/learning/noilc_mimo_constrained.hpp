// Norm-optimal ILC for J joints subject to bounds on the next correction: the J-joint form of
// `noilc-constrained` (engine/learning/noilc_constrained) without its trial context. Minimizes the cost of
// engine/learning/noilc_mimo subject to lower <= u_{j+1} <= upper elementwise (N x J bounds, e.g. the
// pressure reach minus the last trial's feedback per joint). It takes the unconstrained optimum
// first (one O(N) sweep); only if that violates a bound it runs over-relaxed ADMM whose inner step is
// the O(N) sweep with a proximal term and whose projection is a clamp, and returns the projected
// iterate: always feasible. setup() allocates; set_bounds() and solve() allocate nothing.
#pragma once

#include "engine/learning/noilc_mimo.hpp"

namespace bellows {

struct MultiJointAdmmSettings {
  double rho = 1.0;           // ADMM penalty (same units as S); > 0
  int max_iterations = 2000;  // >= 1
  double tolerance = 1.0e-7;  // bar, on the primal and dual residuals; > 0
};

struct MultiJointConstrainedReport {
  int admm_iterations = 0;  // 0 when the unconstrained optimum was feasible
  bool converged = true;
  int active_entries = 0;  // entries (sample, joint) on a bound
  double primal_residual = 0.0;
  double dual_residual = 0.0;
};

class MultiJointNoilcConstrained {
 public:
  /// As MultiJointNoilc::setup, plus kBadWeights for ADMM settings out of range. The bounds start
  /// infinite (the update is then the unconstrained one).
  MultiJointNoilcStatus setup(const MultiJointModel& model, const MultiJointWeights& weights, int samples,
                              const MultiJointAdmmSettings& admm = {});
  /// Bounds for the next solves, N x J each; kBadBounds (and the old bounds kept) when they are not.
  MultiJointNoilcStatus set_bounds(const Eigen::Ref<const Eigen::MatrixXd>& lower,
                                   const Eigen::Ref<const Eigen::MatrixXd>& upper);
  /// u_next = argmin J(u) subject to the bounds. kOk, or kNotConverged with a feasible u_next; on any
  /// other status u_next is left unchanged.
  MultiJointNoilcStatus solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                              const Eigen::Ref<const Eigen::MatrixXd>& e_j, Eigen::Ref<Eigen::MatrixXd> u_next);

  const MultiJointConstrainedReport& last_report() const { return report_; }
  const MultiJointNoilcInfo& info() const { return free_.info(); }
  /// Forgets the last solve's ADMM dual: the next solve starts cold (as the first after setup()).
  void forget_warm_start() { dual_.setZero(); }

 private:
  MultiJointAdmmSettings admm_;
  MultiJointNoilc free_;      // rho = 0: the unconstrained optimum
  MultiJointNoilc proximal_;  // rho = admm.rho: the ADMM step
  Eigen::MatrixXd lower_, upper_, x_, z_, z_previous_, dual_, target_;
  MultiJointConstrainedReport report_;
  bool ready_ = false;
};

}  // namespace bellows
