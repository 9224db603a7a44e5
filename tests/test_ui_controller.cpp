// The console's logic driven by keys against a real engine on a simulated clock: what happens to
// the engine, the trials and the screens, without a terminal.
#include <gtest/gtest.h>

#include "engine/config/learning_law_factory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "devices/simulated_arm.hpp"
#include "tests/console_fixture.hpp"
#include "tests/process_runner.hpp"
#include "tests/ui_sample_state.hpp"
#include "ui/canvas.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;
using testing::MemorySessions;

TEST(UiController, ArmingAsksForConfirmation) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('a');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kConfirmArm);
  f.pump_for(0.5);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
  f.key('n');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  f.pump_for(0.5);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
  f.key('a');
  f.key('y');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kArmed; }));
  EXPECT_TRUE(f.logged("SAFE -> ARMED (arm)"));
  EXPECT_NE(f.state().status.find("armed: r runs a trial"), std::string::npos) << f.state().status;
  // The heartbeat keeps the armed engine alive.
  f.pump_for(3.0);
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  f.key('d');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  EXPECT_NE(f.state().status.find("disarmed: the valves are vented"), std::string::npos) << f.state().status;
}

TEST(UiController, FiveIterationsLowerTheRms) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(5);  // N with K = 5 from scratch: iterations 0..5, as `run --iterations 5` (docs/iterations.md)
  const auto rms = f.state().experiment.rms_history_deg();
  ASSERT_EQ(rms.size(), 6u);
  EXPECT_EQ(f.state().experiment.trials.back().iteration, 5);
  for (std::size_t i = 1; i < rms.size(); ++i) EXPECT_LT(rms[i], rms[i - 1]) << "iteration " << i;
  EXPECT_NEAR(rms[0], 15.06, 0.2);  // the feedback-only trial, as `bellows run` gives it
  EXPECT_EQ(f.state().experiment.trials[0].origin, "feedback only");
  EXPECT_EQ(f.state().experiment.trials[3].origin, "learned from 2");
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  EXPECT_TRUE(f.logged("run iterations 0..5"));
  EXPECT_TRUE(f.logged("iterations 0..5 done"));
  // After them, K more continue from the newest: 6..7, K trials (iteration 0 has run).
  f.run_batch(2);
  ASSERT_EQ(f.state().experiment.trials.size(), 8u);
  EXPECT_EQ(f.state().experiment.trials.back().iteration, 7);
  EXPECT_TRUE(f.logged("iterations 6..7 done"));
  // The law's convergence prediction is shown (for the paper's defaults it warns about model errors).
  EXPECT_NE(f.state().convergence.find("contraction"), std::string::npos) << f.state().convergence;
  // Saved as it went.
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  EXPECT_FALSE(f.state().experiment.unsaved());
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.trials.size(), 8u);
}

TEST(UiController, RunRepeatsAndNextLearnsFirst) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  const auto& trials = f.state().experiment.trials;
  ASSERT_EQ(trials.size(), 2u);
  EXPECT_EQ(trials[1].origin, "same as 0");
  EXPECT_TRUE(trials[1].correction_bar.isZero());
  f.key('n');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_EQ(trials.size(), 3u);
  EXPECT_EQ(trials[2].origin, "learned from 1");
  EXPECT_GT(trials[2].correction_bar.cwiseAbs().maxCoeff(), 0.01);
  EXPECT_LT(trials[2].summary.rms_deg, trials[1].summary.rms_deg);
}

TEST(UiController, BatchIsInterruptible) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('N');
  f.key(key::kBackspace);
  f.key(key::kBackspace);
  f.type("50");
  f.key(key::kEnter);
  ASSERT_TRUE(
      f.pump_until([&] { return f.state().experiment.trials.size() == 2 && f.core.state() == EngineState::kRunning; }));
  f.key('x');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  EXPECT_EQ(f.state().experiment.trials.size(), 2u);  // the running trial was aborted, not counted
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  EXPECT_TRUE(f.logged("stopped"));
}

