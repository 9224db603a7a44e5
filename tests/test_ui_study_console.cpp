// Issue 23, the study through the console's keys: e jumps to the largest |error| and the next ones,
// each trial records the law and weights that learned its correction, and on the simulated clock
// the console's engine time passes only while the engine has work, so that its numbers are
// exactly those of a headless LearningSession (what `bellows run` runs) with the same seed.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "app/trajectory_file.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/rt/engine_driver.hpp"
#include "sessions/manifest_json.hpp"
#include "tests/console_fixture.hpp"
#include "ui/keys.hpp"
#include "ui/plot_data.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;
using testing::MemorySessions;

TEST(UiStudyConsole, ETakesTheInspectorToTheLargestErrorThenTheNextOnesAndEBack) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(1);  // iterations 0..1
  ASSERT_EQ(f.state().screen, Screen::kMain);
  f.key('e');  // from the main screen: one key
  ASSERT_EQ(f.state().screen, Screen::kInspector);
  const Trial& newest = f.state().experiment.trials.back();
  EXPECT_EQ(f.state().inspector.trial, 1);
  const TrialSamples& r = newest.record.joint_samples(0);
  const int n = newest.record.learning_samples;
  int worst = 1;
  for (int k = 1; k <= n; ++k) {
    if (std::abs(r.error_rad(k)) > std::abs(r.error_rad(worst))) worst = k;
  }
  EXPECT_EQ(f.state().inspector.sample, worst);
  EXPECT_NEAR(std::abs(r.error_rad(worst)) * 180.0 / std::numbers::pi, newest.summary.max_abs_error_deg, 1e-9);
  EXPECT_NE(f.state().status.find("|error| peak 1 of"), std::string::npos) << f.state().status;
  f.key('e');
  const int second = f.state().inspector.sample;
  EXPECT_NE(second, worst);
  EXPECT_LE(std::abs(r.error_rad(second)), std::abs(r.error_rad(worst)));
  EXPECT_EQ(f.state().inspector.peak, 1);
  f.key('E');
  EXPECT_EQ(f.state().inspector.sample, worst);
  // Another iteration starts from its own largest error.
  f.key(key::kUp);
  f.key('e');
  EXPECT_EQ(f.state().inspector.trial, 0);
  EXPECT_EQ(f.state().inspector.sample, error_peaks(f.state().experiment.trials[0].record).front());
}

TEST(UiStudyConsole, EachTrialRecordsTheLawAndWeightsThatLearnedItsCorrection) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(1);  // iterations 0..1, with S = 0.1
  f.key('w');
  for (int i = 0; i < 6; ++i) f.key(key::kDown);  // k_p, k_i, k_d, law, M, S
  f.key(key::kEnter);
  for (int i = 0; i < 3; ++i) f.key(key::kBackspace);
  f.type("0.2");
  f.key(key::kEnter);
  ASSERT_DOUBLE_EQ(f.state().config.ilc.s, 0.2) << f.state().status;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key(key::kEscape);
  f.key('n');  // learns from 1 with S = 0.2, then runs 2
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.state().experiment.trials.size() == 3; }));
  const auto& trials = f.state().experiment.trials;
  EXPECT_FALSE(trials[0].summary.learned_with.known());  // feedback only
  Configuration before = f.config;
  EXPECT_EQ(trials[1].summary.learned_with, learned_with(before));
  Configuration after = f.config;
  after.ilc.s = 0.2;
  EXPECT_EQ(trials[2].summary.learned_with, learned_with(after));
  EXPECT_EQ(trials[2].summary.learned_with.weights,
            (std::vector<std::pair<std::string, double>>{{"m", 1.0}, {"s", 0.2}, {"w", 2e-5}}));
  // Saved with the session.
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  ASSERT_EQ(f.sessions.saved.size(), 1u);
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.trials[2].summary.learned_with, learned_with(after));
}

// The console on the simulated clock as `bellows console --clock sim` runs it: engine time passes
// (tick by tick on this thread) only while the controller says the engine has work.
struct SimulatedConsole {
  SimulatedConsole()
      : arm(config.plant, 7), core(arm, config.controller, config.timing, config.safety), clock(core, arm) {
    ConsoleEnvironment env;
    env.core = &core;
    env.telemetry = &core.add_telemetry_tap(4096);
    env.config = config;
    env.sessions = &sessions;
    env.simulated_clock = true;
    env.speed = "max";
    env.clock_text = [] { return std::string("12:00:00"); };
    console = std::make_unique<ConsoleController>(env, library_trajectory("paper", config.timing.sample_s()), false);
    console->resize(120, 40);
    console->start(0.0);
  }
  /// The UI loop's turns: update, then the engine's ticks while it has work; until `done`.
  bool run_until(const std::function<bool()>& done) {
    const auto start = std::chrono::steady_clock::now();
    while (!done()) {
      if (std::chrono::steady_clock::now() - start > std::chrono::seconds(60)) return false;
      console->update(clock.now_s());
      if (!console->needs_engine_time()) std::this_thread::sleep_for(std::chrono::microseconds(200));
      for (int i = 0; i < 4000 && console->needs_engine_time(); ++i) clock.step(1);
    }
    return true;
  }
  void key(int k) { console->handle_key(k, clock.now_s()); }

  Configuration config;
  SimulatedArm arm;
  EngineCore core;
  SimulatedClock clock;
  MemorySessions sessions;
  std::unique_ptr<ConsoleController> console;
};

