#include <gtest/gtest.h>

#include <random>

#include "engine/learning/noilc_dense.hpp"

namespace bellows {
namespace {

TEST(RateDifferenceMatrix, ForwardDifferenceWithRepeatedLastRow) {
  const Eigen::MatrixXd D = rate_difference_matrix(4, 0.5);
  Eigen::MatrixXd expected(4, 4);
  expected << -2, 2, 0, 0,  //
      0, -2, 2, 0,          //
      0, 0, -2, 2,          //
      0, 0, -2, 2;
  EXPECT_TRUE(D.isApprox(expected));
}

TEST(NormOptimalDense, UpdateZeroesTheCostGradientForRandomData) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> weight(0.01, 2.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const DiscreteArmModel model = discretize_arm_model(ModelParameters{}, 0.02);
  for (int trial = 0; trial < 12; ++trial) {
    const int n = 5 + trial * 17;
    const IlcParameters weights =
        trial == 0 ? IlcParameters{} : IlcParameters{"noilc-dense", weight(rng), weight(rng), weight(rng) * 1e-4};
    NormOptimalDense law(model, weights, n);
    Eigen::VectorXd u(n), e(n), next(n);
    for (int i = 0; i < n; ++i) {
      u(i) = 0.1 * normal(rng);
      e(i) = 0.05 * normal(rng);
    }
    law.update(u, e, next);
    const Eigen::VectorXd gradient = law.cost_gradient(u, e, next);
    // Scale: the gradient's terms at u_next = u_j, so the check is relative to the problem size.
    const double scale = law.cost_gradient(u, e, u).norm();
    ASSERT_GT(scale, 0.0);
    EXPECT_LT(gradient.norm(), 1e-10 * scale) << "n = " << n;
    // And it is a descent: any perturbation raises the gradient away from zero.
    Eigen::VectorXd perturbed = next;
    perturbed(n / 2) += 1e-3;
    EXPECT_GT(law.cost_gradient(u, e, perturbed).norm(), 1e3 * gradient.norm());
  }
}

TEST(NormOptimalDense, ZeroErrorAndZeroCorrectionStaysZero) {
  const DiscreteArmModel model = discretize_arm_model(ModelParameters{}, 0.02);
  NormOptimalDense law(model, IlcParameters{}, 50);
  Eigen::VectorXd next(50);
  law.update(Eigen::VectorXd::Zero(50), Eigen::VectorXd::Zero(50), next);
  EXPECT_EQ(next.norm(), 0.0);
}

TEST(NormOptimalDense, RejectsWeightsWithoutAPositiveDefiniteCost) {
  const DiscreteArmModel model = discretize_arm_model(ModelParameters{}, 0.02);
  EXPECT_THROW(NormOptimalDense(model, IlcParameters{"noilc-dense", 0.0, 0.0, 0.0}, 10), std::exception);
  EXPECT_THROW(NormOptimalDense(model, IlcParameters{}, 1), std::exception);
}

}  // namespace
}  // namespace bellows
