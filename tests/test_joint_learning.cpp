// The learning of an arm of J joints as the configuration builds it (engine/config/joint_learning_factory):
// one joint is today's law on the only column, bit for bit; noilc and noilc-constrained are the
// J-joint norm-optimal update with the coupled or the independent model; the other laws run per
// joint on each joint's own model; what cannot fit is refused in one line.
#include <gtest/gtest.h>

#include <random>

#include "engine/model/arm_chain_linearization.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/learning/noilc_mimo.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

constexpr int kLearningSamples = 120;

Eigen::MatrixXd random_columns(int joints, std::mt19937& random, double scale) {
  std::normal_distribution<double> normal(0.0, scale);
  Eigen::MatrixXd m(kLearningSamples, joints);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = normal(random);
  return m;
}

Configuration arm_configuration(const char* preset, const char* law, const char* joint_model = "coupled") {
  Configuration c;
  c.arm.preset = preset;
  c.ilc.law = law;
  c.ilc.joint_model = joint_model;
  return c;
}

TEST(JointLearning, OneJointIsTheSingleJointLawBitForBit) {
  std::mt19937 random(3);
  for (const std::string& name : learning_law_names()) {
    Configuration c;
    c.ilc.law = name;
    const DiscreteArmModel model = discretize_arm_model(c.model, c.timing.sample_s());
    const auto learning = make_joint_learning(c, model, 1, kLearningSamples);
    const auto law = make_learning_law(c, model, kLearningSamples);
    ASSERT_NE(learning->single_joint_law(), nullptr);
    EXPECT_EQ(learning->name(), name);
    EXPECT_EQ(learning->joints(), 1);
    const Eigen::MatrixXd u = random_columns(1, random, 0.05), e = random_columns(1, random, 0.01);
    const Eigen::MatrixXd feedback = random_columns(1, random, 0.1);
    Eigen::MatrixXd next(kLearningSamples, 1);
    Eigen::VectorXd expected(kLearningSamples);
    learning->set_input_context(feedback, 0.4);
    law->set_input_context(feedback.col(0), 0.4);
    learning->update(u, e, next);
    law->update(u.col(0), e.col(0), expected);
    EXPECT_EQ(next.col(0), expected) << name;
  }
}