TEST(UiStudyConsole, OnTheSimulatedClockTimePassesOnlyWhileTheEngineHasWork) {
  SimulatedConsole s;
  ASSERT_TRUE(s.run_until([&] { return s.console->state().law_ready; }));
  EXPECT_EQ(s.core.ticks(), 0u);  // the trajectory and gains wait for the first tick that acts
  EXPECT_FALSE(s.console->needs_engine_time());
  s.key('a');
  s.key('y');
  EXPECT_TRUE(s.console->needs_engine_time());
  s.clock.step(1);
  EXPECT_EQ(s.core.state(), EngineState::kArmed);
  EXPECT_FALSE(s.console->needs_engine_time());  // ARMED and idle: time stands still
  s.console->update(s.clock.now_s());
  s.key('r');
  ASSERT_TRUE(s.run_until([&] {
    return s.console->state().experiment.trials.size() == 1 && s.console->state().run.mode == RunProgress::Mode::kIdle;
  }));
  const std::uint64_t after_trial = s.core.ticks();
  EXPECT_EQ(s.core.state(), EngineState::kArmed);
  s.run_until([&] { return true; });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  s.console->update(s.clock.now_s());
  EXPECT_FALSE(s.console->needs_engine_time());
  EXPECT_EQ(s.core.ticks(), after_trial);
  // An emergency stop needs its tick however idle the engine is.
  s.key(' ');
  EXPECT_TRUE(s.console->needs_engine_time());
  s.clock.step(1);
  EXPECT_EQ(s.core.state(), EngineState::kFault);
  EXPECT_FALSE(s.console->needs_engine_time());
}

TEST(UiStudyConsole, OnTheSimulatedClockTheNumbersAreThoseOfAHeadlessRunExactly) {
  SimulatedConsole s;
  ASSERT_TRUE(s.run_until([&] { return s.console->state().law_ready; }));
  s.key('a');
  s.key('y');
  ASSERT_TRUE(s.run_until([&] { return s.console->state().engine_state == EngineState::kArmed; }));
  s.key('N');
  for (int i = 0; i < 3; ++i) s.key(key::kBackspace);
  s.key('3');
  s.key(key::kEnter);
  ASSERT_TRUE(s.run_until([&] {
    return s.console->state().experiment.trials.size() == 4 && s.console->state().run.mode == RunProgress::Mode::kIdle;
  })) << s.console->state().status
      << " / dialog " << s.console->state().dialog.input << " / trials " << s.console->state().experiment.trials.size()
      << " / ticks " << s.core.ticks();

  // `bellows run --iterations 3 --seed 7` in process: the same arm, law and trajectory.
  const Configuration config;
  SimulatedArm arm(config.plant, 7);
  EngineCore core(arm, config.controller, config.timing, config.safety);
  SimulatedClock clock(core, arm);
  const Trajectory trajectory = library_trajectory("paper", config.timing.sample_s());
  const auto law = make_joint_learning(config, discretize_arm_model(config.model, config.timing.sample_s()), 1,
                                       trajectory.learning_samples());
  LearningSession run(clock, *law, trajectory, config.timing, config.controller);
  const auto& trials = s.console->state().experiment.trials;
  for (int i = 0; i < 4; ++i) {
    const IterationSummary summary = run.run_trial();
    run.learn();
    EXPECT_EQ(trials[static_cast<std::size_t>(i)].summary.rms_deg, summary.rms_deg) << "iteration " << i;
    EXPECT_EQ(trials[static_cast<std::size_t>(i)].summary.max_abs_error_deg, summary.max_abs_error_deg)
        << "iteration " << i;
  }
  EXPECT_EQ(s.core.ticks(), core.ticks());
}

}  // namespace
}  // namespace bellows::ui

namespace bellows {
namespace {

// The manifest's learned_with: written when known, read back the same, absent in older sessions
// (nothing assumed), and a record that is not a law's is refused with its path.
TEST(SessionLearnedWith, RoundTripsIsOptionalAndRefusesWhatNoLawReads) {
  SessionManifest m;
  m.name = "study";
  m.device = "sim";
  m.trajectory_name = "short";
  m.trajectory_samples = 10;
  IterationSummary first;
  IterationSummary second;
  second.iteration = 1;
  Configuration config;
  config.ilc.s = 0.2;
  second.learned_with = learned_with(config);
  m.iterations.push_back({first, "2026-12-01T20:00:00.000Z"});
  m.iterations.push_back({second, "2026-12-01T20:00:01.000Z"});
  m.resume = ResumeState{};
  const std::string text = format_manifest(m);
  EXPECT_NE(text.find("\"learned_with\": {\n        \"law\": \"noilc\",\n        \"m\": 1.0,\n        \"s\": 0.2,"),
            std::string::npos)
      << text;
  const SessionManifest read = parse_manifest(text, "manifest.json");
  ASSERT_EQ(read.iterations.size(), 2u);
  EXPECT_FALSE(read.iterations[0].summary.learned_with.known());
  EXPECT_EQ(read.iterations[1].summary.learned_with, second.learned_with);
  EXPECT_EQ(format_manifest(read), text);
  for (const auto& [from, to] :
       {std::pair{"\"s\": 0.2", "\"pd_kp\": 0.2"}, std::pair{"\"law\": \"noilc\"", "\"law\": \"best\""},
        std::pair{"\"s\": 0.2", "\"s\": -1.0"}}) {
    std::string bad = text;
    bad.replace(bad.find(from, bad.find("\"learned_with\"")), std::string(from).size(), to);
    try {
      parse_manifest(bad, "manifest.json");
      ADD_FAILURE() << "accepted " << to;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("/iterations/1/learned_with"), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace bellows