TEST(UiController, BatchStopsByItselfWhenTheRmsKeepsRising) {
  Configuration c;
  c.model.kappa_rad_per_bar = 0.8;  // a model ten times too weak: the learning overshoots and diverges
  c.ilc.s = 0.0;
  c.ilc.w = 0.0;
  ConsoleFixture f(c, 3);
  f.arm_valves();
  f.run_batch(10);
  const auto rms = f.state().experiment.rms_history_deg();
  const auto rose_three_times_until = [&](std::size_t last) {
    return last >= 3 && rms[last] > rms[last - 1] && rms[last - 1] > rms[last - 2] && rms[last - 2] > rms[last - 3];
  };
  ASSERT_GE(rms.size(), 4u);
  ASSERT_LT(rms.size(), 11u) << "the batch (iterations 0..10) should have stopped by itself";
  EXPECT_TRUE(rose_three_times_until(rms.size() - 1));
  for (std::size_t last = 3; last + 1 < rms.size(); ++last) EXPECT_FALSE(rose_three_times_until(last)) << last;
  EXPECT_TRUE(f.logged("the RMS rose 3 times in a row"));
  EXPECT_TRUE(f.state().status_important);
}

TEST(UiController, EmergencyStopFromAnyScreenAndDialogThenResetAndRearm) {
  ConsoleFixture f;
  // From a dialog: the engine vents, and a notice that the dialog was closed takes the keys typed
  // next until Enter or Esc (UiPrompts.AFaultOrTheStopThatClosesAPrompt...).
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('a');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmArm);
  f.key(' ');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kInterrupted);
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }));
  f.key(key::kEnter);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  f.key('R');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  // From the log screen while a trial runs: the trial is handed back and not counted.
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kRunning; }));
  f.key('l');
  ASSERT_EQ(f.state().screen, Screen::kLog);
  f.key(' ');
  ASSERT_TRUE(f.pump_until([&] { return !f.state().fault_view.black_box.empty() && f.idle(); }));
  EXPECT_EQ(f.state().engine_state, EngineState::kFault);
  EXPECT_EQ(f.state().fault, FaultCode::kEmergencyStop);
  EXPECT_EQ(f.state().screen, Screen::kFault);
  EXPECT_TRUE(f.state().experiment.trials.empty());
  EXPECT_EQ(f.state().fault_view.black_box.back().state, EngineState::kFault);
  const auto& box = f.state().fault_view.black_box;
  EXPECT_TRUE(
      std::any_of(box.begin(), box.end(), [](const TickRecord& t) { return t.state == EngineState::kRunning; }));
  // Arming is refused until the fault is reset.
  f.key('a');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_NE(f.state().status.find("reset it first"), std::string::npos) << f.state().status;
  f.key('R');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  EXPECT_EQ(f.state().screen, Screen::kMain);
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  EXPECT_EQ(f.state().experiment.trials.size(), 1u);
}

TEST(UiController, HeartbeatDrillMakesTheEngineVent) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('H');
  EXPECT_TRUE(f.state().heartbeat_drill);
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }, 5.0));
  EXPECT_EQ(f.core.fault(), FaultCode::kHeartbeatLost);
  f.pump_for(0.1);
  EXPECT_FALSE(f.state().heartbeat_drill);
  EXPECT_TRUE(f.logged("heartbeat drill: the engine vented"));
}

TEST(UiController, InspectorCursorAndGoingBackToAnEarlierCorrection) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(2);  // iterations 0..2
  f.key('c');
  EXPECT_EQ(f.state().screen, Screen::kInspector);
  EXPECT_EQ(f.state().inspector.trial, 2);
  for (int i = 0; i < 3; ++i) f.key(key::kRight);
  f.key(key::kPageDown);
  EXPECT_EQ(f.state().inspector.sample, 43);
  f.key(key::kEnd);
  EXPECT_EQ(f.state().inspector.sample, 400);
  f.key(key::kRight);
  EXPECT_EQ(f.state().inspector.sample, 400);
  f.key(key::kUp);
  f.key('m');
  EXPECT_EQ(f.state().inspector.chosen, 1);
  f.key('u');
  EXPECT_EQ(f.state().experiment.next_origin, "correction of 1");
  EXPECT_FALSE(f.state().experiment.next_tried);
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  const auto& trials = f.state().experiment.trials;
  ASSERT_EQ(trials.size(), 4u);
  EXPECT_EQ(trials[3].origin, "correction of 1");
  EXPECT_TRUE(trials[3].correction_bar.isApprox(trials[1].correction_bar));
  EXPECT_TRUE(f.logged("go back to the correction of iteration 1"));
}

