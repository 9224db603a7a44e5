// The J-joint arm linearized at a pose: the coupled model of the J-joint norm-optimal ILC
// (../shared/spec/multi-joint.md section 4, "2J states, J inputs, J outputs"). At rest at pose q0,
// held by its holding pressure, small deviations obey
//
//   M(q0) dq_ddot = -(K + dG/dq(q0)) dq - D dq_dot + K kappa o d(dp)
//
// (Coriolis terms are quadratic in the velocity and vanish; creep and the pneumatics are left out, as
// the single-joint nominal model leaves them out). The states are the single joint's normalized ones
// per joint, joint i owning states 2i, 2i+1: x = (q_i / pi, q_dot_i / (10 pi)), u = dp (bar),
// y = q / pi; zero-order hold at the sample time. With one joint, no gravity and M_11 = K / w0^2
// this is discretize_arm_model of the single-joint arm.
#pragma once

#include "engine/model/arm_chain.hpp"
#include "engine/model/multi_joint_model.hpp"

namespace bellows {

/// Continuous-time Ac (2J x 2J), Bc (2J x J) in the normalized coordinates above.
void continuous_chain_model(const ArmChain& arm, const JointVector& pose_rad, Eigen::MatrixXd& Ac, Eigen::MatrixXd& Bc);

/// Exact zero-order-hold discretization at `sample_time_s` (> 0, else InputError).
MultiJointModel linearize_chain(const ArmChain& arm, const JointVector& pose_rad, double sample_time_s);

}  // namespace bellows
