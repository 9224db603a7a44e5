#include "engine/model/arm_chain_linearization.hpp"

#include <string>

#include "engine/base/errors.hpp"

namespace bellows {

CoupledJointDynamics chain_dynamics(const ArmChain& arm, const JointVector& pose_rad) {
  const int J = arm.joints();
  if (pose_rad.size() != J) throw InputError("arm linearization: the pose needs " + std::to_string(J) + " angles");
  const Eigen::MatrixXd inverse_mass = Eigen::MatrixXd(arm.mass_matrix(pose_rad)).inverse();
  Eigen::MatrixXd stiffness = arm.gravity_stiffness(pose_rad);
  Eigen::MatrixXd input_torque = Eigen::MatrixXd::Zero(J, J);  // K kappa, N m per bar
  for (int i = 0; i < J; ++i) {
    const ChainLink& l = arm.parameters().links[static_cast<std::size_t>(i)];
    stiffness(i, i) += l.stiffness_Nm_per_rad;
    input_torque(i, i) = l.stiffness_Nm_per_rad * l.kappa_rad_per_bar;
  }
  CoupledJointDynamics d;
  d.per_angle = -inverse_mass * stiffness;  // rad/s^2 per rad
  d.per_velocity = -inverse_mass * Eigen::MatrixXd(arm.damping_Nms_per_rad().asDiagonal());
  d.per_bar = inverse_mass * input_torque;  // rad/s^2 per bar
  return d;
}

void continuous_chain_model(const ArmChain& arm, const JointVector& pose_rad, Eigen::MatrixXd& Ac,
                            Eigen::MatrixXd& Bc) {
  continuous_joint_model(chain_dynamics(arm, pose_rad), Ac, Bc);
}

MultiJointModel linearize_chain(const ArmChain& arm, const JointVector& pose_rad, double sample_time_s) {
  if (!(sample_time_s > 0.0)) throw InputError("arm linearization: the sample time must be > 0");
  return discretize_joint_dynamics(chain_dynamics(arm, pose_rad), sample_time_s);
}

}  // namespace bellows