TEST(UiController, TuningChangesGainsAndWeightsBetweenTrialsAndRecordsThem) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('w');
  f.key(key::kDown);  // k_p
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kEditValue);
  EXPECT_EQ(f.state().dialog.input, "0.3");
  for (int i = 0; i < 3; ++i) f.key(key::kBackspace);
  f.type("0.45");
  f.key(key::kEnter);
  EXPECT_DOUBLE_EQ(f.state().config.controller.k_p, 0.45) << f.state().status;
  EXPECT_TRUE(f.logged("k_p changed 0.3 -> 0.45 ([controller] k_p)"));
  EXPECT_TRUE(f.state().experiment.settings_changed);
  // A refused value changes nothing.
  f.key(key::kEnter);
  for (int i = 0; i < 4; ++i) f.key(key::kBackspace);
  f.type("-1");
  f.key(key::kEnter);
  EXPECT_DOUBLE_EQ(f.state().config.controller.k_p, 0.45);
  EXPECT_TRUE(f.state().status_important);
  EXPECT_NE(f.state().status.find("k_p"), std::string::npos) << f.state().status;
  // The question stays open with what was typed and why it was refused; Esc leaves it.
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kEditValue);
  EXPECT_EQ(f.state().dialog.input, "-1");
  EXPECT_NE(f.state().dialog.error.find("k_p"), std::string::npos) << f.state().dialog.error;
  f.key(key::kEscape);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  // A weight rebuilds the law.
  for (int i = 0; i < 4; ++i) f.key(key::kDown);  // k_i, k_d, law, M
  f.key(key::kDown);                              // S
  f.key(key::kEnter);
  for (int i = 0; i < 3; ++i) f.key(key::kBackspace);
  f.type("0.2");
  f.key(key::kEnter);
  EXPECT_DOUBLE_EQ(f.state().config.ilc.s, 0.2);
  EXPECT_FALSE(f.state().law_ready);
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  EXPECT_TRUE(f.logged("S 0.2"));
  // The gains reach the engine: the next trial differs from one with the old gains.
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_EQ(f.state().experiment.trials.size(), 1u);
  EXPECT_GT(std::abs(f.state().experiment.trials[0].summary.rms_deg - 15.06), 0.3);
}

TEST(UiController, TuningChoosesTheLearningLawBetweenTrials) {
  ConsoleFixture f;
  f.arm_valves();
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('w');
  for (int i = 0; i < TuningForm::kLawRow; ++i) f.key(key::kDown);
  ASSERT_EQ(f.state().tuning.selected, TuningForm::kLawRow);
  EXPECT_EQ(f.state().config.ilc.law, "noilc");
  f.key(key::kEnter);  // the next law in the list
  EXPECT_EQ(f.state().config.ilc.law, "noilc-dense") << f.state().status;
  EXPECT_TRUE(f.logged("law changed noilc -> noilc-dense ([ilc] law)"));
  EXPECT_TRUE(f.state().experiment.settings_changed);
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  EXPECT_EQ(f.state().law_name, "noilc-dense");
  f.key(key::kRight);
  f.key(key::kRight);
  f.key(key::kRight);  // noilc-constrained, noilc-learned, pd
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  EXPECT_EQ(f.state().law_name, "pd");
  for (int i = 0; i < 5; ++i)
    f.key(key::kLeft);  // noilc-learned, noilc-constrained, noilc-dense, noilc, round to the last
  ASSERT_EQ(learning_law_names().back(), "inverse");
  EXPECT_EQ(f.state().config.ilc.law, "inverse");
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  EXPECT_EQ(f.state().law_name, "inverse");
  // The law learns: two iterations with it lower the RMS.
  f.run_batch(2);  // iterations 0..2
  const auto rms = f.state().experiment.rms_history_deg();
  ASSERT_EQ(rms.size(), 3u);
  EXPECT_LT(rms[2], rms[0]);
  // Not while trials run.
  f.key('N');
  f.type("5");
  f.key(key::kEnter);
  f.key('w');
  f.key(key::kEnter);
  EXPECT_EQ(f.state().config.ilc.law, "inverse");
  EXPECT_TRUE(f.state().status_important);
  EXPECT_NE(f.state().status.find("between trials"), std::string::npos) << f.state().status;
}

