// The coupled model's identification (engine/operator/coupled_identification): from trials simulated with a
// known coupled model (arm2's and arm3's linearization), the output-error fit recovers that model
// from the independent joints' diagonal; the chain's linearization is the same description
// (engine/model/coupled_joint_dynamics) as the single-joint nominal model on its diagonal.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "engine/model/arm_chain_linearization.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/operator/coupled_identification.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/joint_learning_factory.hpp"

namespace bellows {
namespace {

constexpr double kTick_s = 0.005;
constexpr double kIlcSample_s = 0.02;

/// J trials of `seconds`: in trial k joint k's pressure difference sweeps a chirp (0.1 bar), every
/// other joint's wanders by a few hundredths of a bar (as a holding PID's does); the angles are
/// `truth`'s response plus measurement noise of `noise_deg`.
std::vector<JointIdentificationData> simulated_trials(const CoupledJointDynamics& truth, double seconds,
                                                      double noise_deg, unsigned seed) {
  const int J = truth.joints();
  const auto n = static_cast<Eigen::Index>(std::lround(seconds / kTick_s));
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<JointIdentificationData> trials;
  for (int k = 0; k < J; ++k) {
    JointIdentificationData t;
    t.sample_time_s = kTick_s;
    t.angle_rad = Eigen::MatrixXd::Zero(n, J);
    t.pressure_difference_bar.resize(n, J);
    std::vector<double> wander(static_cast<std::size_t>(J), 0.0);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double time = static_cast<double>(i) * kTick_s;
      for (int j = 0; j < J; ++j) {
        if (j == k) {
          const double phase = 0.2 * seconds / std::log(20.0) * (std::pow(20.0, time / seconds) - 1.0);  // 0.2 -> 4 Hz
          t.pressure_difference_bar(i, j) = 0.1 * std::sin(2.0 * std::numbers::pi * phase);
        } else {
          wander[static_cast<std::size_t>(j)] = 0.98 * wander[static_cast<std::size_t>(j)] + 0.004 * normal(random);
          t.pressure_difference_bar(i, j) = wander[static_cast<std::size_t>(j)];
        }
      }
    }
    t.angle_rad = simulate_joint_angles(truth, t);
    for (Eigen::Index i = 0; i < n; ++i) {
      for (int j = 0; j < J; ++j) t.angle_rad(i, j) += noise_deg * std::numbers::pi / 180.0 * normal(random);
    }
    trials.push_back(std::move(t));
  }
  return trials;
}

/// Each joint's single-joint model as the spec's table gives it (kappa, w0 straight, delta).
CoupledJointDynamics table_dynamics(const ChainParameters& chain) {
  std::vector<ModelParameters> joints;
  for (int i = 0; i < chain.joints; ++i) {
    const ChainLink& l = chain.links[static_cast<std::size_t>(i)];
    joints.push_back({l.kappa_rad_per_bar, l.omega0_straight_rad_per_s, l.damping_ratio});
  }
  return independent_dynamics(joints);
}

double largest_relative_entry_error(const CoupledJointDynamics& fitted, const CoupledJointDynamics& truth) {
  double worst = 0.0;
  const auto compare = [&](const JointMatrix& a, const JointMatrix& b) {
    worst = std::max(worst, (Eigen::MatrixXd(a) - Eigen::MatrixXd(b)).cwiseAbs().maxCoeff() /
                                Eigen::MatrixXd(b).cwiseAbs().maxCoeff());
  };
  compare(fitted.per_angle, truth.per_angle);
  compare(fitted.per_velocity, truth.per_velocity);
  compare(fitted.per_bar, truth.per_bar);
  return worst;
}

class CoupledIdentification : public ::testing::TestWithParam<const char*> {};

TEST_P(CoupledIdentification, RecoversTheLinearizedChainFromTheIndependentJoints) {
  const ChainParameters chain = chain_preset(GetParam());
  const CoupledJointDynamics truth = chain_dynamics(ArmChain(chain), JointVector::Zero(chain.joints));
  const std::vector<JointIdentificationData> trials = simulated_trials(truth, 12.0, 0.02, 7);
  const CoupledJointDynamics start = table_dynamics(chain);
  const MultiJointModel truth_model = discretize_joint_dynamics(truth, kIlcSample_s);
  // The independent joints are a poor model of the coupled arm: the fit has something to find.
  ASSERT_GT(markov_gap(discretize_joint_dynamics(start, kIlcSample_s), truth_model, 200), 0.1);

  const CoupledModelFit fit = fit_coupled_model(trials, start);
  EXPECT_TRUE(fit.converged);
  EXPECT_LT(largest_relative_entry_error(fit.dynamics, truth), 0.02);
  EXPECT_LT(markov_gap(discretize_joint_dynamics(fit.dynamics, kIlcSample_s), truth_model, 200), 0.01);
  EXPECT_LT(fit.rms_residual_deg, 0.03);  // down to the noise (0.02 deg)
  for (int j = 0; j < chain.joints; ++j) EXPECT_GT(fit.fit_percent(j), 90.0) << "joint " << j + 1;
  // Validated on trials it did not see (other noise, other wander of the held joints).
  const std::vector<JointIdentificationData> held_out = simulated_trials(truth, 8.0, 0.02, 99);
  const JointVector validation = joint_fit_percent(fit.dynamics, held_out);
  const JointVector independent = joint_fit_percent(start, held_out);
  for (int j = 0; j < chain.joints; ++j) {
    EXPECT_GT(validation(j), 90.0) << "joint " << j + 1;
    EXPECT_GT(validation(j), independent(j)) << "joint " << j + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(Presets, CoupledIdentification, ::testing::Values("arm2", "arm3"));

TEST(CoupledJointDynamics, TheLinearizationDiscretizesAsTheSingleJointModelOnItsDiagonal) {
  const ModelParameters paper{7.91, 14.14, 0.31};
  const MultiJointModel one =
      discretize_joint_dynamics(independent_dynamics(std::vector<ModelParameters>{paper}), kIlcSample_s);
  const DiscreteArmModel expected = discretize_arm_model(paper, kIlcSample_s);
  EXPECT_LT((Eigen::MatrixXd(one.A) - Eigen::MatrixXd(expected.A)).norm(), 1e-12);
  EXPECT_LT((Eigen::MatrixXd(one.B) - Eigen::MatrixXd(expected.B)).norm(), 1e-12);
  // The static gain of one joint is its kappa; markov_gap of a model with itself is 0.
  EXPECT_NEAR(independent_dynamics(std::vector<ModelParameters>{paper}).static_gain_rad_per_bar()(0, 0), 7.91, 1e-12);
  EXPECT_EQ(markov_gap(one, one, 50), 0.0);
  // The block-diagonal learning model and the independent dynamics are one model.
  const ChainParameters arm2 = chain_preset("arm2");
  const MultiJointModel blocks = joint_learning_model(arm2, "independent", kIlcSample_s);
  EXPECT_LT(markov_gap(discretize_joint_dynamics(table_dynamics(arm2), kIlcSample_s), blocks, 100), 1e-12);
}

TEST(CoupledJointDynamics, IdentifiedKeysCarryTheModelToTheLearning) {
  const ChainParameters arm3 = chain_preset("arm3");
  const CoupledJointDynamics linearized = chain_dynamics(ArmChain(arm3), JointVector::Zero(3));
  const IdentifiedArmParameters keys = identified_parameters(linearized);
  EXPECT_EQ(keys.joint[3].per_bar_rad_per_s2[0], 0.0);  // rows beyond the arm's joints stay empty
  EXPECT_EQ(keys.joint[1].per_angle_per_s2[2], linearized.per_angle(1, 2));
  const MultiJointModel learned = joint_learning_model(arm3, "identified", kIlcSample_s, keys);
  EXPECT_LT(markov_gap(learned, joint_learning_model(arm3, "coupled", kIlcSample_s), 200), 1e-12);
  try {
    joint_learning_model(arm3, "identified", kIlcSample_s, IdentifiedArmParameters{});
    ADD_FAILURE() << "no identified model, yet learned";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("[ilc] joint_model = 'identified': [identified_joint1] holds no identified model"),
              std::string::npos)
        << error.what();
  }
  IdentifiedArmParameters singular = keys;
  for (double& entry : singular.joint[2].per_angle_per_s2) entry = 0.0;
  EXPECT_THROW(identified_dynamics(singular, 3), InputError);
}

TEST(CoupledIdentification, RefusesDataThatCannotBeFitted) {
  const ChainParameters chain = chain_preset("arm2");
  const CoupledJointDynamics truth = chain_dynamics(ArmChain(chain), JointVector::Zero(2));
  std::vector<JointIdentificationData> trials = simulated_trials(truth, 4.0, 0.0, 3);
  std::vector<JointIdentificationData> only_first(trials.begin(), trials.begin() + 1);
  only_first[0].angle_rad.col(1).setZero();  // joint 2 never moved
  EXPECT_THROW(fit_coupled_model(only_first, truth), InputError);
  std::vector<JointIdentificationData> short_trials = trials;
  short_trials[1].angle_rad.conservativeResize(20, 2);
  short_trials[1].pressure_difference_bar.conservativeResize(20, 2);
  EXPECT_THROW(fit_coupled_model(short_trials, truth), InputError);
  trials[0].angle_rad(5, 0) = std::nan("");
  EXPECT_THROW(fit_coupled_model(trials, truth), InputError);
  const std::atomic<bool> stop{true};
  EXPECT_THROW(fit_coupled_model(simulated_trials(truth, 4.0, 0.0, 3), truth, &stop), Cancelled);
}

}  // namespace
}  // namespace bellows
