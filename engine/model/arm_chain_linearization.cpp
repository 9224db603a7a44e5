#include "engine/model/arm_chain_linearization.hpp"

#include <numbers>
#include <string>

#include <unsupported/Eigen/MatrixFunctions>

#include "engine/base/errors.hpp"

namespace bellows {

void continuous_chain_model(const ArmChain& arm, const JointVector& pose_rad, Eigen::MatrixXd& Ac, Eigen::MatrixXd& Bc) {
  const int J = arm.joints();
  if (pose_rad.size() != J) throw InputError("arm linearization: the pose needs " + std::to_string(J) + " angles");
  // The factor 10 keeps both states of a joint of the same order (the paper's scaling, arm_model.cpp).
  constexpr double kVelocityScale = 10.0;
  const Eigen::MatrixXd inverse_mass = Eigen::MatrixXd(arm.mass_matrix(pose_rad)).inverse();
  Eigen::MatrixXd stiffness = arm.gravity_stiffness(pose_rad);
  Eigen::MatrixXd input_torque = Eigen::MatrixXd::Zero(J, J);  // K kappa, N m per bar
  for (int i = 0; i < J; ++i) {
    const ChainLink& l = arm.parameters().links[static_cast<std::size_t>(i)];
    stiffness(i, i) += l.stiffness_Nm_per_rad;
    input_torque(i, i) = l.stiffness_Nm_per_rad * l.kappa_rad_per_bar;
  }
  const Eigen::MatrixXd from_angle = -inverse_mass * stiffness;                                   // rad/s^2 per rad
  const Eigen::MatrixXd from_velocity = -inverse_mass * Eigen::MatrixXd(arm.damping_Nms_per_rad().asDiagonal());
  const Eigen::MatrixXd from_input = inverse_mass * input_torque;                                 // rad/s^2 per bar
  Ac = Eigen::MatrixXd::Zero(2 * J, 2 * J);
  Bc = Eigen::MatrixXd::Zero(2 * J, J);
  for (int i = 0; i < J; ++i) {
    Ac(2 * i, 2 * i + 1) = kVelocityScale;
    for (int j = 0; j < J; ++j) {
      Ac(2 * i + 1, 2 * j) = from_angle(i, j) / kVelocityScale;
      Ac(2 * i + 1, 2 * j + 1) = from_velocity(i, j);
      Bc(2 * i + 1, j) = from_input(i, j) / (kVelocityScale * std::numbers::pi);
    }
  }
}

MultiJointModel linearize_chain(const ArmChain& arm, const JointVector& pose_rad, double sample_time_s) {
  if (!(sample_time_s > 0.0)) throw InputError("arm linearization: the sample time must be > 0");
  const int J = arm.joints();
  Eigen::MatrixXd Ac, Bc;
  continuous_chain_model(arm, pose_rad, Ac, Bc);
  // exp([[Ac, Bc], [0, 0]] T) = [[A, B], [0, I]] is the exact zero-order hold.
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(3 * J, 3 * J);
  augmented.topLeftCorner(2 * J, 2 * J) = Ac * sample_time_s;
  augmented.topRightCorner(2 * J, J) = Bc * sample_time_s;
  const Eigen::MatrixXd exponential = augmented.exp();
  MultiJointModel model;
  model.A = exponential.topLeftCorner(2 * J, 2 * J);
  model.B = exponential.topRightCorner(2 * J, J);
  model.C.setZero(J, 2 * J);
  for (int i = 0; i < J; ++i) model.C(i, 2 * i) = 1.0;
  model.sample_time_s = sample_time_s;
  return model;
}

}  // namespace bellows
