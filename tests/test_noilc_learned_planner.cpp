// noilc-learned's planner (engine/learning/noilc_learned): which model plans the next update, and what
// the update acts on, for one joint and for several.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "engine/config/configuration.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/learning/closed_loop_model.hpp"
#include "engine/learning/noilc_learned.hpp"
#include "engine/learning/noilc_state_space.hpp"
#include "engine/model/arm_chain_parameters.hpp"
#include "tests/test_support.hpp"

namespace bellows {
// Named, not anonymous: the unity build shares a translation unit with test_noilc_learned.cpp.
namespace learned_planner_test {

Eigen::MatrixXd random_matrix(int rows, int cols, double sigma, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::MatrixXd m(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) m(i, j) = normal(random);
  return m;
}

ClosedLoopPrior paper_prior() {
  const Configuration config;
  const DiscreteArmModel model = testing::paper_model();
  return closed_loop_prior(model.A, model.B, model.sample_time_s, config.model.volume_gain_per_rad, config.controller);
}

ClosedLoopPrior arm2_prior() {
  const Configuration config;
  const double T = config.timing.sample_s();
  const MultiJointModel m = joint_learning_model(chain_preset("arm2"), "coupled", T);
  return closed_loop_prior(m.A, m.B, T, config.model.volume_gain_per_rad, config.controller);
}

// The plan of the prior alone from (u, e): what the law must produce when the prior plans.
Eigen::MatrixXd prior_plan(const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings, const Eigen::MatrixXd& u,
                           const Eigen::MatrixXd& e) {
  StateSpaceNoilc solver;
  solver.setup(closed_loop_model(prior, CorrectionShape{0, {}}, {}), settings.weights, static_cast<int>(u.rows()));
  Eigen::MatrixXd u_next(u.rows(), u.cols());
  solver.solve(u, e, u_next);
  return u_next;
}

// A plant that is the prior plus a correction inside the refit's class: the refit learns it.
Eigen::MatrixXd in_class_truth(const CorrectionShape& shape, int joints) {
  const int p = shape.per_joint(), q = p * (joints > 1 ? joints : 1);
  Eigen::MatrixXd truth = Eigen::MatrixXd::Zero(q, joints);
  truth(0, 0) = 0.02;
  truth(p - 1, 0) = -0.04;
  if (joints > 1) {
    truth(p, 0) = 0.015;  // joint 1's output from joint 2's input
    truth(1, 1) = -0.02;  // joint 2's output from joint 1's input
  }
  return truth;
}

struct PlannedTrials {
  std::vector<bool> prior_plans;           // per update
  double largest_gap_to_prior_plan = 0.0;  // max over the updates of ||u_next - prior's plan||
};

PlannedTrials run(const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings, int trials) {
  const int n = 250, J = prior.joints();
  const StateSpaceModel plant = closed_loop_model(prior, settings.shape, in_class_truth(settings.shape, J));
  const Eigen::MatrixXd reference = 0.3 * random_matrix(n, J, 1.0, 11);
  LearnedModelNoilc law(prior, settings, n);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, J), u_next(n, J);
  PlannedTrials out;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::MatrixXd e = reference - plant.simulate(u);
    law.update(u, e, u_next);
    out.prior_plans.push_back(law.last_report().prior_plans);
    // Every trial here descends (the plant is linear and noise-free): each update is planned from it.
    EXPECT_FALSE(law.last_report().no_descent || law.last_report().fell_back) << "trial " << trial;
    out.largest_gap_to_prior_plan =
        std::max(out.largest_gap_to_prior_plan, (u_next - prior_plan(prior, settings, u, e)).norm() / u_next.norm());
    u = u_next;
  }
  return out;
}

// One joint: once the refit has predicted a trial better than the prior, it plans (unchanged by the
// several-joint keys).
TEST(NoilcLearnedPlanner, OneJointTheRefitPlansOnceItPredictsBetter) {
  LearnedNoilcSettings settings;
  settings.relative_ridge = 1e-9;
  const PlannedTrials planned = run(paper_prior(), settings, 4);
  EXPECT_FALSE(planned.prior_plans.back());
  EXPECT_GT(planned.largest_gap_to_prior_plan, 1e-3);  // the refit's plans are not the prior's
  settings.joints_refit_plans = true;
  settings.joints_zero_limited_errors = true;
  const PlannedTrials same = run(paper_prior(), settings, 4);
  EXPECT_EQ(same.prior_plans, planned.prior_plans);
  EXPECT_EQ(same.largest_gap_to_prior_plan, planned.largest_gap_to_prior_plan);
}

// Several joints: the prior plans every update by default, even after the refit has learned a plant it
// predicts better; with joints_refit_plans the refit plans as it does for one joint.
TEST(NoilcLearnedPlanner, SeveralJointsThePriorPlansEveryUpdateUnlessTheRefitMay) {
  LearnedNoilcSettings settings;
  settings.relative_ridge = 1e-9;
  const PlannedTrials by_default = run(arm2_prior(), settings, 4);
  for (const bool p : by_default.prior_plans) EXPECT_TRUE(p);
  EXPECT_LT(by_default.largest_gap_to_prior_plan, 1e-12);
  settings.joints_refit_plans = true;
  const PlannedTrials refit_may = run(arm2_prior(), settings, 4);
  EXPECT_FALSE(refit_may.prior_plans.back());
  EXPECT_GT(refit_may.largest_gap_to_prior_plan, 1e-3);
}

