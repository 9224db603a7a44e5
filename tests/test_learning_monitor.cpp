// The observed learning diagnostics on hand-made trial records: contraction, change of correction,
// saturation, and wind-up (persistent growth of a correction the clamp throws away); with several
// joints, each joint's on its own and the arm's gathered from them.
#include <cmath>

#include <gtest/gtest.h>

#include "engine/base/errors.hpp"
#include "engine/learning/learning_monitor.hpp"

namespace bellows {
namespace {

constexpr double kLimit = 0.4;

TrialRecord record(const Eigen::VectorXd& error_rad, const Eigen::VectorXd& u_pid, const Eigen::VectorXd& u_ilc) {
  TrialRecord r;
  const int n = static_cast<int>(u_ilc.size());
  r.prepare(n, 1);
  r.joint_samples(0).error_rad.tail(n) = error_rad;
  r.joint_samples(0).u_pid_bar.head(n) = u_pid;
  r.joint_samples(0).u_ilc_bar.head(n) = u_ilc;
  r.joint_samples(0).u_total_bar.head(n) = u_pid + u_ilc;
  r.complete = true;
  return r;
}

TEST(LearningMonitor, ContractionAndCorrectionChange) {
  LearningMonitor monitor(kLimit, 4);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(4);
  const IterationDiagnostics first = monitor.observe(0, record(Eigen::VectorXd::Constant(4, 0.2), zero, zero));
  EXPECT_FALSE(first.contraction.has_value());
  EXPECT_EQ(first.correction_change_bar, 0.0);
  const IterationDiagnostics second =
      monitor.observe(1, record(Eigen::VectorXd::Constant(4, 0.05), zero, Eigen::VectorXd::Constant(4, 0.1)));
  ASSERT_TRUE(second.contraction.has_value());
  EXPECT_NEAR(*second.contraction, 0.25, 1e-12);
  EXPECT_NEAR(second.correction_change_bar, 0.1, 1e-12);
  EXPECT_EQ(monitor.history().size(), 2u);
}

TEST(LearningMonitor, ReportsWindupOnlyWhenAClampedCorrectionKeepsGrowing) {
  LearningMonitor monitor(kLimit, 3);
  const Eigen::VectorXd error = Eigen::VectorXd::Constant(3, 0.01);
  const Eigen::VectorXd pid(Eigen::Vector3d(0.3, 0.0, -0.3));
  for (int j = 0; j < 5; ++j) {
    // Sample 0 is pushed ever further beyond +limit; sample 2 sits beyond -limit but stays put.
    const Eigen::VectorXd ilc(Eigen::Vector3d(0.2 + 0.05 * j, 0.1, -0.2));
    const IterationDiagnostics d = monitor.observe(j, record(error, pid, ilc));
    EXPECT_EQ(d.saturated_samples, 2);
    EXPECT_NEAR(d.clamped_excess_bar, 0.1 + 0.05 * j, 1e-12);
    EXPECT_EQ(d.windup_samples, j == 0 ? 0 : 1);
    EXPECT_EQ(monitor.windup().detected, j >= 3) << "iteration " << j;  // three trials in a row
  }
  EXPECT_EQ(*monitor.windup().first_iteration, 1);
  EXPECT_EQ(monitor.windup().iterations_with_windup, 4);
  EXPECT_NEAR(monitor.windup().max_clamped_excess_bar, 0.3, 1e-12);
}

TEST(LearningMonitor, JitterAtTheLimitIsNotWindup) {
  LearningMonitor monitor(kLimit, 2);
  const Eigen::VectorXd error = Eigen::VectorXd::Constant(2, 0.01);
  for (int j = 0; j < 6; ++j) {
    // The correction grows but the clamp discards less than the 5 mbar threshold.
    const Eigen::VectorXd ilc = Eigen::VectorXd::Constant(2, 0.398 + 0.001 * j);
    const IterationDiagnostics d = monitor.observe(j, record(error, Eigen::VectorXd::Zero(2), ilc));
    EXPECT_EQ(d.windup_samples, 0);
  }
  EXPECT_FALSE(monitor.windup().detected);
  EXPECT_GT(monitor.windup().max_clamped_excess_bar, 0.0);
}

/// A trial of two joints: joint j's error, feedback and correction from column j.
TrialRecord two_joint_record(const Eigen::MatrixXd& error_rad, const Eigen::MatrixXd& u_pid,
                             const Eigen::MatrixXd& u_ilc) {
  TrialRecord r;
  const int n = static_cast<int>(u_ilc.rows());
  r.prepare(n, 1, 2);
  for (int j = 0; j < 2; ++j) {
    r.joint_samples(j).error_rad.tail(n) = error_rad.col(j);
    r.joint_samples(j).u_pid_bar.head(n) = u_pid.col(j);
    r.joint_samples(j).u_ilc_bar.head(n) = u_ilc.col(j);
    r.joint_samples(j).u_total_bar.head(n) = u_pid.col(j) + u_ilc.col(j);
  }
  r.complete = true;
  return r;
}

TEST(LearningMonitor, EachJointIsWatchedOnItsOwnAndTheArmGathersThem) {
  constexpr int kSamples = 3;
  LearningMonitor monitor(kLimit, kSamples, 2);
  Eigen::MatrixXd pid = Eigen::MatrixXd::Zero(kSamples, 2);
  pid(0, 1) = 0.3;  // the elbow's sample 0 sits near the limit
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::MatrixXd error(kSamples, 2), ilc = Eigen::MatrixXd::Zero(kSamples, 2);
    error.col(0).setConstant(0.04 / (trial + 1));  // the shoulder learns
    error.col(1).setConstant(0.01);
    ilc(0, 1) = 0.2 + 0.05 * trial;  // the elbow's correction grows into the clamp
    ilc(1, 0) = 0.01 * trial;        // the shoulder's stays well inside it
    const IterationDiagnostics d = monitor.observe(trial, two_joint_record(error, pid, ilc));
    ASSERT_EQ(d.joints.size(), 2u);
    EXPECT_EQ(d.joints[0].saturated_samples, 0);
    EXPECT_EQ(d.joints[1].saturated_samples, 1);
    EXPECT_EQ(d.saturated_samples, 1) << "the arm's: every joint's samples";
    EXPECT_EQ(d.joints[1].windup_samples, trial == 0 ? 0 : 1);
    EXPECT_EQ(d.windup_samples, d.joints[1].windup_samples);
    EXPECT_NEAR(d.clamped_excess_bar, 0.1 + 0.05 * trial, 1e-12);
    if (trial > 0) {
      ASSERT_TRUE(d.joints[0].contraction && d.joints[1].contraction && d.contraction);
      EXPECT_NEAR(*d.joints[0].contraction, static_cast<double>(trial) / (trial + 1), 1e-12);
      EXPECT_NEAR(*d.joints[1].contraction, 1.0, 1e-12);
      // The arm's: the error over both joints, not either joint's.
      const double now = std::hypot(0.04 / (trial + 1), 0.01), before = std::hypot(0.04 / trial, 0.01);
      EXPECT_NEAR(*d.contraction, now / before, 1e-12);
      EXPECT_NEAR(d.joints[0].correction_change_bar, 0.01 / std::sqrt(3.0), 1e-12);
      EXPECT_NEAR(d.joints[1].correction_change_bar, 0.05 / std::sqrt(3.0), 1e-12);
      EXPECT_NEAR(d.correction_change_bar, std::sqrt((0.01 * 0.01 + 0.05 * 0.05) / 6.0), 1e-12);
    }
    EXPECT_EQ(monitor.windup().detected, trial >= 3) << "trial " << trial;
  }
  const WindupSummary& w = monitor.windup();
  ASSERT_EQ(w.joints.size(), 2u);
  EXPECT_FALSE(w.joints[0].detected) << "the shoulder never reached the clamp";
  EXPECT_EQ(w.joints[0].iterations_with_windup, 0);
  EXPECT_EQ(w.joints[0].max_clamped_excess_bar, 0.0);
  EXPECT_TRUE(w.joints[1].detected);
  EXPECT_EQ(*w.joints[1].first_iteration, 1);
  EXPECT_EQ(*w.first_iteration, 1);
  EXPECT_EQ(w.iterations_with_windup, 4);
  EXPECT_NEAR(w.max_clamped_excess_bar, 0.3, 1e-12);
  EXPECT_TRUE(monitor.history().front().joints.size() == 2u);
}

TEST(LearningMonitor, OneJointHasNoPerJointEntries) {
  LearningMonitor monitor(kLimit, 2);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2);
  EXPECT_TRUE(monitor.observe(0, record(zero, zero, zero)).joints.empty());
  EXPECT_TRUE(monitor.windup().joints.empty());
}

TEST(LearningMonitor, RejectsMismatchedTrials) {
  EXPECT_THROW(LearningMonitor(0.0, 3), InputError);
  LearningMonitor monitor(kLimit, 3);
  const Eigen::VectorXd four = Eigen::VectorXd::Zero(4);
  EXPECT_THROW(monitor.observe(0, record(four, four, four)), InputError);
  LearningMonitor two_joints(kLimit, 4, 2);
  EXPECT_THROW(two_joints.observe(0, record(four, four, four)), InputError) << "one joint's trial for an arm of two";
  EXPECT_THROW(LearningMonitor(kLimit, 3, 0), InputError);
}

}  // namespace
}  // namespace bellows
