// The learning curve of a law on the simulated arm, headless (tests only): the RMS of iterations
// 0..updates, each update learned from the trial before, as `bellows run` does on the simulated clock.
#pragma once

#include <string>
#include <vector>

#include "devices/simulated_arm.hpp"
#include "engine/config/configuration.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/trial/trajectory.hpp"

namespace bellows::testing {

/// RMS (deg) of iterations 0..updates of `law_name` on `trajectory_name` with the simulated arm of
/// `config`, seed 1.
inline std::vector<double> learning_curve(Configuration config, const std::string& law_name,
                                          const std::string& trajectory_name, int updates) {
  config.ilc.law = law_name;
  const Trajectory trajectory = library_trajectory(trajectory_name, config.timing.sample_s());
  const auto law = make_learning_law(config, discretize_arm_model(config.model, config.timing.sample_s()),
                                     trajectory.learning_samples());
  SimulatedArm arm(config.plant, 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  LearningSession session(clock, *law, trajectory, config.timing, config.controller);
  std::vector<double> rms;
  for (int i = 0; i <= updates; ++i) {
    rms.push_back(session.run_trial().rms_deg);
    if (i < updates) session.learn();
  }
  return rms;
}

}  // namespace bellows::testing