TEST(JointLearning, NoilcOfSeveralJointsIsTheJointNormOptimalUpdateWithTheChosenModel) {
  std::mt19937 random(5);
  for (const char* joint_model : {"coupled", "independent"}) {
    const Configuration c = arm_configuration("arm2", "noilc", joint_model);
    const double sample_s = c.timing.sample_s();
    const auto learning = make_joint_learning(c, discretize_arm_model(c.model, sample_s), 2, kLearningSamples);
    EXPECT_EQ(learning->joints(), 2);
    EXPECT_EQ(learning->single_joint_law(), nullptr);
    MultiJointNoilc oracle;
    ASSERT_EQ(oracle.setup(joint_learning_model(chain_preset("arm2"), joint_model, sample_s),
                           MultiJointWeights::uniform(c.ilc, 2), kLearningSamples),
              MultiJointNoilcStatus::kOk);
    const Eigen::MatrixXd u = random_columns(2, random, 0.05), e = random_columns(2, random, 0.01);
    Eigen::MatrixXd next(kLearningSamples, 2), expected(kLearningSamples, 2);
    learning->update(u, e, next);
    ASSERT_EQ(oracle.update(u, e, expected), MultiJointNoilcStatus::kOk);
    EXPECT_EQ(next, expected) << joint_model;
  }
  // The two models differ: the coupled one moves the shoulder for an error seen only at the elbow.
  const Configuration coupled = arm_configuration("arm2", "noilc", "coupled");
  const Configuration independent = arm_configuration("arm2", "noilc", "independent");
  const DiscreteArmModel model = discretize_arm_model(coupled.model, coupled.timing.sample_s());
  Eigen::MatrixXd elbow_error = Eigen::MatrixXd::Zero(kLearningSamples, 2);
  elbow_error.col(1).setConstant(0.01);
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(kLearningSamples, 2);
  Eigen::MatrixXd with_coupled(kLearningSamples, 2), with_independent(kLearningSamples, 2);
  make_joint_learning(coupled, model, 2, kLearningSamples)->update(zero, elbow_error, with_coupled);
  make_joint_learning(independent, model, 2, kLearningSamples)->update(zero, elbow_error, with_independent);
  EXPECT_EQ(with_independent.col(0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(with_coupled.col(0).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(JointLearning, ConstrainedKeepsEveryJointWithinItsReach) {
  Configuration c = arm_configuration("arm3", "noilc-constrained");
  const auto learning = make_joint_learning(c, discretize_arm_model(c.model, c.timing.sample_s()), 3, kLearningSamples);
  EXPECT_EQ(learning->name(), "noilc-constrained");
  // A large error asks for more than the pressure reach: each joint's u_pid + u_ilc stays within it.
  const Eigen::MatrixXd u = Eigen::MatrixXd::Zero(kLearningSamples, 3);
  const Eigen::MatrixXd e = Eigen::MatrixXd::Constant(kLearningSamples, 3, 0.5);
  const Eigen::MatrixXd feedback = Eigen::MatrixXd::Constant(kLearningSamples, 3, 0.1);
  const double limit_bar = c.controller.p_max_bar - c.controller.gas.ambient_bar;
  Eigen::MatrixXd next(kLearningSamples, 3);
  learning->set_input_context(feedback, limit_bar);
  learning->update(u, e, next);
  EXPECT_LE((next + feedback).cwiseAbs().maxCoeff(), limit_bar + 1e-9);
  EXPECT_GT((next + feedback).cwiseAbs().maxCoeff(), 0.9 * limit_bar) << "the bound is reached, not avoided";
}

TEST(JointLearning, OtherLawsRunPerJointOnEachJointsOwnModel) {
  std::mt19937 random(7);
  const Configuration c = arm_configuration("arm2", "pd");
  const double sample_s = c.timing.sample_s();
  const auto learning = make_joint_learning(c, discretize_arm_model(c.model, sample_s), 2, kLearningSamples);
  const std::vector<DiscreteArmModel> models = independent_joint_models(chain_preset("arm2"), sample_s);
  const Eigen::MatrixXd u = random_columns(2, random, 0.05), e = random_columns(2, random, 0.01);
  Eigen::MatrixXd next(kLearningSamples, 2);
  learning->update(u, e, next);
  for (int j = 0; j < 2; ++j) {
    const auto law = make_learning_law(c, models[static_cast<std::size_t>(j)], kLearningSamples);
    Eigen::VectorXd expected(kLearningSamples);
    law->update(u.col(j), e.col(j), expected);
    EXPECT_EQ(next.col(j), expected) << "joint " << j + 1;
  }
}

TEST(JointLearning, WhatDoesNotFitTheArmIsRefusedInOneLine) {
  const Configuration arm2 = arm_configuration("arm2", "noilc");
  const DiscreteArmModel model = discretize_arm_model(arm2.model, arm2.timing.sample_s());
  EXPECT_EQ(testing::error_of([&] { make_joint_learning(arm2, model, 3, kLearningSamples); }),
            "the trajectory has 3 joints; the arm has 2 (arm2)");
  EXPECT_EQ(testing::error_of([&] { make_joint_learning(Configuration{}, model, 2, kLearningSamples); }),
            "an arm of several joints needs [arm] preset (arm2 or arm3) or [arm] joints (2 to 4)");
  Configuration bad = arm2;
  bad.ilc.joint_model = "rigid";
  EXPECT_EQ(testing::error_of([&] { make_joint_learning(bad, model, 2, kLearningSamples); }),
            "[ilc] joint_model = 'rigid': unknown (known: coupled, independent, identified)");
  const auto learning = make_joint_learning(arm2, model, 2, kLearningSamples);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(kLearningSamples, 2), next(kLearningSamples, 2);
  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(kLearningSamples, 2);
  e(3, 1) = std::numeric_limits<double>::quiet_NaN();
  next.setConstant(7.0);
  EXPECT_THROW(learning->update(u, e, next), FaultError);
  EXPECT_EQ(next, Eigen::MatrixXd::Constant(kLearningSamples, 2, 7.0)) << "a failed update leaves the output as it was";
}

}  // namespace
}  // namespace bellows
