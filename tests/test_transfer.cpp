// Learning transfer (engine/config/learning_transfer): trained on `paper` and `steps` (30 iterations each,
// simulated arm, simulated clock), the first correction for five unseen trajectories of different
// character (tests/test_transfer_scenarios.hpp) must beat feedback only, and learning must go on
// from it; a transfer that cannot help falls back to zero and says why.
#include <algorithm>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "engine/base/errors.hpp"
#include "test_transfer_scenarios.hpp"

namespace bellows {
namespace {

using testing::LearningRun;
using testing::run_learning;
using testing::unseen_trajectories;

constexpr int kTrainingIterations = 30;
constexpr int kFollowUpIterations = 5;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<TransferSource> train(const Configuration& config) {
  const double t = config.timing.sample_s();
  return {run_learning(config, library_trajectory("paper", t), kTrainingIterations).source,
          run_learning(config, library_trajectory("steps", t), kTrainingIterations).source};
}

/// Trained once for every test here: the sessions and, per unseen trajectory, learning from scratch
/// and from the transfer.
class TransferOnTheSimulatedArm : public ::testing::Test {
 protected:
  struct Outcome {
    std::string name;
    TransferResult transfer;
    LearningRun scratch, transferred;
  };

  // Built on first use and shared by the tests of one process (ctest runs each test in its own, so
  // a test only pays for what it uses: the sessions ~0.7 s CPU, the outcomes ~0.8 s more).
  static const std::vector<TransferSource>& sources() {
    static const std::vector<TransferSource> trained = train(Configuration{});
    return trained;
  }
  static const std::vector<Outcome>& outcomes() {
    static const std::vector<Outcome> all = [] {
      const Configuration config;
      std::vector<Outcome> out;
      LearningTransfer transfer;
      transfer.setup(sources(), config.controller, config.timing.sample_s());
      for (const Trajectory& target : unseen_trajectories(config.timing.sample_s())) {
        Outcome o{target.name, transfer.solve(target), {}, {}};
        o.scratch = run_learning(config, target, kFollowUpIterations);
        o.transferred = run_learning(config, target, kFollowUpIterations, o.transfer.correction_bar);
        out.push_back(std::move(o));
      }
      return out;
    }();
    return all;
  }
};

TEST_F(TransferOnTheSimulatedArm, FirstTrialIsFarBetterThanFeedbackOnlyAndNeverWorse) {
  std::vector<double> ratios;
  for (const Outcome& o : outcomes()) {
    EXPECT_EQ(o.transfer.status, TransferStatus::kTransferred) << o.name << ": " << o.transfer.reason;
    const double ratio = o.transferred.rms_deg[0] / o.scratch.rms_deg[0];
    EXPECT_LT(ratio, 1.0) << o.name;
    ratios.push_back(ratio);
  }
  EXPECT_LE(median(ratios), 0.4);
}

TEST_F(TransferOnTheSimulatedArm, AfterFiveIterationsAtMostHalfOfLearningFromScratch) {
  std::vector<double> ratios;
  for (const Outcome& o : outcomes()) {
    ratios.push_back(o.transferred.rms_deg[kFollowUpIterations] / o.scratch.rms_deg[kFollowUpIterations]);
  }
  EXPECT_LE(median(ratios), 0.5);
}

TEST_F(TransferOnTheSimulatedArm, PredictsTheFirstTrialWithinAFactorOfThree) {
  for (const Outcome& o : outcomes()) {
    // Feedback only is predicted from the reference alone (measured: within 28 %, the triangle worst).
    EXPECT_NEAR(o.transfer.predicted_feedback_only_rms_deg, o.scratch.rms_deg[0], 0.35 * o.scratch.rms_deg[0])
        << o.name;
    EXPECT_LT(o.transfer.predicted_rms_deg, 3.0 * o.transferred.rms_deg[0]) << o.name;
    EXPECT_GT(o.transfer.predicted_rms_deg, o.transferred.rms_deg[0] / 3.0) << o.name;
  }
}

TEST_F(TransferOnTheSimulatedArm, PlannedSetPointsRespectThePressureLimits) {
  const Configuration config;
  const ControllerParameters& c = config.controller;
  const double reach = c.p_max_bar - c.gas.ambient_bar - TransferSettings{}.limit_margin_bar;
  const auto targets = unseen_trajectories(config.timing.sample_s());
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const Eigen::VectorXd r = targets[i].joint(0) / std::numbers::pi;
    const Eigen::VectorXd& u = (outcomes())[i].transfer.correction_bar;
    for (Eigen::Index t = 0; t < u.size(); ++t) {
      const double feedback = c.k_ff * r(t) - c.k_d_s * (t > 0 ? (r(t) - r(t - 1)) / config.timing.sample_s() : 0.0);
      EXPECT_LE(std::abs(feedback + u(t)), reach + 1e-12) << targets[i].name << " sample " << t;
    }
  }
  // And on the arm: the first trial's set points hardly touch the clamp.
  for (const Outcome& o : outcomes()) {
    const TransferTrial& first = o.transferred.source.trials.front();
    const double limit = c.p_max_bar - c.gas.ambient_bar;
    EXPECT_LE((first.u_pid_bar + first.u_ilc_bar).cwiseAbs().maxCoeff(), limit + 0.05) << o.name;
  }
}

TEST_F(TransferOnTheSimulatedArm, EveryMethodIsValidatedAndAutoTakesTheBest) {
  const Configuration config;
  const Trajectory target = unseen_trajectories(config.timing.sample_s())[0];
  LearningTransfer transfer;
  transfer.setup(sources(), config.controller, config.timing.sample_s());
  const TransferResult automatic = transfer.solve(target);
  ASSERT_EQ(automatic.method_ratios.size(), 3u);
  double best = INFINITY;
  for (const auto& [name, ratio] : automatic.method_ratios) {
    EXPECT_LT(ratio, 1.0) << name;  // held out: fitted on paper, predicting steps and the reverse
    best = std::min(best, ratio);
  }
  EXPECT_EQ(automatic.validation_ratio, best);
  for (const char* name : {"reference-fir", "basis", "inverse-fir"}) {
    TransferSettings settings;
    settings.method = parse_transfer_method(name);
    LearningTransfer one(settings);
    one.setup(sources(), config.controller, config.timing.sample_s());
    const TransferResult r = one.solve(target);
    EXPECT_EQ(r.method, name);
    EXPECT_EQ(r.status, TransferStatus::kTransferred) << name << ": " << r.reason;
    EXPECT_LT(r.predicted_rms_deg, 0.5 * r.predicted_feedback_only_rms_deg) << name;
  }
  EXPECT_EQ(transfer.info().sources, 2);
  EXPECT_EQ(transfer.info().trials, 2 * (kTrainingIterations + 1));
}

TEST_F(TransferOnTheSimulatedArm, SessionsThatTeachNothingFallBackToZeroAndSayWhy) {
  const Configuration config;
  const Trajectory target = unseen_trajectories(config.timing.sample_s())[2];
  // The feedback recorded in the sessions replaced by noise: every fitted input map is garbage.
  std::vector<TransferSource> poisoned = sources();
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (TransferSource& s : poisoned) {
    for (TransferTrial& trial : s.trials) {
      for (Eigen::Index t = 0; t < trial.u_pid_bar.size(); ++t) trial.u_pid_bar(t) = noise(random);
    }
  }
  for (const char* name : {"auto", "reference-fir", "inverse-fir"}) {
    TransferSettings settings;
    settings.method = parse_transfer_method(name);
    LearningTransfer transfer(settings);
    transfer.setup(poisoned, config.controller, config.timing.sample_s());
    const TransferResult r = transfer.solve(target);
    EXPECT_EQ(r.status, TransferStatus::kFallback) << name;
    EXPECT_NE(r.reason.find("feedback-only"), std::string::npos) << r.reason;
    EXPECT_TRUE(r.correction_bar.isZero()) << name;
    EXPECT_EQ(r.correction_bar.size(), target.learning_samples());
    EXPECT_EQ(r.predicted_rms_deg, r.predicted_feedback_only_rms_deg);
  }
  // A demand no prediction can meet falls back as well, with the prediction in the reason.
  TransferSettings strict;
  strict.largest_accepted_ratio = 0.01;
  LearningTransfer transfer(strict);
  transfer.setup(sources(), config.controller, config.timing.sample_s());
  const TransferResult r = transfer.solve(target);
  EXPECT_EQ(r.status, TransferStatus::kFallback);
  EXPECT_TRUE(r.correction_bar.isZero());
  EXPECT_FALSE(r.reason.empty());
}

TEST_F(TransferOnTheSimulatedArm, SourcesOfAnotherSampleTimeAreRefusedByName) {
  const Configuration config;
  std::vector<TransferSource> changed = sources();
  changed[1].name = "steps-at-40-hz";
  changed[1].trajectory.sample_time_s = 0.025;
  LearningTransfer transfer;
  try {
    transfer.setup(changed, config.controller, config.timing.sample_s());
    FAIL() << "accepted a source of another sample time";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("steps-at-40-hz"), std::string::npos) << e.what();
  }
  // Without a single complete trial a source is refused too.
  changed = sources();
  changed[0].trials.resize(1);
  changed[0].trials[0].angle_rad.resize(3);
  EXPECT_THROW(transfer.setup({changed[0]}, config.controller, config.timing.sample_s()), InputError);
}

