#include "engine/learning/noilc_mimo_constrained.hpp"

#include <limits>

namespace bellows {
namespace {
// Over-relaxation of ADMM: 1.5-1.8 is the usual sweet spot (Boyd et al., section 3.4.3), as for one joint.
constexpr double kAdmmOverRelaxation = 1.6;
}  // namespace

MultiJointNoilcStatus MultiJointNoilcConstrained::setup(const MultiJointModel& model, const MultiJointWeights& weights,
                                                        int samples, const MultiJointAdmmSettings& admm) {
  ready_ = false;
  if (!(admm.rho > 0.0) || admm.max_iterations < 1 || !(admm.tolerance > 0.0))
    return MultiJointNoilcStatus::kBadWeights;
  MultiJointNoilcStatus status = free_.setup(model, weights, samples);
  if (status != MultiJointNoilcStatus::kOk) return status;
  status = proximal_.setup(model, weights, samples, admm.rho);
  if (status != MultiJointNoilcStatus::kOk) return status;
  admm_ = admm;
  const Eigen::Index n = samples, J = model.joints();
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  lower_ = Eigen::MatrixXd::Constant(n, J, -kInfinity);
  upper_ = Eigen::MatrixXd::Constant(n, J, kInfinity);
  for (Eigen::MatrixXd* m : {&x_, &z_, &z_previous_, &target_}) m->resize(n, J);
  dual_ = Eigen::MatrixXd::Zero(n, J);
  report_ = {};
  ready_ = true;
  return status;
}

MultiJointNoilcStatus MultiJointNoilcConstrained::set_bounds(const Eigen::Ref<const Eigen::MatrixXd>& lower,
                                                             const Eigen::Ref<const Eigen::MatrixXd>& upper) {
  if (!ready_) return MultiJointNoilcStatus::kNotSetUp;
  if (lower.rows() != lower_.rows() || lower.cols() != lower_.cols() || upper.rows() != upper_.rows() ||
      upper.cols() != upper_.cols() || lower.hasNaN() || upper.hasNaN() || (lower.array() > upper.array()).any()) {
    return MultiJointNoilcStatus::kBadBounds;
  }
  lower_ = lower;
  upper_ = upper;
  return MultiJointNoilcStatus::kOk;
}

MultiJointNoilcStatus MultiJointNoilcConstrained::solve(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                                                        const Eigen::Ref<const Eigen::MatrixXd>& e_j,
                                                        Eigen::Ref<Eigen::MatrixXd> u_next) {
  if (!ready_) return MultiJointNoilcStatus::kNotSetUp;
  report_ = {};
  const MultiJointNoilcStatus free_status = free_.update(u_j, e_j, x_);
  if (free_status != MultiJointNoilcStatus::kOk) return free_status;  // shapes, NaN: u_next untouched
  if (u_next.rows() != x_.rows() || u_next.cols() != x_.cols()) return MultiJointNoilcStatus::kShapeMismatch;
  if ((x_.array() >= lower_.array()).all() && (x_.array() <= upper_.array()).all()) {
    u_next = x_;
    return MultiJointNoilcStatus::kOk;
  }
  // ADMM on  min J(x) + I_box(z)  s.t.  x = z, warm-started at the last correction (projected) and the
  // last solve's scaled dual (consecutive trials ask nearly the same question).
  z_ = u_j.cwiseMax(lower_).cwiseMin(upper_);
  if (!dual_.allFinite()) dual_.setZero();
  for (int k = 1; k <= admm_.max_iterations; ++k) {
    target_ = z_ - dual_;
    proximal_.solve(u_j, e_j, target_, x_);
    z_previous_.swap(z_);
    target_ = kAdmmOverRelaxation * x_ + (1.0 - kAdmmOverRelaxation) * z_previous_;  // the relaxed x
    z_ = (target_ + dual_).cwiseMax(lower_).cwiseMin(upper_);
    dual_ += target_ - z_;
    report_.admm_iterations = k;
    report_.primal_residual = (x_ - z_).cwiseAbs().maxCoeff();
    report_.dual_residual = admm_.rho * (z_ - z_previous_).cwiseAbs().maxCoeff();
    if (report_.primal_residual <= admm_.tolerance && report_.dual_residual <= admm_.tolerance) break;
  }
  report_.converged = report_.primal_residual <= admm_.tolerance && report_.dual_residual <= admm_.tolerance;
  report_.active_entries = static_cast<int>(((z_.array() <= lower_.array()) || (z_.array() >= upper_.array())).count());
  u_next = z_;
  return report_.converged ? MultiJointNoilcStatus::kOk : MultiJointNoilcStatus::kNotConverged;
}

}  // namespace bellows
