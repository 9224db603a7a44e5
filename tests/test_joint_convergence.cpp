// Convergence prediction for arms of several joints (issue 26): the lifted operator's largest
// singular value, checked against a dense SVD, against learning on the arm's linear coupled closed
// loop (a law predicted to contract does, one predicted to diverge does, by no more than predicted
// per trial), and the per-joint figures: each joint's rows, its share of the slowest direction, and
// for laws per joint each joint's one-joint prediction on its own model.
#include <cmath>

#include <gtest/gtest.h>

#include "engine/config/joint_convergence.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/learning/closed_loop_model.hpp"
#include "engine/model/arm_chain.hpp"
#include "engine/model/arm_chain_linearization.hpp"

namespace bellows {
namespace {

constexpr int kSamples = 60;  // short trials: the dense checks stay cheap, the band still spans the loop

Configuration arm2(const std::string& law = "noilc") {
  Configuration config;
  config.arm.preset = "arm2";
  config.ilc.law = law;
  config.ilc.prediction_grid_points = 1;
  return config;
}

std::unique_ptr<JointLearning> law_of(const Configuration& config) {
  return make_joint_learning(config, discretize_arm_model(config.model, config.timing.sample_s()), 2, kSamples);
}

/// The arm's linear coupled closed loop, built here from its parts: the chain linearized stretched
/// out behind each joint's pressure lag and PID.
StateSpaceModel coupled_loop(const Configuration& config) {
  const double T = config.timing.sample_s();
  const MultiJointModel arm = linearize_chain(ArmChain(chain_of(config.arm)), JointVector::Zero(2), T);
  return closed_loop_model(closed_loop_prior(arm.A, arm.B, T, config.model.volume_gain_per_rad, config.controller),
                           CorrectionShape{0, {}}, Eigen::MatrixXd());
}

/// Trials on the linear loop from the feedback-only error `e0`: the norm of every change of the
/// correction, ||u_{k+1} - u_k|| (the change contracts by M each trial).
std::vector<double> correction_changes(const Configuration& config, int trials) {
  const StateSpaceModel loop = coupled_loop(config);
  const auto law = law_of(config);
  Eigen::MatrixXd e0(kSamples, 2);
  for (int t = 0; t < kSamples; ++t) e0.row(t) << std::sin(0.2 * t), 0.5 * std::cos(0.07 * t);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(kSamples, 2), next(kSamples, 2);
  std::vector<double> changes;
  for (int k = 0; k < trials; ++k) {
    law->update(u, e0 - loop.simulate(u), next);
    changes.push_back((next - u).norm());
    u = next;
  }
  return changes;
}

TEST(JointConvergence, ThePredictionIsTheLiftedOperatorsLargestSingularValue) {
  const Configuration config = arm2();
  const JointConvergencePrediction p = predict_joint_convergence(config, 2, kSamples);
  ASSERT_TRUE(p.arm.available);
  EXPECT_TRUE(p.learned_together);
  const auto law = law_of(config);
  const Eigen::MatrixXd m = lifted_learning_operator(*law, config, 1.0, 1.0, kSamples);
  ASSERT_EQ(m.rows(), 2 * kSamples);
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(m);
  EXPECT_NEAR(p.arm.nominal.contraction, svd.singularValues()(0), 1e-6 * svd.singularValues()(0));
  EXPECT_LT(p.arm.nominal.contraction, 1.0) << "the default law contracts on the arm it models";
  EXPECT_GT(p.arm.nominal.contraction, 0.5);
  // Per joint: its rows' gain, at most the arm's; the shares of the slowest direction add up to 1.
  ASSERT_EQ(p.joints.size(), 2u);
  double shares = 0.0;
  for (int j = 0; j < 2; ++j) {
    const Eigen::BDCSVD<Eigen::MatrixXd> rows(m.middleRows(j * kSamples, kSamples));
    EXPECT_NEAR(p.joints[j].contraction, rows.singularValues()(0), 1e-6) << "joint " << j + 1;
    EXPECT_LE(p.joints[j].contraction, p.arm.nominal.contraction + 1e-9);
    EXPECT_FALSE(p.joints[j].own.available) << "a law of the whole arm has no per-joint law";
    shares += p.joints[j].slowest_direction_share;
  }
  EXPECT_NEAR(shares, 1.0, 1e-9);
  EXPECT_GE(p.arm.nominal.worst_frequency_hz, p.arm.band_low_hz);
  EXPECT_LE(p.arm.nominal.worst_frequency_hz, p.arm.band_high_hz);
  EXPECT_TRUE(p.arm.warning.empty()) << p.arm.warning;
}

TEST(JointConvergence, ALawPredictedToContractDoesSoOnTheCoupledLoopByNoLessThanPredicted) {
  const Configuration config = arm2();
  const double c = predict_joint_convergence(config, 2, kSamples).arm.nominal.contraction;
  const std::vector<double> changes = correction_changes(config, 40);
  for (std::size_t k = 1; k < changes.size(); ++k)
    EXPECT_LE(changes[k], c * changes[k - 1] * (1.0 + 1e-9) + 1e-15) << "trial " << k;
  EXPECT_LT(changes.back(), 0.5 * changes.front());
}

// Each joint's PD law with a derivative learning gain far too high (the default is 0.01 s).
Configuration aggressive_pd() {
  Configuration config = arm2("pd");
  config.ilc.pd_kp = 0.5;
  config.ilc.pd_kd_s = 0.2;
  config.ilc.pd_q_cutoff_hz = 5.0;
  return config;
}

TEST(JointConvergence, ALawPredictedToDivergeDivergesOnTheCoupledLoop) {
  const Configuration config = aggressive_pd();
  const JointConvergencePrediction p = predict_joint_convergence(config, 2, kSamples);
  ASSERT_TRUE(p.arm.available);
  EXPECT_FALSE(p.learned_together);
  EXPECT_GT(p.arm.nominal.contraction, 1.0 + kDivergenceTolerance);
  EXPECT_NE(p.arm.warning.find("predicted to diverge"), std::string::npos) << p.arm.warning;
  const std::vector<double> changes = correction_changes(config, 60);
  for (std::size_t k = 1; k < changes.size(); ++k)
    EXPECT_LE(changes[k], p.arm.nominal.contraction * changes[k - 1] * (1.0 + 1e-9)) << "trial " << k;
  EXPECT_GT(changes.back(), 10.0 * changes.front()) << "it blows up";
}

TEST(JointConvergence, LawsPerJointAlsoGetEachJointsOwnPrediction) {
  const Configuration config = arm2("pd");
  const JointConvergencePrediction p = predict_joint_convergence(config, 2, kSamples);
  ASSERT_TRUE(p.arm.available);
  const std::vector<ModelParameters> models = independent_joint_parameters(chain_of(config.arm));
  for (std::size_t j = 0; j < 2; ++j) {
    ASSERT_TRUE(p.joints[j].own.available) << "joint " << j + 1;
    Configuration own = config;
    own.model = models[j];
    own.model.volume_gain_per_rad = config.model.volume_gain_per_rad;
    const auto law = make_learning_law(own, discretize_arm_model(own.model, own.timing.sample_s()), kSamples);
    EXPECT_EQ(p.joints[j].own.nominal.contraction, predict_convergence(*law, own, kSamples).nominal.contraction);
  }
  EXPECT_NE(p.joints[0].own.nominal.contraction, p.joints[1].own.nominal.contraction) << "each joint its own model";
}

TEST(JointConvergence, TheGridScalesEveryJointAndConstrainedIsPredictedAsItsUnboundedLaw) {
  Configuration config = arm2("noilc-constrained");
  config.ilc.prediction_grid_points = 3;
  const JointConvergencePrediction constrained = predict_joint_convergence(config, 2, kSamples);
  config.ilc.law = "noilc";
  const JointConvergencePrediction plain = predict_joint_convergence(config, 2, kSamples);
  ASSERT_TRUE(constrained.arm.available);
  EXPECT_NEAR(constrained.arm.nominal.contraction, plain.arm.nominal.contraction, 1e-12);
  ASSERT_EQ(plain.arm.grid.size(), 9u);
  EXPECT_EQ(plain.arm.grid[4].kappa_scale, 1.0);
  EXPECT_NEAR(plain.arm.grid[4].contraction, plain.arm.nominal.contraction, 1e-6) << "the grid's centre is nominal";
  EXPECT_NEAR(plain.arm.grid[0].kappa_scale, 1.0 - config.ilc.prediction_model_error, 1e-12);
  EXPECT_GE(plain.arm.worst.contraction, plain.arm.nominal.contraction);
  bool differs = false;
  for (const ContractionEstimate& e : plain.arm.grid)
    differs = differs || std::abs(e.contraction - plain.arm.nominal.contraction) > 1e-6;
  EXPECT_TRUE(differs) << "another arm learns at another rate";
}

TEST(JointConvergence, AModelLearningLawHasNoPredictionAndAStopIsHeard) {
  const JointConvergencePrediction learned = predict_joint_convergence(arm2("noilc-learned"), 2, kSamples);
  EXPECT_FALSE(learned.arm.available);
  EXPECT_EQ(learned.joints.size(), 2u);
  std::atomic<bool> stop{true};
  EXPECT_THROW(predict_joint_convergence(arm2(), 2, kSamples, &stop), Cancelled);
}

}  // namespace
}  // namespace bellows
