#include "engine/learning/noilc_mimo_dense.hpp"

#include <string>

#include "engine/base/errors.hpp"
#include "engine/learning/noilc_dense.hpp"

namespace bellows {
namespace {

/// kron(I_N, X) for a J x J block X.
Eigen::MatrixXd block_diagonal_repeat(const JointMatrix& block, int samples) {
  const Eigen::Index J = block.rows();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(samples * J, samples * J);
  for (int t = 0; t < samples; ++t) out.block(t * J, t * J, J, J) = block;
  return out;
}

}  // namespace

MultiJointNoilcDense::MultiJointNoilcDense(const MultiJointModel& model, const MultiJointWeights& weights, int samples,
                                           double proximal_weight)
    : joints_(model.joints()), rho_(proximal_weight) {
  if (samples < 2) throw InputError("norm-optimal ILC needs at least 2 samples, got " + std::to_string(samples));
  if (joints_ < 1 || joints_ > kMaxJoints) throw InputError("norm-optimal ILC for J joints: J must be 1 to 4");
  const int J = joints_;
  lifted_ = model.lifted(samples);
  output_weight_ = block_diagonal_repeat(weights.m, samples);
  const Eigen::MatrixXd DtD = [&] {
    const Eigen::MatrixXd D = rate_difference_matrix(samples, model.sample_time_s);
    return Eigen::MatrixXd(D.transpose() * D);
  }();
  rate_weight_.setZero(samples * J, samples * J);
  for (int row = 0; row < samples; ++row) {
    for (int column = 0; column < samples; ++column) {
      rate_weight_.block(row * J, column * J, J, J) = DtD(row, column) * weights.w;
    }
  }
  change_weight_ = block_diagonal_repeat(weights.s, samples);
  tracking_plus_change_ = lifted_.transpose() * output_weight_ * lifted_ + change_weight_;
  Eigen::MatrixXd hessian = tracking_plus_change_ + rate_weight_;
  hessian.diagonal().array() += rho_;
  factor_.compute(hessian);
  if (factor_.info() != Eigen::Success) {
    throw InputError("norm-optimal ILC for J joints: the weights do not give a positive definite cost");
  }
}

Eigen::MatrixXd MultiJointNoilcDense::solve(const Eigen::MatrixXd& u_j, const Eigen::MatrixXd& e_j,
                                            const Eigen::MatrixXd& target) const {
  const Eigen::VectorXd u = stack_time_major(u_j);
  Eigen::VectorXd rhs = tracking_plus_change_ * u + lifted_.transpose() * (output_weight_ * stack_time_major(e_j));
  if (rho_ > 0.0) rhs += rho_ * stack_time_major(target);
  return unstack_time_major(factor_.solve(rhs), joints_);
}

Eigen::VectorXd MultiJointNoilcDense::cost_gradient(const Eigen::MatrixXd& u_j, const Eigen::MatrixXd& e_j,
                                                    const Eigen::MatrixXd& target,
                                                    const Eigen::MatrixXd& u_next) const {
  // J = 1/2 [e'(I (x) M)e + v'(I (x) S)v + u'((D'D) (x) W)u] + rho/2 |u - target|^2, e = e_j - P v, v = u - u_j
  const Eigen::VectorXd u = stack_time_major(u_next), v = u - stack_time_major(u_j);
  const Eigen::VectorXd predicted_error = stack_time_major(e_j) - lifted_ * v;
  Eigen::VectorXd gradient =
      -lifted_.transpose() * (output_weight_ * predicted_error) + change_weight_ * v + rate_weight_ * u;
  if (rho_ > 0.0) gradient += rho_ * (u - stack_time_major(target));
  return gradient;
}

}  // namespace bellows
