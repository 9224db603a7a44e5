// The nominal arm model (spec section 2): continuous second-order dynamics from pressure
// difference to angle, its zero-order-hold discretization and the lifted trial matrix P.
//
// State x = (alpha/pi, alpha_dot/(10 pi)), input u = dp / 1 bar, output y = C x = alpha/pi.
#pragma once

#include <Eigen/Dense>

#include "engine/base/parameters.hpp"

namespace bellows {

struct DiscreteArmModel {
  Eigen::Matrix2d A;
  Eigen::Vector2d B;
  Eigen::RowVector2d C;
  double sample_time_s = 0.0;

  /// Markov parameters C A^k B, k = 0..count-1: the first column of the lifted matrix.
  Eigen::VectorXd markov_parameters(int count) const;
  /// Lifted N x N lower-triangular Toeplitz matrix mapping u(0..N-1) to y(1..N) (one step delay).
  Eigen::MatrixXd lifted(int samples) const;
};

/// Continuous-time state matrices (Ac, Bc) in the normalized coordinates above.
void continuous_arm_model(const ModelParameters& model, Eigen::Matrix2d& Ac, Eigen::Vector2d& Bc);

/// Exact zero-order-hold discretization with the matrix exponential at `sample_time_s`.
DiscreteArmModel discretize_arm_model(const ModelParameters& model, double sample_time_s);

}  // namespace bellows