TEST(TransferFromOneSession, ASingleShortSessionStillHelpsOrFallsBack) {
  const Configuration config;
  const double t = config.timing.sample_s();
  LearningTransfer transfer;
  transfer.setup({run_learning(config, library_trajectory("paper", t), 4).source}, config.controller, t);
  const Trajectory target = unseen_trajectories(t)[4];
  const TransferResult r = transfer.solve(target);
  const LearningRun scratch = run_learning(config, target, 0);
  const LearningRun run = run_learning(config, target, 0, r.correction_bar);
  EXPECT_LE(run.rms_deg[0], scratch.rms_deg[0] + 1e-9) << r.reason;
}

TEST(TransferWithAMismatchedModel, NeverStartsWorseThanFeedbackOnly) {
  // The sessions were learned with a model 20 % off the arm (kappa and omega0), and so is the target
  // run: the transfer, fitted from the measured trials, must still never start worse.
  Configuration config;
  config.model.kappa_rad_per_bar *= 1.2;
  config.model.omega0_rad_per_s *= 0.8;
  const double t = config.timing.sample_s();
  LearningTransfer transfer;
  transfer.setup(train(config), config.controller, t);
  for (const Trajectory& target : unseen_trajectories(t)) {
    const TransferResult r = transfer.solve(target);
    const double feedback_only = run_learning(config, target, 0).rms_deg[0];
    const double first = run_learning(config, target, 0, r.correction_bar).rms_deg[0];
    EXPECT_LT(first, feedback_only) << target.name << " (" << r.method << ", " << r.reason << ")";
  }
}

