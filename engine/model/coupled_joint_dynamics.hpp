// The linear dynamics of J coupled joints in physical units, one row per joint:
//
//   q_ddot = per_angle q + per_velocity q_dot + per_bar dp
//
// (1/s^2, 1/s, rad/(s^2 bar)). It is what the chain linearized at a pose is (per_angle =
// -M^-1 (K + dG/dq), per_velocity = -M^-1 D, per_bar = M^-1 K kappa: engine/model/arm_chain_linearization),
// what J independent single-joint models are (diagonal: -w0^2, -2 delta w0, w0^2 kappa), and what
// `bellows identify` fits on a chain (engine/operator/coupled_identification). One description, so the three
// can be compared entry by entry and all discretize to the same MultiJointModel coordinates:
// x = (q_i / pi, q_dot_i / (10 pi)) per joint, joint i owning states 2i, 2i+1, y = q / pi.
#pragma once

#include <span>

#include <Eigen/Dense>

#include "engine/base/joints.hpp"
#include "engine/model/multi_joint_model.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

struct CoupledJointDynamics {
  JointMatrix per_angle;     // d q_ddot / d q (1/s^2)
  JointMatrix per_velocity;  // d q_ddot / d q_dot (1/s)
  JointMatrix per_bar;       // d q_ddot / d dp (rad/(s^2 bar))

  int joints() const { return static_cast<int>(per_angle.rows()); }
  /// The angle a constant pressure difference settles at: -per_angle^-1 per_bar (rad/bar), J x J.
  Eigen::MatrixXd static_gain_rad_per_bar() const;
};

/// J independent joints, each its single-joint model: diagonal matrices. InputError for 0 or more
/// than kMaxJoints models.
CoupledJointDynamics independent_dynamics(std::span<const ModelParameters> joints);

/// The first `joints` rows of `[identified_joint1..4]`. InputError when they hold no model (a row
/// without any per_bar entry) or do not describe an arm (a singular per_angle).
CoupledJointDynamics identified_dynamics(const IdentifiedArmParameters& identified, int joints);
/// The dynamics as `[identified_jointK]` values (the rows beyond its joints zero).
IdentifiedArmParameters identified_parameters(const CoupledJointDynamics& dynamics);

/// Continuous-time Ac (2J x 2J), Bc (2J x J) in the normalized coordinates above.
void continuous_joint_model(const CoupledJointDynamics& dynamics, Eigen::MatrixXd& Ac, Eigen::MatrixXd& Bc);

/// Exact zero-order-hold discretization at `sample_time_s` (> 0, else InputError).
MultiJointModel discretize_joint_dynamics(const CoupledJointDynamics& dynamics, double sample_time_s);

/// How far model `a` is from `reference`: the relative Frobenius distance of their first `count`
/// Markov parameters (C A^k B, the lifted matrix's block columns), sqrt(sum ||a_k - r_k||^2 / sum ||r_k||^2).
double markov_gap(const MultiJointModel& a, const MultiJointModel& reference, int count);

}  // namespace bellows
