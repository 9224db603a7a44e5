// The observed learning diagnostics on hand-made trial records: contraction, change of correction,
// saturation, and wind-up (persistent growth of a correction the clamp throws away).
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

TEST(LearningMonitor, RejectsMismatchedTrials) {
  EXPECT_THROW(LearningMonitor(0.0, 3), InputError);
  LearningMonitor monitor(kLimit, 3);
  const Eigen::VectorXd four = Eigen::VectorXd::Zero(4);
  EXPECT_THROW(monitor.observe(0, record(four, four, four)), InputError);
}

}  // namespace
}  // namespace bellows
