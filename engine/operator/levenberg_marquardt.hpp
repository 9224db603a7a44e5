// Levenberg-Marquardt on a residual function, with forward-difference Jacobians: the one loop both
// identifications (one joint's model, the chain's coupled model) minimise their output error with.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace bellows {

/// Where the search ended. `residual` is the residual at `parameters`, `cost` its squared norm.
template <typename Vector>
struct LeastSquaresSolution {
  Vector parameters;
  Eigen::VectorXd residual;
  double cost = 0.0;
  int iterations = 0;
  bool converged = false;  // the relative decrease fell below the tolerance, or no step lowered the cost
};

/// Minimises |residual(p)|^2 from `start`, whose residual `start_residual` the caller has checked
/// finite. `steps`: each parameter's difference step. A candidate with a non-finite cost is rejected
/// like a worse one (damping grows).
template <typename Vector, typename Residual>
LeastSquaresSolution<Vector> levenberg_marquardt(const Residual& residual, const Vector& start,
                                                 Eigen::VectorXd start_residual, const Vector& steps,
                                                 int max_iterations, double relative_cost_tolerance) {
  using Matrix = Eigen::Matrix<double, Vector::RowsAtCompileTime, Vector::RowsAtCompileTime>;
  LeastSquaresSolution<Vector> s{start, std::move(start_residual)};
  s.cost = s.residual.squaredNorm();
  double damping = 1e-3;
  Eigen::MatrixXd jacobian(s.residual.size(), start.size());
  for (s.iterations = 1; s.iterations <= max_iterations; ++s.iterations) {
    for (Eigen::Index i = 0; i < start.size(); ++i) {
      Vector q = s.parameters;
      q(i) += steps(i);
      jacobian.col(i) = (residual(q) - s.residual) / steps(i);
    }
    const Matrix normal = jacobian.transpose() * jacobian;
    const Vector gradient = jacobian.transpose() * s.residual;
    bool improved = false;
    for (int attempt = 0; attempt < 20 && !improved; ++attempt) {
      Matrix lhs = normal;
      lhs.diagonal() += damping * normal.diagonal();
      const Vector candidate = s.parameters - lhs.ldlt().solve(gradient);
      const Eigen::VectorXd candidate_residual = residual(candidate);
      const double candidate_cost = candidate_residual.squaredNorm();
      if (std::isfinite(candidate_cost) && candidate_cost < s.cost) {
        const double decrease = (s.cost - candidate_cost) / s.cost;
        s.parameters = candidate;
        s.residual = candidate_residual;
        s.cost = candidate_cost;
        damping = std::max(damping / 3.0, 1e-9);
        improved = true;
        if (decrease < relative_cost_tolerance) s.converged = true;
      } else {
        damping *= 4.0;
      }
    }
    if (!improved) s.converged = true;  // no direction lowers the cost: a minimum
    if (s.converged) break;
  }
  s.iterations = std::min(s.iterations, max_iterations);
  return s;
}

}  // namespace bellows
