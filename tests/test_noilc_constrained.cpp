// Constraint-aware norm-optimal ILC: the update is the bounded optimum of the paper's cost (checked
// by the KKT conditions against the dense gradient), equals the unconstrained law when no bound is
// active, always returns a feasible correction, leaves out the errors the pressure limit shaped, and
// on the paper scenario does not wind up and tracks no worse than the unconstrained law.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/learning/learning_monitor.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/noilc_constrained.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/learning/noilc_riccati.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::paper_model;

struct RandomProblem {
  Eigen::VectorXd u_j, e_j;
};

RandomProblem random_problem(int samples, std::mt19937& random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  RandomProblem p{Eigen::VectorXd(samples), Eigen::VectorXd(samples)};
  // Smooth-ish error with large excursions, so that the free optimum leaves any moderate box.
  double drift = 0.0;
  for (int t = 0; t < samples; ++t) {
    drift = 0.9 * drift + 0.1 * normal(random);
    p.e_j(t) = drift;
    p.u_j(t) = 0.05 * normal(random);
  }
  return p;
}

// KKT for min J(u) s.t. lower <= u <= upper: g = grad J(u) is ~0 where u is strictly inside,
// g >= 0 on the lower bound and g <= 0 on the upper bound.
void expect_kkt(const NormOptimalDense& dense, const RandomProblem& p, const Eigen::VectorXd& lower,
                const Eigen::VectorXd& upper, const Eigen::VectorXd& u, double tolerance) {
  const Eigen::VectorXd g = dense.cost_gradient(p.u_j, p.e_j, u);
  int active = 0;
  for (Eigen::Index t = 0; t < u.size(); ++t) {
    ASSERT_GE(u(t), lower(t));
    ASSERT_LE(u(t), upper(t));
    const bool at_lower = u(t) <= lower(t) + 1e-9, at_upper = u(t) >= upper(t) - 1e-9;
    if (at_lower || at_upper) ++active;
    if (at_lower) EXPECT_GE(g(t), -tolerance) << "sample " << t;
    else if (at_upper) EXPECT_LE(g(t), tolerance) << "sample " << t;
    else EXPECT_NEAR(g(t), 0.0, tolerance) << "sample " << t;
  }
  EXPECT_GT(active, 0) << "the test problem should have active bounds";
}

TEST(NoilcConstrained, UpdateIsTheBoundedOptimum) {
  std::mt19937 random(5);
  IlcParameters parameters;
  parameters.admm_tolerance = 1e-10;
  parameters.admm_max_iterations = 20000;
  for (int samples : {20, 120, 400}) {
    const RandomProblem p = random_problem(samples, random);
    NormOptimalDense dense(paper_model(), parameters, samples);
    NormOptimalConstrained constrained(paper_model(), parameters, samples);
    Eigen::VectorXd free(samples);
    dense.update(p.u_j, p.e_j, free);
    const double reach = 0.5 * free.cwiseAbs().maxCoeff();
    const Eigen::VectorXd lower = Eigen::VectorXd::Constant(samples, -reach);
    const Eigen::VectorXd upper = Eigen::VectorXd::Constant(samples, reach).array() -
                                  0.1 * reach * (Eigen::ArrayXd::LinSpaced(samples, 0.0, 1.0));
    constrained.set_bounds(lower, upper);
    Eigen::VectorXd u(samples);
    constrained.update(p.u_j, p.e_j, u);
    EXPECT_TRUE(constrained.last_report().converged);
    EXPECT_GT(constrained.last_report().admm_iterations, 0);
    expect_kkt(dense, p, lower, upper, u, 1e-7 * (1.0 + dense.cost_gradient(p.u_j, p.e_j, p.u_j).norm()));
  }
}

TEST(NoilcConstrained, EqualsUnconstrainedWhenNoBoundIsActive) {
  std::mt19937 random(9);
  const int samples = 300;
  const RandomProblem p = random_problem(samples, random);
  NormOptimalDense dense(paper_model(), IlcParameters{}, samples);
  NormOptimalConstrained constrained(paper_model(), IlcParameters{}, samples);
  Eigen::VectorXd expected(samples), actual(samples);
  dense.update(p.u_j, p.e_j, expected);
  // From the pressure-limit context: zero feedback and a limit far beyond the correction.
  constrained.set_input_context(Eigen::VectorXd::Zero(samples), 10.0 * expected.cwiseAbs().maxCoeff());
  constrained.update(p.u_j, p.e_j, actual);
  EXPECT_EQ(constrained.last_report().admm_iterations, 0);
  EXPECT_LT((actual - expected).norm(), 1e-10 * expected.norm());
}

