// The J-joint arm linearized at a pose (engine/model/arm_chain_linearization): with one joint it is the
// single-joint nominal model; for arm2 and arm3 it predicts the simulated chain's small motions.
#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "engine/model/arm_chain_linearization.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

constexpr double kLinearizationSampleTime_s = 0.02;

TEST(ArmChainLinearization, OneJointWithoutGravityIsTheSingleJointNominalModel) {
  ChainParameters chain;
  chain.joints = 1;
  chain.gravity = false;
  chain.links[0] = chain_preset("arm2").links[1];  // the elbow: the paper's arm, M_11(0) = K / w0^2 up to rounding
  ChainLink& l = chain.links[0];
  l.inertia_kg_m2 = l.stiffness_Nm_per_rad / (l.omega0_straight_rad_per_s * l.omega0_straight_rad_per_s) -
                    l.mass_kg * l.center_of_mass_m * l.center_of_mass_m;  // exactly K / w0^2
  const ArmChain arm(chain);
  ModelParameters nominal;
  nominal.kappa_rad_per_bar = l.kappa_rad_per_bar;
  nominal.omega0_rad_per_s = l.omega0_straight_rad_per_s;
  nominal.damping = l.damping_ratio;
  const DiscreteArmModel expected = discretize_arm_model(nominal, kLinearizationSampleTime_s);
  for (double pose : {0.0, 0.7}) {  // without gravity the pose does not matter for one joint
    const MultiJointModel model = linearize_chain(arm, JointVector::Constant(1, pose), kLinearizationSampleTime_s);
    EXPECT_LT((Eigen::MatrixXd(model.A) - Eigen::MatrixXd(expected.A)).norm(), 1e-12);
    EXPECT_LT((Eigen::MatrixXd(model.B) - Eigen::MatrixXd(expected.B)).norm(), 1e-12);
    EXPECT_LT((Eigen::MatrixXd(model.C) - Eigen::MatrixXd(expected.C)).norm(), 1e-15);
    EXPECT_EQ(model.sample_time_s, kLinearizationSampleTime_s);
  }
}

/// Simulates the chain (creep off: the linear model leaves it out) from rest at `pose`, held, then
/// a small step `delta_bar` on top of the holding pressure; compares the angle deviations (/ pi)
/// with the linear model's prediction sample by sample. Returns max |difference| / max |response|.
double step_response_mismatch(const char* preset, const JointVector& pose, const JointVector& delta_bar, int samples) {
  ChainParameters chain = chain_preset(preset);
  for (ChainLink& l : chain.links) l.creep_gain = 0.0;
  ArmChain arm(chain);
  ArmChain::State start = arm.state();
  start.angle_rad = pose;
  arm.set_state(start);
  const MultiJointModel model = linearize_chain(arm, pose, kLinearizationSampleTime_s);
  const JointVector input = arm.holding_pressure_bar(pose) + delta_bar;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * arm.joints());
  double largest_response = 0.0, largest_difference = 0.0;
  for (int t = 0; t < samples; ++t) {
    arm.advance(kLinearizationSampleTime_s, input);
    x = model.A * x + model.B * Eigen::VectorXd(delta_bar);
    const Eigen::VectorXd simulated = Eigen::VectorXd(arm.state().angle_rad - pose) / std::numbers::pi;
    const Eigen::VectorXd predicted = model.C * x;
    largest_response = std::max(largest_response, simulated.cwiseAbs().maxCoeff());
    largest_difference = std::max(largest_difference, (simulated - predicted).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest_response, 1e-4);  // it moved
  testing::Test::RecordProperty(std::string(preset) + "_mismatch",
                                std::to_string(largest_difference / largest_response));
  return largest_difference / largest_response;
}

TEST(ArmChainLinearization, PredictsSmallMotionsOfTheSimulatedArm) {
  // 1 mbar steps (about 0.5 deg) for one second: the linear model is within 1 % of the response.
  EXPECT_LT(step_response_mismatch("arm2", JointVector::Zero(2), JointVector::Constant(2, 0.001), 50), 0.01);
  JointVector pose2(2), step2(2);
  pose2 << 0.4, -0.6;
  step2 << -0.001, 0.0015;
  EXPECT_LT(step_response_mismatch("arm2", pose2, step2, 50), 0.01);
  JointVector pose3(3), step3(3);
  pose3 << -0.3, 0.5, 0.9;
  step3 << 0.001, -0.001, 0.001;
  EXPECT_LT(step_response_mismatch("arm3", pose3, step3, 50), 0.01);
}

TEST(ArmChainLinearization, TheChainIsCoupledAndGravityStiffensOrSoftensWithThePose) {
  const ArmChain arm(chain_preset("arm2"));
  const MultiJointModel straight = linearize_chain(arm, JointVector::Zero(2), kLinearizationSampleTime_s);
  // The elbow's pressure moves the shoulder (inertia coupling): off-diagonal blocks of B are not zero.
  EXPECT_GT(std::abs(straight.B(1, 1)), 0.01 * std::abs(straight.B(1, 0)));
  EXPECT_GT(std::abs(straight.B(3, 0)), 0.01 * std::abs(straight.B(3, 1)));
  // Gravity's torque on the shoulder is largest stretched out (dG/dq = 0 there); hanging down it pulls
  // back toward the vertical (a stiffening), pointing up it pushes away (a softening). The linear
  // model sees it in A: the shoulder's acceleration per radian of its own angle.
  Eigen::MatrixXd Ac_straight, Bc, Ac_down, Ac_up;
  continuous_chain_model(arm, JointVector::Zero(2), Ac_straight, Bc);
  JointVector down(2), up(2);
  down << -std::numbers::pi / 2, 0.0;
  up << std::numbers::pi / 2, 0.0;
  continuous_chain_model(arm, down, Ac_down, Bc);
  continuous_chain_model(arm, up, Ac_up, Bc);
  EXPECT_LT(Ac_down(1, 0), Ac_straight(1, 0) - 0.05 * std::abs(Ac_straight(1, 0)));
  EXPECT_GT(Ac_up(1, 0), Ac_straight(1, 0) + 0.05 * std::abs(Ac_straight(1, 0)));
  EXPECT_THROW(linearize_chain(arm, JointVector::Zero(3), kLinearizationSampleTime_s), InputError);
  EXPECT_THROW(linearize_chain(arm, JointVector::Zero(2), 0.0), InputError);
}

}  // namespace
}  // namespace bellows
