// Norm-optimal ILC in the paper's closed form (spec section 5):
//   u_{j+1} = (P'MP + S + D'WD)^-1 [ (P'MP + S) u_j + P'M e_j ]
// with M = m I, S = s I, W = w I and D the forward difference divided by T (its last row repeating
// the one before). The N x N system is factorized once, at construction; an update is then two
// triangular solves and a matrix-vector product: O(N^2). The O(N) Riccati form is the default law;
// this dense one is the reference it is tested against.
#pragma once

#include <cstddef>

#include "engine/model/arm_model.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

/// Forward-difference matrix divided by T, N x N, last row repeating the one before.
Eigen::MatrixXd rate_difference_matrix(int samples, double sample_time_s);

class NormOptimalDense final : public LearningLaw {
 public:
  NormOptimalDense(const DiscreteArmModel& model, const IlcParameters& weights, int samples);

  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override;
  std::string name() const override { return "noilc-dense"; }
  int samples() const override { return static_cast<int>(lifted_.rows()); }
  std::optional<LawFrequencyResponse> frequency_response(double theta_rad_per_sample) const override;

  /// Bytes held by the dense matrices and the factor (what grows with N).
  std::size_t memory_bytes() const;

  /// Gradient of the cost J(u) at `u_next` for the given u_j, e_j: zero at the optimum.
  Eigen::VectorXd cost_gradient(const Eigen::VectorXd& u_j, const Eigen::VectorXd& e_j,
                                const Eigen::VectorXd& u_next) const;

 private:
  DiscreteArmModel model_;
  IlcParameters weights_;
  Eigen::MatrixXd lifted_;                // P
  Eigen::MatrixXd rate_;                  // D
  Eigen::MatrixXd tracking_plus_change_;  // P'MP + S
  Eigen::LLT<Eigen::MatrixXd> factor_;    // of P'MP + S + D'WD
  Eigen::VectorXd rhs_;
};

}  // namespace bellows