TEST(NoilcConstrained, BoundsComeFromTheFeedbackAndThePressureLimit) {
  const int samples = 50;
  IlcParameters parameters;
  parameters.limit_margin_bar = 0.01;
  NormOptimalConstrained constrained(paper_model(), parameters, samples);
  const Eigen::VectorXd feedback = Eigen::VectorXd::LinSpaced(samples, -0.2, 0.3);
  constrained.set_input_context(feedback, 0.387);
  // u_pid + u_ilc must stay within +-(limit - margin).
  EXPECT_TRUE(((feedback + constrained.upper_bound()).array() - 0.377).abs().maxCoeff() < 1e-15);
  EXPECT_TRUE(((feedback + constrained.lower_bound()).array() + 0.377).abs().maxCoeff() < 1e-15);
  // A large error would drive the free update far beyond; the constrained one stays feasible
  // even when ADMM is stopped after one iteration.
  parameters.admm_max_iterations = 1;
  NormOptimalConstrained hurried(paper_model(), parameters, samples);
  hurried.set_input_context(feedback, 0.387);
  Eigen::VectorXd u(samples);
  hurried.update(Eigen::VectorXd::Zero(samples), Eigen::VectorXd::Constant(samples, 1.0), u);
  EXPECT_FALSE(hurried.last_report().converged);
  EXPECT_LE((feedback + u).cwiseAbs().maxCoeff(), 0.377 + 1e-15);
}

// After an input that sat on the pressure limit in the last trial, the next limit_recovery_s of error
// carry no weight: the update is the bounded optimum for the error with those entries zeroed.
TEST(NoilcConstrained, LeavesOutTheErrorsAfterInputsOnTheLimit) {
  std::mt19937 random(13);
  const int samples = 120;
  const RandomProblem p = random_problem(samples, random);
  IlcParameters parameters;
  parameters.admm_tolerance = 1e-11;
  parameters.admm_max_iterations = 20000;
  parameters.limit_recovery_s = 0.08;  // 4 samples at 50 Hz
  const double limit = 0.3;
  const Eigen::VectorXd feedback = Eigen::VectorXd::Zero(samples);
  Eigen::VectorXd u_j = p.u_j;
  u_j(30) = limit;          // the set point reached the limit at inputs 30 and 31
  u_j(31) = -limit - 0.01;  // (beyond it: clamped in the trial)
  u_j(100) = limit;         // and at 100
  NormOptimalConstrained constrained(paper_model(), parameters, samples);
  constrained.set_input_context(feedback, limit);
  Eigen::VectorXd actual(samples);
  constrained.update(u_j, p.e_j, actual);
  EXPECT_EQ(constrained.last_report().unweighted_errors, 5 + 4);  // entries 30..34 and 100..103

  Eigen::VectorXd e = p.e_j;
  e.segment(30, 5).setZero();
  e.segment(100, 4).setZero();
  NormOptimalConstrained plain(paper_model(), parameters, samples);
  plain.set_bounds(Eigen::VectorXd::Constant(samples, -limit), Eigen::VectorXd::Constant(samples, limit));
  Eigen::VectorXd expected(samples);
  plain.update(u_j, e, expected);
  EXPECT_EQ(plain.last_report().unweighted_errors, 0);
  EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-8);

  // limit_recovery_s = 0 is the plain bounded optimum of the error as measured.
  parameters.limit_recovery_s = 0.0;
  NormOptimalConstrained unmasked(paper_model(), parameters, samples);
  unmasked.set_input_context(feedback, limit);
  unmasked.update(u_j, p.e_j, actual);
  plain.set_bounds(Eigen::VectorXd::Constant(samples, -limit), Eigen::VectorXd::Constant(samples, limit));
  plain.update(u_j, p.e_j, expected);
  EXPECT_EQ(unmasked.last_report().unweighted_errors, 0);
  EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-8);
}