TEST(UiController, EachIterationsLogLineCarriesTheLearningDiagnostics) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(2);                                          // iterations 0..2
  for (const ui::LogEntry& e : f.state().log.entries()) {  // the first trial has nothing to contract from
    if (e.text.rfind("iteration 0: RMS", 0) == 0) {
      EXPECT_EQ(e.text.find("contraction"), std::string::npos) << e.text;
    }
  }
  const auto& trials = f.state().experiment.trials;
  ASSERT_EQ(trials.size(), 3u);
  const double contraction = trials[2].summary.rms_deg / trials[1].summary.rms_deg;  // same N: norms scale alike
  EXPECT_TRUE(f.logged(format("iteration 2: RMS %.3f deg", trials[2].summary.rms_deg)));
  EXPECT_TRUE(f.logged(format("contraction %.3f, correction changed", contraction))) << contraction;
}

TEST(UiController, ChoosingATrajectoryFromTheLibraryOrAFile) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  f.key('t');
  EXPECT_EQ(f.state().screen, Screen::kTrajectory);
  EXPECT_EQ(f.state().chooser.preview->name, "paper");
  f.key(key::kDown);
  ASSERT_TRUE(f.state().chooser.preview);
  EXPECT_EQ(f.state().chooser.preview->name, "steps");
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  f.key(key::kEnter);  // the trial is saved: nothing is lost, nothing to ask
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_EQ(f.state().experiment.trajectory->name, "steps");
  EXPECT_TRUE(f.state().experiment.trials.empty());
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_EQ(f.state().experiment.trials.size(), 1u);
  EXPECT_EQ(f.state().experiment.trials[0].record.learning_samples, 500);

  // A file: a bad one shows why, a good one previews.
  const auto dir = testing::make_temp_dir("bellows-ui");
  const auto bad = testing::write_file(dir, "bad.csv", "time_s,angle_deg\n0,0\n0.02,abc\n");
  std::string good_text = "time_s,angle_deg\n";
  for (int k = 0; k <= 100; ++k) good_text += format("%.2f,%.3f\n", k * 0.02, 10.0 * std::sin(k * 0.05));
  const auto good = testing::write_file(dir, "good.csv", good_text);
  f.key('t');
  for (int i = 0; i < 5; ++i) f.key(key::kDown);
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  f.type(bad.string());
  f.key(key::kEnter);
  f.wait_for_trajectory_file();
  // Refused: the prompt stays open with the path and why (issue 23).
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  EXPECT_NE(f.state().dialog.error.find("bad.csv"), std::string::npos) << f.state().dialog.error;
  for (std::size_t i = 0; i < bad.string().size(); ++i) f.key(key::kBackspace);
  f.type(good.string());
  f.key(key::kEnter);
  f.wait_for_trajectory_file();
  ASSERT_TRUE(f.state().chooser.preview) << f.state().chooser.preview_error;
  EXPECT_EQ(f.state().chooser.preview->learning_samples(), 100);
  f.key(key::kEnter);
  f.key('y');
  EXPECT_EQ(f.state().experiment.samples(), 100);
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('n');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  EXPECT_EQ(f.state().experiment.trials.size(), 1u);
}

TEST(UiController, RefusalsAreExplainedAndSendNothing) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('r');
  EXPECT_NE(f.state().status.find("arm the valves first"), std::string::npos) << f.state().status;
  f.key('c');
  EXPECT_NE(f.state().status.find("no trial has run yet"), std::string::npos);
  f.pump_for(0.2);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
  EXPECT_TRUE(f.state().experiment.trials.empty());
}