TEST(TransferFit, LeavingAGroupOutEqualsFittingTheOthers) {
  std::mt19937 random(3);
  std::normal_distribution<double> noise;
  const auto matrix = [&](int rows, int cols) {
    Eigen::MatrixXd m(rows, cols);
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) m(i, j) = noise(random);
    }
    return m;
  };
  const Eigen::MatrixXd a = matrix(50, 4), b = matrix(30, 4);
  const Eigen::VectorXd ya = a * Eigen::Vector4d(1, 2, 3, 4), yb = matrix(30, 1);
  RidgeAccumulator both(4, 2), only_a(4, 1);
  both.add(0, a, ya);
  both.add(1, b, yb);
  only_a.add(0, a, ya);
  EXPECT_TRUE(both.solve(1e-9, 1).isApprox(only_a.solve(1e-9), 1e-12));
  EXPECT_TRUE(only_a.solve(1e-12).isApprox(Eigen::Vector4d(1, 2, 3, 4), 1e-8));
  EXPECT_EQ(both.rows(), 80);
  EXPECT_EQ(both.rows(0), 30);
}

TEST(TransferFit, RegressorsHoldTheEndsAndLeadTheSignal) {
  Eigen::VectorXd s(5);
  s << 1, 2, 3, 4, 5;
  RegressorShape shape;
  shape.taps_behind = 1;
  shape.taps_ahead = 2;
  shape.constant = false;
  const Eigen::MatrixXd phi = build_regressors(s, shape, 0, 5, 0.02);
  ASSERT_EQ(phi.cols(), 4);
  EXPECT_EQ(phi.row(0), Eigen::RowVector4d(1, 1, 2, 3));  // before the start: held at s(0)
  EXPECT_EQ(phi.row(4), Eigen::RowVector4d(4, 5, 5, 5));  // after the end: held at s(N)
  const Eigen::MatrixXd causal = build_causal_regressors(s.head(3), 2, {}, 0.02);
  EXPECT_EQ(causal.row(0), Eigen::RowVector2d(1, 0));
  EXPECT_EQ(causal.row(2), Eigen::RowVector2d(3, 2));
}

}  // namespace
}  // namespace bellows
