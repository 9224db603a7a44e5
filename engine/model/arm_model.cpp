#include "engine/model/arm_model.hpp"

#include <numbers>

#include <unsupported/Eigen/MatrixFunctions>

namespace bellows {

void continuous_arm_model(const ModelParameters& model, Eigen::Matrix2d& Ac, Eigen::Vector2d& Bc) {
  // alpha_ddot = w0^2 (kappa u - alpha) - 2 delta w0 alpha_dot, with x1 = alpha/pi and
  // x2 = alpha_dot/(10 pi): the factor 10 keeps both states of the same order (the paper's scaling).
  const double w0 = model.omega0_rad_per_s;
  constexpr double kVelocityScale = 10.0;
  Ac << 0.0, kVelocityScale, -w0 * w0 / kVelocityScale, -2.0 * model.damping * w0;
  Bc << 0.0, w0 * w0 * model.kappa_rad_per_bar / (kVelocityScale * std::numbers::pi);
}

DiscreteArmModel discretize_arm_model(const ModelParameters& model, double sample_time_s) {
  Eigen::Matrix2d Ac;
  Eigen::Vector2d Bc;
  continuous_arm_model(model, Ac, Bc);
  // exp([[Ac, Bc], [0, 0]] T) = [[A, B], [0, 1]] is the exact zero-order hold.
  Eigen::Matrix3d augmented = Eigen::Matrix3d::Zero();
  augmented.topLeftCorner<2, 2>() = Ac * sample_time_s;
  augmented.topRightCorner<2, 1>() = Bc * sample_time_s;
  const Eigen::Matrix3d exponential = augmented.exp();
  DiscreteArmModel d;
  d.A = exponential.topLeftCorner<2, 2>();
  d.B = exponential.topRightCorner<2, 1>();
  d.C << 1.0, 0.0;
  d.sample_time_s = sample_time_s;
  return d;
}

Eigen::VectorXd DiscreteArmModel::markov_parameters(int count) const {
  Eigen::VectorXd h(count);
  Eigen::Vector2d power_times_b = B;
  for (int k = 0; k < count; ++k) {
    h(k) = C * power_times_b;
    power_times_b = A * power_times_b;
  }
  return h;
}

Eigen::MatrixXd DiscreteArmModel::lifted(int samples) const {
  const Eigen::VectorXd h = markov_parameters(samples);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(samples, samples);
  for (int column = 0; column < samples; ++column) {
    P.col(column).tail(samples - column) = h.head(samples - column);
  }
  return P;
}

}  // namespace bellows
