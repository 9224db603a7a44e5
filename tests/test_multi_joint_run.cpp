// The issue's learning bar on the whole simulated arm (issue 14, "What it must show"), through the
// same pieces `bellows run` uses: the J-joint simulated arm with its bellows (SimulatedArmChain), the
// engine on the simulated clock, LearningSession and the learning [ilc] and [arm] configure. Every
// joint's RMS at iteration 30 is at most 1/8 of its iteration 0 and no later iteration to 60 exceeds
// 1.25 x its best so far, on arm2/paper2 and arm3/paper3; on arm2 the coupled model beats independent
// joints overall. The numbers are printed for docs/learning-laws.md.
#include <gtest/gtest.h>

#include <iostream>

#include "devices/simulated_arm_chain.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "engine/trial/trajectory.hpp"

namespace bellows {
namespace {

/// Each iteration's summary of `iterations` learning iterations of `preset` on its paper trajectory.
std::vector<IterationSummary> learn_on_the_arm(const char* preset, const char* joint_model, int iterations) {
  Configuration config;
  config.arm.preset = preset;
  config.ilc.joint_model = joint_model;
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  const Trajectory trajectory = library_trajectory("paper" + std::to_string(arm.joints()), config.timing.sample_s());
  const auto learning = make_joint_learning(config, discretize_arm_model(config.model, config.timing.sample_s()),
                                            trajectory.joints(), trajectory.learning_samples());
  LearningSession session(clock, *learning, trajectory, config.timing, config.controller);
  std::vector<IterationSummary> history;
  for (int i = 0; i <= iterations; ++i) {
    history.push_back(session.run_trial());
    session.learn();
  }
  return history;
}

void print(const char* what, const std::vector<IterationSummary>& history) {
  std::cout << what << " RMS per joint (deg) / overall:";
  for (int i : {0, 5, 10, 30, 60}) {
    if (static_cast<std::size_t>(i) >= history.size()) continue;
    const IterationSummary& s = history[static_cast<std::size_t>(i)];
    std::cout << "  it " << i << ": " << s.joint_rms_deg.transpose() << " / " << s.rms_deg;
  }
  std::cout << "\n";
}

void expect_the_issues_bar(const std::vector<IterationSummary>& history, const char* what) {
  ASSERT_EQ(history.size(), 61u);
  for (Eigen::Index j = 0; j < history[0].joint_rms_deg.size(); ++j) {
    const double first = history[0].joint_rms_deg(j);
    EXPECT_GT(first, 5.0) << what << " joint " << j + 1 << ": the feedback alone leaves an error to learn";
    EXPECT_LE(history[30].joint_rms_deg(j), first / 8.0) << what << " joint " << j + 1;
    double best = first;
    for (std::size_t i = 1; i < history.size(); ++i) {
      EXPECT_LE(history[i].joint_rms_deg(j), 1.25 * best) << what << " joint " << j + 1 << " iteration " << i;
      best = std::min(best, history[i].joint_rms_deg(j));
    }
  }
}

TEST(MultiJointRun, EveryJointLearnsToAnEighthIn30IterationsAndStaysThereTo60) {
  const std::vector<IterationSummary> arm2 = learn_on_the_arm("arm2", "coupled", 60);
  print("arm2/paper2 coupled", arm2);
  expect_the_issues_bar(arm2, "arm2");
  const std::vector<IterationSummary> arm3 = learn_on_the_arm("arm3", "coupled", 60);
  print("arm3/paper3 coupled", arm3);
  expect_the_issues_bar(arm3, "arm3");
  // Independent joints on arm2: the same start, then slower and worse overall (docs/learning-laws.md).
  const std::vector<IterationSummary> independent = learn_on_the_arm("arm2", "independent", 30);
  print("arm2/paper2 independent", independent);
  EXPECT_EQ(independent[0].rms_deg, arm2[0].rms_deg) << "iteration 0 is feedback only, whatever the model";
  for (int i : {5, 10, 30}) {
    EXPECT_LT(arm2[static_cast<std::size_t>(i)].rms_deg, independent[static_cast<std::size_t>(i)].rms_deg)
        << "iteration " << i;
  }
}

}  // namespace
}  // namespace bellows