TEST(UiController, SavesAsItGoesAndOpensFromTheSession) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(2);  // iterations 0..2
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  ASSERT_EQ(f.sessions.saved.size(), 1u);
  const SessionSnapshot& saved = f.sessions.saved.begin()->second;
  EXPECT_EQ(saved.experiment.trials.size(), 3u);
  EXPECT_FALSE(saved.events.empty());
  EXPECT_FALSE(f.state().experiment.unsaved());
  EXPECT_EQ(f.state().experiment.session_location, "mem://0");
  // The correction learned from the last trial of the batch is saved as its next correction.
  EXPECT_TRUE(saved.experiment.next_correction_bar.isApprox(f.state().experiment.next_correction_bar));

  // Another trial: saved without asking, into the same session.
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.trials.size(), 4u);
  const auto rms = f.state().experiment.rms_history_deg();
  // Open it (valves vented first): nothing to discard, it comes from what was saved.
  f.key('o');
  EXPECT_NE(f.state().status.find("disarm first"), std::string::npos) << f.state().status;
  f.key('d');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  f.key('o');
  ASSERT_TRUE(f.pump_until([&] { return !f.state().browser.loading; }));
  ASSERT_EQ(f.state().browser.sessions.size(), 1u);
  EXPECT_EQ(f.state().browser.sessions[0].iterations, 4);
  f.key(key::kEnter);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  ASSERT_TRUE(f.pump_until([&] { return !f.state().learner_busy && f.state().law_ready; }));
  EXPECT_EQ(f.state().experiment.rms_history_deg(), rms);
  EXPECT_FALSE(f.state().experiment.unsaved());
  // Learning continues from the opened session.
  f.arm_valves();
  f.key('n');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  EXPECT_EQ(f.state().experiment.trials.size(), 5u);
  EXPECT_EQ(f.state().experiment.trials[4].origin, "learned from 3");
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.trials.size(), 5u);
}

TEST(UiController, ATrialWaitsForTheSaveAndAFailedSaveStopsTrials) {
  ConsoleFixture f;
  f.arm_valves();
  f.sessions.fail_saves = true;
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  EXPECT_TRUE(f.logged("save failed: disk full (test)"));
  EXPECT_TRUE(f.state().experiment.unsaved());
  // No trial starts while the session cannot be saved: asking retries the save, which fails again.
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  EXPECT_EQ(f.state().experiment.trials.size(), 1u);
  // Quit asks now (the work is not on disk); once saving works, it saves and quits.
  f.key('q');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmQuit);
  f.sessions.fail_saves = false;
  f.key('s');
  ASSERT_TRUE(f.pump_until([&] { return f.console->quit_requested(); }));
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.trials.size(), 1u);
}

TEST(UiController, QuitAsksWhileArmedThenFinishesTheSaveAndDisarms) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  f.key('q');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmQuit);  // the valves are live: it asks
  f.key('y');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  ASSERT_TRUE(f.pump_until([&] { return f.console->quit_requested(); }));
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.trials.size(), 1u);
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kSafe; }));
}

TEST(UiController, MemoryHoldsOnlyTheNewestTrialsAndTheEngineHandsTrajectoriesBack) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(Experiment::kTrialsKeptInMemory + 3);  // iterations 0..kept + 3
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  const auto& trials = f.state().experiment.trials;
  ASSERT_EQ(trials.size(), static_cast<std::size_t>(Experiment::kTrialsKeptInMemory + 4));
  int in_memory = 0;
  for (const Trial& t : trials) in_memory += t.in_memory() ? 1 : 0;
  EXPECT_EQ(in_memory, Experiment::kTrialsKeptInMemory);
  EXPECT_TRUE(trials.back().in_memory());
  EXPECT_FALSE(trials.front().in_memory());
  EXPECT_GT(trials.front().summary.rms_deg, 0.0);  // the RMS history stays whole
  // The session on disk (here: in memory) has every record.
  for (const Trial& t : f.sessions.saved.begin()->second.experiment.trials) EXPECT_TRUE(t.in_memory());
}