// The update on a trial whose set point reached the pressure limit: one joint zeroes the limit-shaped
// errors (as noilc-constrained does); several joints act on them unless joints_zero_limited_errors.
TEST(NoilcLearnedPlanner, SeveralJointsTheUpdateActsOnTheLimitShapedErrors) {
  const auto first_update = [](const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings,
                               const Eigen::MatrixXd& e) {
    const int n = static_cast<int>(e.rows()), J = prior.joints();
    LearnedModelNoilc law(prior, settings, n);
    Eigen::MatrixXd feedback = Eigen::MatrixXd::Zero(n, J);
    feedback(40, 0) = 5.0;  // far above the limit below
    law.set_input_context(feedback, 1.0);
    Eigen::MatrixXd u_next(n, J);
    law.update(Eigen::MatrixXd::Zero(n, J), e, u_next);
    return u_next;
  };
  const int n = 200;
  const LearnedNoilcSettings settings;
  for (const ClosedLoopPrior& prior : {paper_prior(), arm2_prior()}) {
    const int J = prior.joints();
    const int recovery = static_cast<int>(std::lround(settings.limit_recovery_s / prior.sample_time_s));
    const Eigen::MatrixXd e = 0.3 * random_matrix(n, J, 1.0, 5);
    Eigen::MatrixXd zeroed = e;
    zeroed.block(40, 0, recovery, 1).setZero();
    const Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, J);
    const Eigen::MatrixXd acts_on = prior_plan(prior, settings, u, e), ignores = prior_plan(prior, settings, u, zeroed);
    ASSERT_GT((acts_on - ignores).norm(), 1e-3 * acts_on.norm());
    const Eigen::MatrixXd by_default = first_update(prior, LearnedNoilcSettings{}, e);
    LearnedNoilcSettings zero_limited;
    zero_limited.joints_zero_limited_errors = true;
    const Eigen::MatrixXd zeroing = first_update(prior, zero_limited, e);
    EXPECT_LT((zeroing - ignores).norm(), 1e-9 * ignores.norm()) << J << " joints";
    EXPECT_LT((by_default - (J == 1 ? ignores : acts_on)).norm(), 1e-9 * acts_on.norm()) << J << " joints";
  }
}

// A second trial whose cost is 3 % above the first's: several joints count it as a descent (within the
// default slack of 5 %) and plan the next update from it with the whole step; with no slack, and for one
// joint whatever the slack, it is a no-descent: the update starts again from the best (first) trial
// with half the step.
TEST(NoilcLearnedPlanner, SeveralJointsATrialWithinTheSlackOfTheBestIsPlannedFrom) {
  const int n = 200;
  struct Second {
    LearnedNoilcReport report;
    Eigen::MatrixXd u1, e1, u_next;
  };
  const auto second_update = [&](const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings,
                                 const Eigen::MatrixXd& e0) {
    const int J = prior.joints();
    LearnedModelNoilc law(prior, settings, n);
    Second out;
    out.u1.resize(n, J);
    out.u_next.resize(n, J);
    law.update(Eigen::MatrixXd::Zero(n, J), e0, out.u1);
    out.e1 = random_matrix(n, J, 1.0, 9);
    out.e1 *= std::sqrt(1.03) * e0.norm() / out.e1.norm();
    law.update(out.u1, out.e1, out.u_next);
    out.report = law.last_report();
    return out;
  };
  for (const ClosedLoopPrior& prior : {arm2_prior(), paper_prior()}) {
    const int J = prior.joints();
    const Eigen::MatrixXd e0 = 0.3 * random_matrix(n, J, 1.0, 5), u0 = Eigen::MatrixXd::Zero(n, J);
    const LearnedNoilcSettings by_default;
    ASSERT_DOUBLE_EQ(by_default.joints_descent_slack, 0.05);
    const Second slack = second_update(prior, by_default, e0);
    LearnedNoilcSettings none;
    none.joints_descent_slack = 0.0;
    const Second strict = second_update(prior, none, e0);
    EXPECT_TRUE(strict.report.no_descent) << J << " joints";
    EXPECT_FALSE(strict.report.within_slack) << J << " joints";
    if (J == 1) {  // one joint ignores the slack: the same update as without it
      EXPECT_TRUE(slack.report.no_descent);
      EXPECT_FALSE(slack.report.within_slack);
      EXPECT_EQ(slack.u_next, strict.u_next);
      continue;
    }
    EXPECT_FALSE(slack.report.no_descent);
    EXPECT_TRUE(slack.report.within_slack);
    EXPECT_DOUBLE_EQ(slack.report.step, 1.0);
    const Eigen::MatrixXd from_the_trial = prior_plan(prior, by_default, slack.u1, slack.e1);
    EXPECT_LT((slack.u_next - from_the_trial).norm(), 1e-9 * from_the_trial.norm());
    const Eigen::MatrixXd half_from_the_best = 0.5 * prior_plan(prior, none, u0, e0);
    EXPECT_LT((strict.u_next - half_from_the_best).norm(), 1e-9 * half_from_the_best.norm());
    EXPECT_DOUBLE_EQ(strict.report.step, 0.5);
  }
  LearnedNoilcSettings beyond_the_guard;
  beyond_the_guard.joints_descent_slack = beyond_the_guard.guard + 0.01;
  EXPECT_THROW(LearnedModelNoilc(arm2_prior(), beyond_the_guard, n), InputError);
}

}  // namespace learned_planner_test
}  // namespace bellows
