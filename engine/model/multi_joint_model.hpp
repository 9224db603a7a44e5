// A linear discrete model of an arm with J joints (1 <= J <= kMaxJoints): x(t+1) = A x(t) + B u(t),
// y(t) = C x(t), 2J states, u(t) the J pressure differences (bar), y(t) the J angles / pi. Two kinds:
// block-diagonal (J independent single-joint models, engine/model/arm_model) and coupled (one MIMO model,
// e.g. the chain linearized at a pose, engine/model/arm_chain_linearization). Sizes are fixed-capacity
// matrices: copying or reading a model never allocates.
#pragma once

#include <span>

#include <Eigen/Dense>

#include "engine/model/arm_model.hpp"
#include "engine/base/joints.hpp"  // kMaxJoints, JointVector, JointMatrix

namespace bellows {

struct MultiJointModel {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJointStates, kMaxJointStates> A;  // 2J x 2J
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJointStates, kMaxJoints> B;       // 2J x J
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJoints, kMaxJointStates> C;       // J x 2J
  double sample_time_s = 0.0;

  int joints() const { return static_cast<int>(C.rows()); }
  /// Lifted NJ x NJ matrix mapping u(0..N-1) to y(1..N), one step of delay, time-major ordering:
  /// entry t*J + i is joint i at sample t. Block (t, k) = C A^(t-k) B for t >= k. The test oracle.
  Eigen::MatrixXd lifted(int samples) const;
};

/// J independent joints: A, B, C block-diagonal from each joint's model (joint i owns states 2i, 2i+1).
/// Throws InputError for 0 or more than kMaxJoints models or differing sample times.
MultiJointModel block_diagonal_model(std::span<const DiscreteArmModel> joints);

/// Time-major stacking of an N x J matrix (a column per joint) into an NJ vector, and back.
Eigen::VectorXd stack_time_major(const Eigen::Ref<const Eigen::MatrixXd>& per_joint);
Eigen::MatrixXd unstack_time_major(const Eigen::Ref<const Eigen::VectorXd>& stacked, int joints);

}  // namespace bellows