TEST(UiExperiment, TheUnsavedSentenceNamesWhatASaveWouldAdd) {
  Experiment e;
  EXPECT_EQ(e.unsaved_sentence(), "");
  e.trials.resize(3);
  e.saved_trials = 2;
  EXPECT_EQ(e.unsaved_sentence(), "iteration 2 is not saved.");
  e.saved_trials = 0;
  EXPECT_EQ(e.unsaved_sentence(), "3 iterations (0-2) are not saved.");
  e.faults.resize(1);
  EXPECT_EQ(e.unsaved_sentence(), "3 iterations (0-2) and 1 fault's black box are not saved.");
  e.settings_changed = true;
  EXPECT_EQ(e.unsaved_sentence(), "3 iterations (0-2), 1 fault's black box and changed settings are not saved.");
  e.saved_trials = 3;
  e.faults.resize(2);
  e.settings_changed = false;
  EXPECT_EQ(e.unsaved_sentence(), "2 faults' black boxes are not saved.");
  e.saved_faults = 2;
  e.settings_changed = true;
  EXPECT_EQ(e.unsaved_sentence(), "changed settings are not saved.");
  e.settings_changed = false;
  e.next_unsaved = true;  // learned after the last trial was saved
  EXPECT_EQ(e.unsaved_sentence(), "the correction learned from iteration 2 is not saved.");
}

TEST(UiController, AFaultsBlackBoxIsSavedAtOnceAndAStopIsVentedOnlyWhenTheEngineActed) {
  ConsoleFixture f;
  f.arm_valves();
  f.key(' ');
  // Requested, not yet acted on (no tick since): the console does not claim the valves vented.
  EXPECT_EQ(f.state().status.find("valves vented"), std::string::npos) << f.state().status;
  EXPECT_NE(f.state().status.find("EMERGENCY STOP requested"), std::string::npos) << f.state().status;
  ASSERT_TRUE(f.pump_until([&] { return !f.state().experiment.faults.empty() && f.console->saves_settled(); }));
  EXPECT_TRUE(f.logged("emergency stop: valves vented"));
  EXPECT_TRUE(f.logged("ARMED -> FAULT (emergency-stop)"));
  ASSERT_EQ(f.sessions.saved.size(), 1u);  // the black box made the session
  EXPECT_EQ(f.sessions.saved.begin()->second.experiment.faults.size(), 1u);
  f.key('q');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_TRUE(f.console->quit_requested());
}

TEST(UiController, AStopWithAFullCommandQueueStillVentsInTheNextTick) {
  ConsoleFixture f;
  f.arm_valves();
  while (f.core.send(EngineCommand::of(CommandKind::kHeartbeat))) {
  }
  f.key(' ');
  f.clock.step(1);
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  EXPECT_EQ(f.core.fault(), FaultCode::kEmergencyStop);
  f.console->update(f.clock.now_s());
  EXPECT_TRUE(f.logged("emergency stop: valves vented"));
}

TEST(UiController, WithoutASessionStoreSaveSaysSo) {
  Configuration c;
  SimulatedArm arm(c.plant, 1);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  UnavailableSessionGateway none("the session store is not part of this build yet");
  ConsoleEnvironment env;
  env.core = &core;
  env.config = c;
  env.sessions = &none;
  ConsoleController console(env, library_trajectory("paper", 0.02), false);
  console.start(0.0);
  console.handle_key('s', 0.0);
  EXPECT_NE(console.state().status.find("not part of this build"), std::string::npos) << console.state().status;
  console.handle_key('q', 0.0);  // nothing can be saved: quit does not wait for a save
  EXPECT_TRUE(console.quit_requested());
  console.handle_key('o', 0.0);
  EXPECT_EQ(console.state().screen, Screen::kMain);
}