// What "left out" means (docs/learning-laws.md): the errors are set to zero, so the update keeps those
// outputs where they are; it is not the update with zero weight in M there, which would be free to move
// them. Checked with no bound active, against the Riccati law on the zeroed error and the dense
// zero-weight optimum.
TEST(NoilcConstrained, LimitShapedErrorsAreZeroedNotUnweighted) {
  std::mt19937 random(21);
  const int n = 120;
  const RandomProblem p = random_problem(n, random);
  IlcParameters parameters;
  const double limit = 50.0;  // far away: the free optimum is feasible
  Eigen::VectorXd u_j = 0.01 * p.u_j;
  u_j(40) = limit;  // reached the limit in the trial: outputs 40..43 are left out
  NormOptimalConstrained constrained(paper_model(), parameters, n);
  constrained.set_input_context(Eigen::VectorXd::Zero(n), limit);
  Eigen::VectorXd actual(n);
  constrained.update(u_j, p.e_j, actual);
  ASSERT_EQ(constrained.last_report().unweighted_errors, 4);
  ASSERT_EQ(constrained.last_report().admm_iterations, 0);
  Eigen::VectorXd zeroed = p.e_j;
  zeroed.segment(40, 4).setZero();
  NormOptimalRiccati riccati(paper_model(), parameters, n);
  Eigen::VectorXd expected(n);
  riccati.update(u_j, zeroed, expected);
  EXPECT_LT((actual - expected).norm(), 1e-10 * expected.norm());
  // The zero-weight alternative: M = diag(m, with 0 at entries 40..43), the measured error.
  const Eigen::MatrixXd P = paper_model().lifted(n);
  Eigen::VectorXd mask = Eigen::VectorXd::Constant(n, parameters.m);
  mask.segment(40, 4).setZero();
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  const double T = paper_model().sample_time_s;
  for (int t = 0; t + 1 < n; ++t) {
    D(t, t) = -1.0 / T;
    D(t, t + 1) = 1.0 / T;
  }
  D.row(n - 1) = D.row(n - 2);
  const Eigen::MatrixXd H = P.transpose() * mask.asDiagonal() * P + parameters.s * Eigen::MatrixXd::Identity(n, n) +
                            parameters.w * D.transpose() * D;
  const Eigen::VectorXd v =
      H.ldlt().solve(P.transpose() * mask.asDiagonal() * p.e_j - parameters.w * D.transpose() * D * u_j);
  const Eigen::VectorXd unweighted = u_j + v;
  EXPECT_GT((unweighted - actual).norm(), 0.05 * (actual - u_j).norm());
  // And the zero-weight optimum is what the dense form gives on the error with M zeroed there: a sanity
  // check of the oracle itself (with no entry masked it is the paper's law).
  Eigen::VectorXd all = Eigen::VectorXd::Constant(n, parameters.m);
  const Eigen::MatrixXd H_all = P.transpose() * all.asDiagonal() * P + parameters.s * Eigen::MatrixXd::Identity(n, n) +
                                parameters.w * D.transpose() * D;
  const Eigen::VectorXd v_all = H_all.ldlt().solve(P.transpose() * p.e_j - parameters.w * D.transpose() * D * u_j);
  Eigen::VectorXd paper(n);
  riccati.update(u_j, p.e_j, paper);
  EXPECT_LT((u_j + v_all - paper).norm(), 1e-8 * paper.norm());
}

TEST(NoilcConstrained, RejectsBadParametersAndBounds) {
  IlcParameters parameters;
  parameters.admm_rho = 0.0;
  EXPECT_THROW(NormOptimalConstrained(paper_model(), parameters, 10), InputError);
  NormOptimalConstrained constrained(paper_model(), IlcParameters{}, 10);
  EXPECT_THROW(constrained.set_input_context(Eigen::VectorXd::Zero(9), 0.3), InputError);
  EXPECT_THROW(constrained.set_bounds(Eigen::VectorXd::Ones(10), Eigen::VectorXd::Zero(10)), InputError);
  IlcParameters wide_margin;
  wide_margin.limit_margin_bar = 0.5;
  IlcParameters negative_recovery;
  negative_recovery.limit_recovery_s = -0.01;
  EXPECT_THROW(NormOptimalConstrained(paper_model(), negative_recovery, 10), InputError);
  NormOptimalConstrained no_room(paper_model(), wide_margin, 10);
  EXPECT_THROW(no_room.set_input_context(Eigen::VectorXd::Zero(10), 0.387), InputError);
}

// ---- The paper scenario, 200 iterations on the simulated arm ----------------------------------

