#include "engine/model/coupled_joint_dynamics.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include <unsupported/Eigen/MatrixFunctions>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {
// The factor 10 keeps both states of a joint of the same order (the paper's scaling, arm_model.cpp).
constexpr double kVelocityScale = 10.0;
}  // namespace

Eigen::MatrixXd CoupledJointDynamics::static_gain_rad_per_bar() const {
  return -Eigen::MatrixXd(per_angle).partialPivLu().solve(Eigen::MatrixXd(per_bar));
}

CoupledJointDynamics independent_dynamics(std::span<const ModelParameters> joints) {
  const int J = static_cast<int>(joints.size());
  if (!valid_joint_count(J)) {
    throw InputError("coupled joint dynamics need 1 to " + std::to_string(kMaxJoints) + " joints, got " +
                     std::to_string(J));
  }
  CoupledJointDynamics d;
  d.per_angle.setZero(J, J);
  d.per_velocity.setZero(J, J);
  d.per_bar.setZero(J, J);
  for (int i = 0; i < J; ++i) {
    const ModelParameters& m = joints[static_cast<std::size_t>(i)];
    const double w0 = m.omega0_rad_per_s;
    d.per_angle(i, i) = -w0 * w0;
    d.per_velocity(i, i) = -2.0 * m.damping * w0;
    d.per_bar(i, i) = w0 * w0 * m.kappa_rad_per_bar;
  }
  return d;
}

CoupledJointDynamics identified_dynamics(const IdentifiedArmParameters& identified, int joints) {
  if (!valid_joint_count(joints)) throw InputError("identified model: 1 to " + std::to_string(kMaxJoints) + " joints");
  CoupledJointDynamics d;
  d.per_angle.setZero(joints, joints);
  d.per_velocity.setZero(joints, joints);
  d.per_bar.setZero(joints, joints);
  for (int i = 0; i < joints; ++i) {
    const IdentifiedJointRow& row = identified.joint[static_cast<std::size_t>(i)];
    for (int k = 0; k < joints; ++k) {
      const auto at = static_cast<std::size_t>(k);
      d.per_angle(i, k) = row.per_angle_per_s2[at];
      d.per_velocity(i, k) = row.per_velocity_per_s[at];
      d.per_bar(i, k) = row.per_bar_rad_per_s2[at];
    }
    if (d.per_bar.row(i).isZero(0.0)) {
      throw InputError("[identified_joint" + std::to_string(i + 1) +
                       "] holds no identified model (bellows identify --config FILE --write-model FILE writes it)");
    }
  }
  if (Eigen::MatrixXd(d.per_angle).fullPivLu().rank() < joints) {
    throw InputError("[identified_joint1.." + std::to_string(joints) +
                     "] per_angle: a singular matrix is no arm (identify again)");
  }
  return d;
}

IdentifiedArmParameters identified_parameters(const CoupledJointDynamics& dynamics) {
  IdentifiedArmParameters p;
  for (int i = 0; i < dynamics.joints(); ++i) {
    IdentifiedJointRow& row = p.joint[static_cast<std::size_t>(i)];
    for (int k = 0; k < dynamics.joints(); ++k) {
      const auto at = static_cast<std::size_t>(k);
      row.per_angle_per_s2[at] = dynamics.per_angle(i, k);
      row.per_velocity_per_s[at] = dynamics.per_velocity(i, k);
      row.per_bar_rad_per_s2[at] = dynamics.per_bar(i, k);
    }
  }
  return p;
}

void continuous_joint_model(const CoupledJointDynamics& dynamics, Eigen::MatrixXd& Ac, Eigen::MatrixXd& Bc) {
  const int J = dynamics.joints();
  Ac = Eigen::MatrixXd::Zero(2 * J, 2 * J);
  Bc = Eigen::MatrixXd::Zero(2 * J, J);
  for (int i = 0; i < J; ++i) {
    Ac(2 * i, 2 * i + 1) = kVelocityScale;
    for (int j = 0; j < J; ++j) {
      Ac(2 * i + 1, 2 * j) = dynamics.per_angle(i, j) / kVelocityScale;
      Ac(2 * i + 1, 2 * j + 1) = dynamics.per_velocity(i, j);
      Bc(2 * i + 1, j) = dynamics.per_bar(i, j) / (kVelocityScale * std::numbers::pi);
    }
  }
}

MultiJointModel discretize_joint_dynamics(const CoupledJointDynamics& dynamics, double sample_time_s) {
  if (!(sample_time_s > 0.0)) throw InputError("joint dynamics: the sample time must be > 0");
  const int J = dynamics.joints();
  if (!valid_joint_count(J)) throw InputError("joint dynamics: 1 to " + std::to_string(kMaxJoints) + " joints");
  Eigen::MatrixXd Ac, Bc;
  continuous_joint_model(dynamics, Ac, Bc);
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

double markov_gap(const MultiJointModel& a, const MultiJointModel& reference, int count) {
  if (a.joints() != reference.joints()) throw InputError("markov_gap: the models have different joint counts");
  Eigen::MatrixXd power_a = a.B, power_r = reference.B;  // A^k B
  double difference = 0.0, size = 0.0;
  for (int k = 0; k < count; ++k) {
    const Eigen::MatrixXd markov_a = a.C * power_a, markov_r = reference.C * power_r;
    difference += (markov_a - markov_r).squaredNorm();
    size += markov_r.squaredNorm();
    power_a = (a.A * power_a).eval();
    power_r = (reference.A * power_r).eval();
  }
  return size > 0.0 ? std::sqrt(difference / size) : std::sqrt(difference);
}

}  // namespace bellows
