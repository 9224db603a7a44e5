// The operator's mistakes and the emergency stop, against a real engine on a simulated clock:
// Space vents from every screen and every dialog; a key that does nothing here, a bad K, a bad file
// path, a bad trajectory file and a bad number each say why, and lose nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>

#include "tests/console_fixture.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;

bool has(const std::string& text, const std::string& fragment) { return text.find(fragment) != std::string::npos; }

void clear_input(ConsoleFixture& f) {
  while (!f.state().dialog.input.empty()) f.key(key::kBackspace);
}

// Space from where `go_there` leaves the console: the engine vents (FAULT), and a dialog being
// answered gives way to the notice that takes the keys typed next until Enter
// (UiPrompts.AFaultOrTheStopThatClosesAPrompt...); then reset, so the next case starts from SAFE.
void expect_stop_from(ConsoleFixture& f, const std::string& where, const std::function<void()>& go_there) {
  SCOPED_TRACE(where);
  go_there();
  const bool dialog_open = f.state().dialog.kind != DialogKind::kNone;
  f.key(' ');
  EXPECT_EQ(f.state().dialog.kind, dialog_open ? DialogKind::kInterrupted : DialogKind::kNone);
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kFault && f.idle(); }));
  EXPECT_EQ(f.core.fault(), FaultCode::kEmergencyStop);
  EXPECT_TRUE(f.logged("EMERGENCY STOP (Space)"));
  if (dialog_open) f.key(key::kEnter);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  f.key('R');
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kSafe; }));
}

TEST(UiInput, EmergencyStopFromEveryScreenAndEveryDialog) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_EQ(f.state().experiment.trials.size(), 1u);
  const auto armed = [&](const std::function<void()>& then) {
    return [&f, then] {
      f.arm_valves();
      then();
    };
  };
  const auto running = [&](int screen_key) {
    return [&f, screen_key] {
      f.arm_valves();
      f.key('r');
      ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kRunning; }));
      if (screen_key != 0) f.key(screen_key);
    };
  };
  expect_stop_from(f, "main, trial running", running(0));
  expect_stop_from(f, "help, trial running", running('?'));
  expect_stop_from(f, "inspector, trial running", running('c'));
  expect_stop_from(f, "log, trial running", running('l'));
  expect_stop_from(f, "tuning, trial running", running('w'));
  expect_stop_from(f, "arm dialog", [&] { f.key('a'); });
  expect_stop_from(f, "K dialog", armed([&] { f.key('N'); }));
  expect_stop_from(f, "trajectory chooser", armed([&] { f.key('t'); }));
  expect_stop_from(f, "trajectory path dialog", armed([&] {
                     f.key('t');
                     for (std::size_t i = 0; i < trajectory_library_names().size(); ++i)
                       f.key(key::kDown);  // to "from a file..."
                     f.key(key::kEnter);
                     ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
                   }));
  // Discarding asks only about work not on disk: a trial whose save failed (whether an autosave has
  // finished by now depends on the machine's speed; a failed one does not).
  expect_stop_from(f, "discard dialog", armed([&] {
                     ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
                     f.sessions.fail_saves = true;
                     f.key('r');  // a completed trial (counted), whose save fails
                     ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
                     f.key('t');
                     f.key(key::kDown);  // steps
                     f.key(key::kEnter);
                     ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmDiscard);
                   }));
  expect_stop_from(f, "tuning value dialog", armed([&] {
                     f.key('w');
                     f.key(key::kEnter);
                     ASSERT_EQ(f.state().dialog.kind, DialogKind::kEditValue);
                   }));
  // Quit asks only when the work is not on disk: a save that failed.
  expect_stop_from(f, "quit dialog", armed([&] {
                     f.sessions.fail_saves = true;
                     f.key('r');
                     ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
                     f.key('q');
                     ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmQuit);
                   }));
  f.sessions.fail_saves = false;
  expect_stop_from(f, "session browser (SAFE)", [&] {
    f.key('o');
    ASSERT_EQ(f.state().screen, Screen::kSessions);
  });
  expect_stop_from(f, "fault screen", armed([&] { f.key('f'); }));
  // Too small to show the console: Space still stops.
  f.arm_valves();
  f.console->resize(60, 20);
  f.key(' ');
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kFault && f.idle(); }));
  f.console->resize(120, 40);
  EXPECT_FALSE(f.console->quit_requested());
  EXPECT_EQ(f.state().experiment.trials.size(), 2u);  // the stopped trials are not counted (the two completed are)
}

TEST(UiInput, AKeyThatDoesNothingHereSaysSo) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('z');
  EXPECT_TRUE(f.state().status_important);
  EXPECT_TRUE(has(f.state().status, "z does nothing here; ? lists every key")) << f.state().status;
  f.key(key::kLeft);  // the inspector's key, on the main screen
  EXPECT_TRUE(has(f.state().status, "Left does nothing here")) << f.state().status;
  f.key(key::kOther);  // e.g. F5
  EXPECT_TRUE(has(f.state().status, "this key does nothing here")) << f.state().status;
  // A y/n question: a wrong key is named and the question stays.
  f.key('a');
  f.key('x');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmArm);
  EXPECT_TRUE(has(f.state().dialog.error, "x is not an answer here: y arm")) << f.state().dialog.error;
  f.key('n');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  // Too small: only Space and q work, and other keys say so.
  f.console->resize(70, 20);
  f.key('a');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_TRUE(has(f.state().status, "too small")) << f.state().status;
  f.console->resize(120, 40);
  f.pump_for(0.2);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
}

