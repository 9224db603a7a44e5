// Bounded norm-optimal ILC for J joints (engine/learning/noilc_mimo_constrained): the result is always
// feasible and satisfies the optimality conditions of the bounded problem, checked with the dense
// oracle's cost gradient; loose bounds give the unconstrained optimum; solve allocates nothing.
#include <gtest/gtest.h>

#include "engine/model/arm_model.hpp"
#include "engine/learning/noilc_constrained.hpp"
#include "engine/learning/noilc_mimo_constrained.hpp"
#include "engine/learning/noilc_mimo_dense.hpp"
#include "tests/allocation_counter.hpp"
#include "tests/multi_joint_random.hpp"

namespace bellows {
namespace {

using namespace mimo_test;

/// KKT of min J(u) s.t. lower <= u <= upper: the gradient vanishes inside, points inward-or-zero
/// (g >= 0) at a lower bound and (g <= 0) at an upper bound. Returns the largest violation.
double kkt_violation(const Eigen::VectorXd& gradient, const Eigen::MatrixXd& u, const Eigen::MatrixXd& lower,
                     const Eigen::MatrixXd& upper) {
  const Eigen::Index J = u.cols();
  double worst = 0.0;
  for (Eigen::Index t = 0; t < u.rows(); ++t) {
    for (Eigen::Index i = 0; i < J; ++i) {
      const double g = gradient(t * J + i);
      constexpr double kOnBound = 1e-9;
      if (u(t, i) <= lower(t, i) + kOnBound) {
        worst = std::max(worst, -g);
      } else if (u(t, i) >= upper(t, i) - kOnBound) {
        worst = std::max(worst, g);
      } else {
        worst = std::max(worst, std::abs(g));
      }
    }
  }
  return worst;
}

TEST(NoilcMimoConstrained, BoundedOptimumIsFeasibleAndOptimalForOneToFourJoints) {
  Random random(61);
  for (int joints = 1; joints <= kMaxJoints; ++joints) {
    constexpr int kSamples = 80;
    const MultiJointModel model = random_coupled_model(joints, 0.9, random);
    const MultiJointWeights weights = random_full_weights(joints, random);
    MultiJointNoilcConstrained law;
    MultiJointAdmmSettings admm;
    admm.tolerance = 1e-10;
    admm.max_iterations = 100000;
    ASSERT_EQ(law.setup(model, weights, kSamples, admm), MultiJointNoilcStatus::kOk);
    const MultiJointNoilcDense dense(model, weights, kSamples);
    const Eigen::MatrixXd u_j = random.matrix(kSamples, joints, 0.2), e_j = random.matrix(kSamples, joints, 0.3);
    const Eigen::MatrixXd free = dense.update(u_j, e_j);
    // Bounds that cut the free optimum: per joint, half its reach, shifted as a feedback would shift them.
    const Eigen::MatrixXd shift = random.matrix(kSamples, joints, 0.02);
    Eigen::MatrixXd lower(kSamples, joints), upper(kSamples, joints);
    for (int i = 0; i < joints; ++i) {
      const double reach = 0.5 * free.col(i).cwiseAbs().maxCoeff();
      lower.col(i) = -reach - shift.col(i).array();
      upper.col(i) = reach - shift.col(i).array();
    }
    ASSERT_EQ(law.set_bounds(lower, upper), MultiJointNoilcStatus::kOk);
    Eigen::MatrixXd u(kSamples, joints);
    ASSERT_EQ(law.solve(u_j, e_j, u), MultiJointNoilcStatus::kOk) << "J = " << joints;
    EXPECT_TRUE((u.array() >= lower.array()).all() && (u.array() <= upper.array()).all());
    EXPECT_GT(law.last_report().admm_iterations, 0);
    EXPECT_GT(law.last_report().active_entries, 0);
    const Eigen::VectorXd gradient = dense.cost_gradient(u_j, e_j, u_j, u);
    const double scale = dense.cost_gradient(u_j, e_j, u_j, u_j).cwiseAbs().maxCoeff();
    EXPECT_LT(kkt_violation(gradient, u, lower, upper), 1e-6 * scale) << "J = " << joints;
    // The clamped free optimum is feasible but not optimal: it violates the conditions.
    const Eigen::MatrixXd clamped = free.cwiseMax(lower).cwiseMin(upper);
    EXPECT_GT(kkt_violation(dense.cost_gradient(u_j, e_j, u_j, clamped), clamped, lower, upper), 1e-3 * scale);
  }
}

TEST(NoilcMimoConstrained, OneJointIsTheSingleJointBoundedLaw) {
  // noilc-constrained with set_bounds (no trial context) is the plain bounded optimum of one joint.
  const DiscreteArmModel arm = discretize_arm_model(ModelParameters{}, kSampleTime_s);
  constexpr int kSamples = 200;
  IlcParameters parameters;
  parameters.admm_tolerance = 1e-10;
  parameters.admm_max_iterations = 20000;
  NormOptimalConstrained single(arm, parameters, kSamples);
  MultiJointNoilcConstrained law;
  MultiJointAdmmSettings admm{parameters.admm_rho, parameters.admm_max_iterations, parameters.admm_tolerance};
  ASSERT_EQ(
      law.setup(block_diagonal_model(std::span(&arm, 1)), MultiJointWeights::uniform(parameters, 1), kSamples, admm),
      MultiJointNoilcStatus::kOk);
  Random random(73);
  const Eigen::MatrixXd u_j = random.matrix(kSamples, 1, 0.05), e_j = random.matrix(kSamples, 1, 0.5);
  const Eigen::MatrixXd lower = Eigen::MatrixXd::Constant(kSamples, 1, -0.05) - random.matrix(kSamples, 1, 0.01);
  const Eigen::MatrixXd upper = lower.array() + 0.1;
  single.set_bounds(lower.col(0), upper.col(0));
  ASSERT_EQ(law.set_bounds(lower, upper), MultiJointNoilcStatus::kOk);
  Eigen::VectorXd expected(kSamples);
  Eigen::MatrixXd actual(kSamples, 1);
  single.update(u_j.col(0), e_j.col(0), expected);
  ASSERT_EQ(law.solve(u_j, e_j, actual), MultiJointNoilcStatus::kOk);
  EXPECT_GT(single.last_report().active_samples, 10);
  EXPECT_EQ(law.last_report().active_entries, single.last_report().active_samples);
  EXPECT_LT((actual.col(0) - expected).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(NoilcMimoConstrained, LooseBoundsGiveTheUnconstrainedOptimum) {
  Random random(67);
  constexpr int kSamples = 100, kJoints = 3;
  const MultiJointModel model = random_coupled_model(kJoints, 0.9, random);
  const MultiJointWeights weights = random_full_weights(kJoints, random);
  MultiJointNoilcConstrained bounded;
  MultiJointNoilc free;
  ASSERT_EQ(bounded.setup(model, weights, kSamples), MultiJointNoilcStatus::kOk);
  ASSERT_EQ(free.setup(model, weights, kSamples), MultiJointNoilcStatus::kOk);
  const Eigen::MatrixXd u_j = random.matrix(kSamples, kJoints, 0.2), e_j = random.matrix(kSamples, kJoints, 0.1);
  Eigen::MatrixXd expected(kSamples, kJoints), actual(kSamples, kJoints);
  ASSERT_EQ(free.update(u_j, e_j, expected), MultiJointNoilcStatus::kOk);
  ASSERT_EQ(bounded.solve(u_j, e_j, actual), MultiJointNoilcStatus::kOk);  // no bounds set: infinite
  EXPECT_EQ(actual, expected);
  ASSERT_EQ(bounded.set_bounds(Eigen::MatrixXd::Constant(kSamples, kJoints, -10.0),
                               Eigen::MatrixXd::Constant(kSamples, kJoints, 10.0)),
            MultiJointNoilcStatus::kOk);
  ASSERT_EQ(bounded.solve(u_j, e_j, actual), MultiJointNoilcStatus::kOk);
  EXPECT_EQ(actual, expected);
  EXPECT_EQ(bounded.last_report().admm_iterations, 0);
}

TEST(NoilcMimoConstrained, ReportsBadSettingsBoundsAndDataAndAllocatesNothing) {
  Random random(71);
  constexpr int kSamples = 60, kJoints = 2;
  const MultiJointModel model = random_coupled_model(kJoints, 0.9, random);
  const MultiJointWeights weights = MultiJointWeights::uniform(IlcParameters{}, kJoints);
  MultiJointNoilcConstrained law;
  Eigen::MatrixXd u_j = random.matrix(kSamples, kJoints, 0.2), e_j = random.matrix(kSamples, kJoints, 0.3);
  Eigen::MatrixXd out = Eigen::MatrixXd::Constant(kSamples, kJoints, 5.0);
  EXPECT_EQ(law.solve(u_j, e_j, out), MultiJointNoilcStatus::kNotSetUp);
  MultiJointAdmmSettings bad;
  bad.rho = 0.0;
  EXPECT_EQ(law.setup(model, weights, kSamples, bad), MultiJointNoilcStatus::kBadWeights);
  EXPECT_EQ(law.setup(model, weights, 1), MultiJointNoilcStatus::kTooFewSamples);
  MultiJointAdmmSettings few;
  few.max_iterations = 1;
  few.tolerance = 1e-12;
  ASSERT_EQ(law.setup(model, weights, kSamples, few), MultiJointNoilcStatus::kOk);
  const Eigen::MatrixXd lower = Eigen::MatrixXd::Constant(kSamples, kJoints, -0.01);
  const Eigen::MatrixXd upper = Eigen::MatrixXd::Constant(kSamples, kJoints, 0.01);
  EXPECT_EQ(law.set_bounds(upper, lower), MultiJointNoilcStatus::kBadBounds);  // lower above upper
  EXPECT_EQ(law.set_bounds(lower.topRows(10), upper.topRows(10)), MultiJointNoilcStatus::kBadBounds);
  ASSERT_EQ(law.set_bounds(lower, upper), MultiJointNoilcStatus::kOk);
  Eigen::MatrixXd with_nan = e_j;
  with_nan(3, 1) = std::nan("");
  EXPECT_EQ(law.solve(u_j, with_nan, out), MultiJointNoilcStatus::kNonFiniteData);
  EXPECT_EQ(out, Eigen::MatrixXd::Constant(kSamples, kJoints, 5.0));
  long allocations = 0;
  MultiJointNoilcStatus status;
  {
    testing_allocations::Counter counter;
    status = law.solve(u_j, e_j, out);  // one ADMM iteration: not converged, but feasible
    allocations = counter.allocations();
  }
  EXPECT_EQ(status, MultiJointNoilcStatus::kNotConverged);
  EXPECT_FALSE(law.last_report().converged);
  EXPECT_TRUE((out.array() >= lower.array()).all() && (out.array() <= upper.array()).all());
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace bellows
