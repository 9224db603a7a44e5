// Model identification: the least-squares fit on synthetic data, on the simulated arm with creep
// switched off (the plant is then exactly the model's structure: kappa, omega0 and delta within 5 %),
// on the default plant (held-out fit >= 80 %, and the ILC learns with the fitted model), the angle
// bound, and writing the result into a config file's [model] section.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "app/config_file.hpp"
#include "app/identify_command.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/identification.hpp"
#include "engine/operator/identification_trial.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"

namespace bellows {
namespace {

IdentificationData trial_data(const Configuration& config, const std::string& signal, std::uint64_t seed) {
  SimulatedArm arm(config.plant, seed);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  TrialRecord record;
  run_identification_trial(clock, identification_trajectory(signal, config.identify, config.timing.sample_s()),
                           config.timing, config.identify.max_abs_angle_deg, record);
  return identification_data(record, config.controller, config.timing.tick_s);
}

void expect_within(double actual, double truth, double fraction, const std::string& what) {
  EXPECT_LT(std::abs(actual - truth), fraction * truth) << what << " = " << actual << ", truth " << truth;
}

TEST(Identification, RecoversAKnownModelFromNoiselessSyntheticData) {
  ModelParameters truth;
  truth.kappa_rad_per_bar = 6.0;
  truth.omega0_rad_per_s = 18.0;
  truth.damping = 0.45;
  IdentificationData data;
  data.sample_time_s = 0.005;
  data.angle_rad = Eigen::VectorXd::Zero(3000);
  data.pressure_difference_bar.resize(3000);
  for (int k = 0; k < 3000; ++k) {
    const double t = k * data.sample_time_s;
    data.pressure_difference_bar(k) = 0.05 * std::sin(2.0 * std::numbers::pi * (0.2 + 0.15 * t) * t);
  }
  data.angle_rad = simulate_arm_angle(truth, data);
  const ArmModelFit fit = fit_arm_model(data, ModelParameters{});
  EXPECT_TRUE(fit.converged);
  expect_within(fit.model.kappa_rad_per_bar, truth.kappa_rad_per_bar, 1e-6, "kappa");
  expect_within(fit.model.omega0_rad_per_s, truth.omega0_rad_per_s, 1e-6, "omega0");
  expect_within(fit.model.damping, truth.damping, 1e-6, "damping");
  EXPECT_GT(fit.fit_percent, 99.999);
}

TEST(Identification, RejectsDataWithoutExcitation) {
  IdentificationData data;
  data.sample_time_s = 0.005;
  data.angle_rad = Eigen::VectorXd::Zero(500);
  data.pressure_difference_bar = Eigen::VectorXd::Zero(500);
  EXPECT_THROW(fit_arm_model(data, ModelParameters{}), InputError);
  data.angle_rad.resize(10);
  EXPECT_THROW(fit_arm_model(data, ModelParameters{}), InputError);
}

TEST(Identification, RecoversThePlantWithinFivePercentWithCreepOff) {
  Configuration config;
  config.plant.creep_gain = 0.0;
  for (const std::string signal : {"chirp", "steps"}) {
    const ArmModelFit fit = fit_arm_model(trial_data(config, signal, 3), config.model);
    expect_within(fit.model.kappa_rad_per_bar, config.plant.kappa_rad_per_bar, 0.05, signal + " kappa");
    expect_within(fit.model.omega0_rad_per_s, config.plant.omega0_rad_per_s, 0.05, signal + " omega0");
    expect_within(fit.model.damping, config.plant.damping, 0.05, signal + " damping");
    EXPECT_GT(fit.fit_percent, 95.0);
  }
}

TEST(Identification, DefaultPlantFitPredictsAHeldOutTrialAndTheIlcLearnsWithIt) {
  Configuration config;  // creep on: the model's structure cannot describe the plant exactly
  const ArmModelFit fit = fit_arm_model(trial_data(config, "chirp", 1), config.model);
  const IdentificationData held_out = trial_data(config, "steps", 2);
  const double validation = normalized_fit_percent(held_out.angle_rad, simulate_arm_angle(fit.model, held_out));
  EXPECT_GE(validation, 80.0);

  config.model = fit.model;
  const Trajectory trajectory = library_trajectory("paper", config.timing.sample_s());
  const auto law = make_learning_law(config, discretize_arm_model(config.model, config.timing.sample_s()),
                                     trajectory.learning_samples());
  SimulatedArm arm(config.plant, 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  LearningSession session(clock, *law, trajectory, config.timing, config.controller);
  const double first = session.run_trial().rms_deg;
  double last = first;
  for (int i = 0; i < 30; ++i) {
    session.learn();
    last = session.run_trial().rms_deg;
  }
  EXPECT_LT(last, 1.5);
  EXPECT_LT(last, first / 8.0);
}

TEST(Identification, TrialIsAbortedAndTheArmVentedBeyondTheAngleBound) {
  Configuration config;
  config.plant.kappa_rad_per_bar = 25.0;  // a much stiffer-than-modelled gain: the feed-forward overshoots
  config.identify.max_abs_angle_deg = 30.0;
  SimulatedArm arm(config.plant, 1);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  TrialRecord record;
  EXPECT_THROW(run_identification_trial(clock, identification_trajectory("chirp", config.identify, 0.02), config.timing,
                                        config.identify.max_abs_angle_deg, record),
               InputError);
  EXPECT_EQ(arm.state().command.inlet_duty[0], 0.0);
  EXPECT_EQ(arm.state().command.outlet_duty[0], 1.0);
  EXPECT_EQ(core.state(), EngineState::kFault);
}

TEST(Identification, ExcitationsStayWithinTheirAmplitudeAndUnknownSignalsAreRejected) {
  const IdentificationParameters p;
  for (const std::string signal : {"chirp", "steps"}) {
    const Trajectory t = identification_trajectory(signal, p, 0.02);
    EXPECT_LE(t.joint(0).cwiseAbs().maxCoeff(), p.amplitude_deg * std::numbers::pi / 180.0 + 1e-12);
    EXPECT_NEAR(t.joint(0)(0), 0.0, 1e-12);
    EXPECT_NEAR(t.joint(0)(t.joint(0).size() - 1), 0.0, 1e-9);
    EXPECT_GT(t.joint(0).cwiseAbs().maxCoeff(), 0.8 * p.amplitude_deg * std::numbers::pi / 180.0);
  }
  EXPECT_EQ(validation_signal("chirp"), "steps");
  EXPECT_THROW(identification_trajectory("noise", p, 0.02), InputError);
  IdentificationParameters too_wide = p;
  too_wide.amplitude_deg = 70.0;
  EXPECT_THROW(identification_trajectory("chirp", too_wide, 0.02), InputError);
}

TEST(ModelSection, ReplacesKeysInPlaceKeepingEverythingElse) {
  ModelParameters m;
  m.kappa_rad_per_bar = 7.25;
  m.omega0_rad_per_s = 13.5;
  m.damping = 0.28;
  const std::string text =
      "# lab rig 2\n[ilc]\nlaw = \"noilc\"  # default\n\n[model]\n# from the paper\nkappa = "
      "7.91\n\n[plant]\ncreep_gain = 0.2\n";
  const std::string updated = with_model_section(text, "lab.toml", m);
  EXPECT_NE(updated.find("# lab rig 2"), std::string::npos);
  EXPECT_NE(updated.find("# from the paper"), std::string::npos);
  EXPECT_EQ(updated.find("kappa = 7.91"), std::string::npos);
  Configuration c;
  apply_config_toml(updated, "updated", c);
  EXPECT_DOUBLE_EQ(c.model.kappa_rad_per_bar, 7.25);
  EXPECT_DOUBLE_EQ(c.model.omega0_rad_per_s, 13.5);
  EXPECT_DOUBLE_EQ(c.model.damping, 0.28);
  EXPECT_DOUBLE_EQ(c.plant.creep_gain, 0.2);
  EXPECT_EQ(c.ilc.law, "noilc");
}

TEST(ModelSection, AddsTheSectionWhenMissingAndRefusesInvalidFiles) {
  ModelParameters m;
  m.kappa_rad_per_bar = 8.0;
  Configuration c;
  apply_config_toml(with_model_section("[ilc]\ns = 0.2\n", "a.toml", m), "a", c);
  EXPECT_DOUBLE_EQ(c.model.kappa_rad_per_bar, 8.0);
  EXPECT_DOUBLE_EQ(c.ilc.s, 0.2);
  apply_config_toml(with_model_section("", "empty.toml", m), "empty", c);
  EXPECT_DOUBLE_EQ(c.model.kappa_rad_per_bar, 8.0);
  EXPECT_THROW(with_model_section("[ilc]\nbogus = 1\n", "bad.toml", m), InputError);
  EXPECT_THROW(with_model_section("model.kappa = 7.0\n", "dotted.toml", m), InputError);
}

}  // namespace
}  // namespace bellows