TEST(UiInput, ABadKKeepsTheQuestionAndWhatWasTyped) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('N');
  for (const std::string bad : {"abc", "0", "2.5", "1001", "-3", "5x"}) {
    SCOPED_TRACE(bad);
    clear_input(f);
    f.type(bad);
    f.key(key::kEnter);
    ASSERT_EQ(f.state().dialog.kind, DialogKind::kAskIterations);
    EXPECT_EQ(f.state().dialog.input, bad);
    EXPECT_TRUE(has(f.state().dialog.error, "K must be a whole number from 1 to 1000, not '" + bad + "'"))
        << f.state().dialog.error;
    EXPECT_TRUE(f.idle());
  }
  f.key(key::kBackspace);  // editing clears the complaint
  EXPECT_TRUE(f.state().dialog.error.empty());
  clear_input(f);
  f.type("2");
  f.key(key::kEnter);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  EXPECT_EQ(f.state().experiment.trials.size(), 3u);  // the good K ran: iterations 0..2 (docs/iterations.md)
}

TEST(UiInput, TheChooserListsMultiJointTrajectoriesAndSaysWhyNotYet) {
  ConsoleFixture f;
  f.key('t');
  ASSERT_EQ(f.state().screen, Screen::kTrajectory);
  const auto& names = f.state().chooser.names;
  const auto paper2 = std::find(names.begin(), names.end(), "paper2");
  ASSERT_NE(paper2, names.end());
  EXPECT_TRUE(has(f.state().chooser.descriptions[static_cast<std::size_t>(paper2 - names.begin())], "2 joints"));
  for (auto i = names.begin(); i != paper2; ++i) f.key(key::kDown);
  EXPECT_FALSE(f.state().chooser.preview);
  EXPECT_EQ(f.state().chooser.preview_error, "trajectory 'paper2' has 2 joints; the arm has 1 ([arm] preset)");
  f.key(key::kEnter);  // nothing to use: the paper stays
  EXPECT_EQ(f.state().screen, Screen::kTrajectory);
  EXPECT_EQ(f.state().experiment.trajectory->name, "paper");
}

TEST(UiInput, BadTrajectoryPathsAndFilesSayWhyAndChangeNothing) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("ui_input_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string bad_file = (dir / "bad.csv").string();
  std::ofstream(bad_file) << "time_s,angle_deg\n0,0\n0.02,abc\n";
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  f.key('t');
  for (std::size_t i = 0; i < trajectory_library_names().size(); ++i) f.key(key::kDown);  // to "from a file..."
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  f.key(key::kEnter);  // nothing typed
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  EXPECT_TRUE(has(f.state().dialog.error, "type the path of a CSV file")) << f.state().dialog.error;
  const std::string missing = (dir / "missing.csv").string();
  f.type(missing);
  f.key(key::kEnter);
  f.wait_for_trajectory_file();
  // Refused: the prompt stays open with the path and the reason (issue 23), the preview as it was.
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  EXPECT_EQ(f.state().dialog.input, missing);
  EXPECT_FALSE(f.state().chooser.preview);
  EXPECT_TRUE(has(f.state().dialog.error, "cannot be read")) << f.state().dialog.error;
  EXPECT_TRUE(f.state().status_important);
  EXPECT_TRUE(has(f.state().status, "missing.csv")) << f.state().status;
  clear_input(f);
  f.type(bad_file);
  f.key(key::kEnter);
  f.wait_for_trajectory_file();
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  EXPECT_TRUE(has(f.state().dialog.error, "line 3: 'abc' is not a number")) << f.state().dialog.error;
  f.key(key::kEscape);
  // Nothing changed: the trajectory, the trial, the valves.
  EXPECT_EQ(f.state().experiment.trajectory->name, "paper");
  EXPECT_EQ(f.state().experiment.trials.size(), 1u);
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  std::filesystem::remove_all(dir);
}

TEST(UiInput, ABadNumberForAWeightKeepsTheQuestionAndChangesNothing) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('w');
  for (int i = 0; i < TuningForm::kLawRow + 1; ++i) f.key(key::kDown);  // past the gains and the law: M
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kEditValue);
  EXPECT_EQ(f.state().dialog.title, "Change M");
  for (const std::string bad : {"abc", "1e999", "-1", "2,5"}) {
    SCOPED_TRACE(bad);
    clear_input(f);
    f.type(bad);
    f.key(key::kEnter);
    ASSERT_EQ(f.state().dialog.kind, DialogKind::kEditValue);
    EXPECT_EQ(f.state().dialog.input, bad);
    EXPECT_FALSE(f.state().dialog.error.empty());
    EXPECT_DOUBLE_EQ(f.state().config.ilc.m, 1.0);
    EXPECT_TRUE(f.state().law_ready);
    EXPECT_FALSE(f.state().experiment.settings_changed);
  }
  f.key(key::kEscape);
  EXPECT_FALSE(f.logged("M changed"));
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
}

}  // namespace
}  // namespace bellows::ui
