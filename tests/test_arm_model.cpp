#include <gtest/gtest.h>

#include <numbers>

#include "engine/model/arm_model.hpp"

namespace bellows {
namespace {

TEST(ArmModel, DiscretizationReproducesThePapersPrintedMatrices) {
  const DiscreteArmModel d = discretize_arm_model(ModelParameters{}, 1.0 / 50.0);
  // The paper prints A = [[0.96, 0.18], [-0.36, 0.80]], B = [0.09, 0.91]: two decimals.
  EXPECT_NEAR(d.A(0, 0), 0.96, 0.005);
  EXPECT_NEAR(d.A(0, 1), 0.18, 0.005);
  EXPECT_NEAR(d.A(1, 0), -0.36, 0.005);
  EXPECT_NEAR(d.A(1, 1), 0.80, 0.005);
  EXPECT_NEAR(d.B(0), 0.09, 0.005);
  EXPECT_NEAR(d.B(1), 0.91, 0.005);
  // And the spec's exact values to four decimals.
  EXPECT_NEAR(d.A(0, 0), 0.9625, 5e-5);
  EXPECT_NEAR(d.A(0, 1), 0.1810, 5e-5);
  EXPECT_NEAR(d.A(1, 0), -0.3619, 5e-5);
  EXPECT_NEAR(d.A(1, 1), 0.8038, 5e-5);
  EXPECT_NEAR(d.B(0), 0.0944, 5e-5);
  EXPECT_NEAR(d.B(1), 0.9112, 5e-5);
}

TEST(ArmModel, DiscretizationFollowsTheParameters) {
  ModelParameters stiffer;
  stiffer.omega0_rad_per_s = 20.0;
  const DiscreteArmModel nominal = discretize_arm_model(ModelParameters{}, 0.02);
  const DiscreteArmModel changed = discretize_arm_model(stiffer, 0.02);
  EXPECT_GT((nominal.A - changed.A).norm(), 1e-3);
  // The static gain from u to alpha/pi is kappa/pi whatever the frequency: C (I - A)^-1 B.
  const double gain = changed.C * (Eigen::Matrix2d::Identity() - changed.A).inverse() * changed.B;
  EXPECT_NEAR(gain, 7.91 / std::numbers::pi, 1e-9);
}

TEST(ArmModel, LiftedMatrixIsLowerTriangularToeplitzOfMarkovParameters) {
  const DiscreteArmModel d = discretize_arm_model(ModelParameters{}, 0.02);
  const int n = 7;
  const Eigen::MatrixXd P = d.lifted(n);
  ASSERT_EQ(P.rows(), n);
  EXPECT_DOUBLE_EQ(P(0, 0), (d.C * d.B).value());
  EXPECT_DOUBLE_EQ(P(3, 1), (d.C * d.A * d.A * d.B).value());
  for (int r = 0; r < n; ++r) {
    for (int c = r + 1; c < n; ++c) EXPECT_EQ(P(r, c), 0.0);
    for (int c = 1; c <= r; ++c) EXPECT_DOUBLE_EQ(P(r, c), P(r - 1, c - 1));
  }
  // Simulating the model gives the same outputs as the lifted product.
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(n, -0.2, 0.3);
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int t = 0; t < n; ++t) {
    x = d.A * x + d.B * u(t);
    EXPECT_NEAR((d.C * x).value(), (P * u)(t), 1e-12);
  }
}

}  // namespace
}  // namespace bellows