struct PaperRun {
  std::vector<double> rms_deg, max_correction_bar;
  double worst_planned_total_bar = 0.0;  // max over j, k of |u_pid,j(k) + u_ilc,j+1(k)|
  WindupSummary windup;
  double largest_clamp_bar = 0.0;
};

PaperRun run_paper_scenario(const std::string& law_name, int iterations) {
  Configuration config;
  config.ilc.law = law_name;
  const Trajectory trajectory = library_trajectory("paper", config.timing.sample_s());
  const int n = trajectory.learning_samples();
  const auto law = make_learning_law(config, discretize_arm_model(config.model, config.timing.sample_s()), n);
  SimulatedArm arm(config.plant, 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  LearningSession session(clock, *law, trajectory, config.timing, config.controller);
  LearningMonitor monitor(config.controller.p_max_bar - config.controller.gas.ambient_bar, n);
  PaperRun run;
  for (int j = 0; j <= iterations; ++j) {
    const IterationSummary s = session.run_trial();
    const IterationDiagnostics& d = monitor.observe(j, session.last_record());
    run.rms_deg.push_back(s.rms_deg);
    run.max_correction_bar.push_back(s.max_abs_correction_bar);
    run.largest_clamp_bar = std::max(run.largest_clamp_bar, d.clamped_excess_bar);
    if (j == iterations) break;
    const Eigen::VectorXd feedback = session.last_record().joint_samples(0).u_pid_bar.head(n);
    session.learn();
    run.worst_planned_total_bar =
        std::max(run.worst_planned_total_bar, (feedback + session.correction_bar()).cwiseAbs().maxCoeff());
  }
  run.windup = monitor.windup();
  return run;
}

TEST(NoilcConstrainedOnThePaperScenario, NoWindupWhereTheUnconstrainedLawWindsUp) {
  constexpr int kIterations = 200;
  const double limit = ControllerParameters{}.p_max_bar - GasParameters{}.ambient_bar;
  const PaperRun constrained = run_paper_scenario("noilc-constrained", kIterations);
  const PaperRun free = run_paper_scenario("noilc", kIterations);

  // Every correction keeps the set points inside [p0, p_max] with the feedback it was planned for.
  EXPECT_LE(constrained.worst_planned_total_bar, limit + 1e-9);
  // In the trials themselves the feedback moves a little; the clamp then cuts less than 5 mbar.
  EXPECT_LT(constrained.largest_clamp_bar, 0.005);
  EXPECT_FALSE(constrained.windup.detected);
  EXPECT_LT(constrained.max_correction_bar.back(), limit + 0.1);
  // The correction has settled: its largest value over the last 50 trials is no larger than over the
  // 50 before (the unconstrained one grows by ~0.1 bar per 50 trials there).
  const auto largest_in = [](const std::vector<double>& v, std::size_t from, std::size_t to) {
    return *std::max_element(v.begin() + static_cast<std::ptrdiff_t>(from),
                             v.begin() + static_cast<std::ptrdiff_t>(to));
  };
  EXPECT_LT(largest_in(constrained.max_correction_bar, 151, 201),
            largest_in(constrained.max_correction_bar, 101, 151) + 0.005);

  // The paper's unconstrained update winds up, and the run says so.
  EXPECT_TRUE(free.windup.detected);
  EXPECT_GT(free.max_correction_bar.back(), 2.5 * limit);
  EXPECT_GT(free.max_correction_bar.back(), free.max_correction_bar[150] + 0.03);
  EXPECT_GT(free.largest_clamp_bar, 0.5);

  // Tracking, same seed and noise, RMS over the same samples: no worse than the unconstrained law at
  // 200 trials, and no worse on average over the last 50 (not one lucky trial).
  EXPECT_LE(constrained.rms_deg.back(), free.rms_deg.back());
  const auto mean_of_last = [](const std::vector<double>& v, std::size_t count) {
    double sum = 0.0;
    for (std::size_t i = v.size() - count; i < v.size(); ++i) sum += v[i];
    return sum / static_cast<double>(count);
  };
  EXPECT_LE(mean_of_last(constrained.rms_deg, 50), mean_of_last(free.rms_deg, 50));
  EXPECT_LT(constrained.rms_deg.back(), 1.0);
  EXPECT_GT(free.rms_deg.back(), free.rms_deg[60]);  // the wound-up law has been getting worse
}

}  // namespace
}  // namespace bellows