TEST(UiController, AfterAnEmergencyStopTheLivePanelShowsTheRealState) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.state().run.sample > 150; }));  // mid-trial, the arm well off zero
  f.key(' ');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }));
  f.pump_for(3.0);          // vented, the arm sags
  f.key(ui::key::kEscape);  // from the fault screen the stop opened, back to the main one
  ASSERT_EQ(f.state().screen, Screen::kMain);
  const TickRecord& live = f.state().live;
  ASSERT_EQ(live.state, EngineState::kFault);
  const std::string screen = testing::all(render_lines(f.state()));
  EXPECT_NE(screen.find("set point  none: vented"), std::string::npos) << screen;
  EXPECT_NE(screen.find("error      no trial"), std::string::npos) << screen;
  // The angle shown is the latest reading, not where the trial was.
  EXPECT_NE(screen.find(format("angle      %7.2f deg", live.reading.joint[0].angle_rad * 180.0 / std::numbers::pi)),
            std::string::npos)
      << screen;
  EXPECT_GT(std::abs(live.joint(0).desired_rad - live.reading.joint[0].angle_rad) * 180.0 / std::numbers::pi, 1.0)
      << "the engine keeps its last set point: the panel must not show it as a tracking error";
}

TEST(UiController, TheBrowserShowsEachSessionsDeviceAndRefusesAnotherOnesBeforeOpening) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  f.key('d');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  {
    const std::lock_guard<std::mutex> guard(f.sessions.mutex);
    ASSERT_EQ(f.sessions.saved.size(), 1u);
    f.sessions.saved.begin()->second.device_name = "t7";  // as if recorded at the bench
  }
  f.key('o');
  ASSERT_TRUE(f.pump_until([&] { return !f.state().browser.loading; }));
  ASSERT_EQ(f.state().browser.sessions.size(), 1u);
  const ui::SessionListing& l = f.state().browser.sessions[0];
  EXPECT_EQ(l.device, "t7");
  EXPECT_EQ(l.refusal, "recorded on the device 't7'; this console drives 'sim'");
  const std::string screen = testing::all(render_lines(f.state()));
  EXPECT_NE(screen.find("t7"), std::string::npos) << screen;
  EXPECT_NE(screen.find("cannot open it here: recorded on the device 't7'"), std::string::npos) << screen;
  const int saves = f.sessions.saves;
  f.key(ui::key::kEnter);
  EXPECT_NE(f.state().status.find("cannot be opened here: recorded on the device 't7'"), std::string::npos)
      << f.state().status;
  EXPECT_FALSE(f.state().learner_busy);  // nothing was opened
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  f.pump_for(0.5);
  EXPECT_EQ(f.state().experiment.trials.size(), 1u);
  EXPECT_EQ(f.sessions.saves, saves);
}

// A save still running when the operator moves on (a trajectory chosen, its unsaved trials
// discarded) belongs to the experiment it saved: the new experiment keeps no location and no saved
// count of it, and its own first save makes a session of its own (before, it took the old session's
// location, and its trials would have gone into the old session, of another trajectory).
TEST(UiController, ASaveThatEndsAfterATrajectorySwitchStaysWithTheExperimentItSaved) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');  // iteration 0, saved as it goes
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  const std::string paper_location = f.state().experiment.session_location;
  ASSERT_FALSE(paper_location.empty());
  f.sessions.hold_saves = true;
  f.key('r');  // iteration 1: its save is held
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && !f.console->saves_settled(); }, 60.0));
  f.key('t');
  f.key(ui::key::kDown);  // steps
  f.key(ui::key::kEnter);
  if (f.state().dialog.kind == ui::DialogKind::kConfirmDiscard) f.key('y');
  ASSERT_EQ(f.state().experiment.trajectory->name, "steps");
  f.sessions.hold_saves = false;
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  EXPECT_TRUE(f.state().experiment.session_location.empty()) << f.state().experiment.session_location;
  EXPECT_EQ(f.state().experiment.saved_trials, 0);
  EXPECT_TRUE(f.logged("the last save of the experiment left behind finished: " + paper_location));
  EXPECT_EQ(f.sessions.open(paper_location).experiment.trials.size(), 2u);  // both paper trials, on disk
  f.key('r');                                                               // steps' iteration 0: a session of its own
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  const std::string steps_location = f.state().experiment.session_location;
  EXPECT_FALSE(steps_location.empty());
  EXPECT_NE(steps_location, paper_location);
  EXPECT_EQ(f.sessions.open(paper_location).experiment.trials.size(), 2u);
  EXPECT_EQ(f.sessions.open(steps_location).experiment.trajectory->name, "steps");
}

}  // namespace
}  // namespace bellows::ui
