// Norm-optimal ILC for J joints in the dense lifted closed form: the test oracle of the O(N) form
// (engine/learning/noilc_mimo). Time-major stacking (engine/model/multi_joint_model), P the NJ x NJ lifted model,
// and with Kronecker products the weights of the cost in noilc_mimo.hpp:
//
//   u_{j+1} = (P'(I (x) M)P + I (x) S + (D'D) (x) W + rho I)^-1 [ (P'(I (x) M)P + I (x) S) u_j + P'(I (x) M) e_j + rho
//   target ]
//
// O(N^2 J^2) memory and O(N^3 J^3) set-up: for tests and benchmarks, not for the loop.
#pragma once

#include "engine/learning/noilc_mimo.hpp"

namespace bellows {

class MultiJointNoilcDense {
 public:
  /// Throws InputError when N < 2, the joint count is outside 1..kMaxJoints or the cost is not
  /// positive definite.
  MultiJointNoilcDense(const MultiJointModel& model, const MultiJointWeights& weights, int samples,
                       double proximal_weight = 0.0);

  /// N x J in and out, as MultiJointNoilc::solve.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& u_j, const Eigen::MatrixXd& e_j, const Eigen::MatrixXd& target) const;
  Eigen::MatrixXd update(const Eigen::MatrixXd& u_j, const Eigen::MatrixXd& e_j) const { return solve(u_j, e_j, u_j); }

  /// Gradient of the cost at `u_next` (stacked time-major, NJ): zero at the optimum.
  Eigen::VectorXd cost_gradient(const Eigen::MatrixXd& u_j, const Eigen::MatrixXd& e_j, const Eigen::MatrixXd& target,
                                const Eigen::MatrixXd& u_next) const;

  int joints() const { return joints_; }

 private:
  int joints_;
  double rho_;
  Eigen::MatrixXd lifted_;                // P
  Eigen::MatrixXd output_weight_;         // I (x) M
  Eigen::MatrixXd change_weight_;         // I (x) S
  Eigen::MatrixXd rate_weight_;           // (D'D) (x) W
  Eigen::MatrixXd tracking_plus_change_;  // P'(I (x) M)P + I (x) S
  Eigen::LLT<Eigen::MatrixXd> factor_;
};

}  // namespace bellows
