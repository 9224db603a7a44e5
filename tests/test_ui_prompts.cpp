// Keys never do what the operator did not mean (issue 23): every prompt and every question of the
// console keeps the focus until it takes an answer or Esc, so nothing typed into one reaches the
// command table. For each: a refused answer, then a string full of command letters, then Esc; no
// trial ran, the arm's state and the session are unchanged, and the prompt showed what was typed.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>

#include "app/console_sessions.hpp"
#include "sessions/session_store.hpp"
#include "tests/console_fixture.hpp"
#include "tests/process_runner.hpp"
#include "ui/canvas.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::ConsoleFixture;

bool prompt_has(const std::string& text, const std::string& fragment) {
  return text.find(fragment) != std::string::npos;
}

// Every command key of the console but Space (the emergency stop, which works in prompts too):
// typed into a prompt, none may run.
const std::string kCommandLetters = "brdnNaxtcwlsofgHjTRqv?zmu";

std::string prompt_screen_text(const ConsoleState& state) {
  Canvas canvas(state.width, state.height);
  render(state, canvas);
  return canvas.text();
}

// Types UTF-8 text as the terminal delivers it: one key per code point.
void type_text(ConsoleFixture& f, const std::string& text) {
  for (char32_t c : decode_utf8(text)) f.key(static_cast<int>(c));
}

struct Before {
  std::size_t trials;
  EngineState engine;
  std::string session;
  std::string trajectory;
  std::size_t log_entries;
};

Before before_of(const ConsoleFixture& f) {
  return {f.state().experiment.trials.size(), f.core.state(), f.state().experiment.session_location,
          f.state().experiment.trajectory->name, f.state().log.total()};
}

void expect_unchanged(ConsoleFixture& f, const Before& before) {
  f.pump_for(0.5);  // a trial started by a stray key would be running by now
  EXPECT_EQ(f.state().experiment.trials.size(), before.trials);
  EXPECT_EQ(f.core.state(), before.engine);
  EXPECT_TRUE(f.idle());
  EXPECT_EQ(f.state().experiment.session_location, before.session);
  EXPECT_EQ(f.state().experiment.trajectory->name, before.trajectory);
  EXPECT_FALSE(f.logged("operator run")) << "a trial ran from a key typed into a prompt";
  for (std::size_t i = before.log_entries; i < f.state().log.total(); ++i) {
    const LogEntry& e = f.state().log.entries()[i - (f.state().log.total() - f.state().log.entries().size())];
    EXPECT_NE(e.source, LogSource::kOperator) << "the operator did something: " << e.text;
  }
}

// The prompt `open` opens refuses `refused`, then takes the command letters as text; Esc closes it.
void expect_prompt_keeps_focus(ConsoleFixture& f, DialogKind kind, const std::function<void()>& open,
                               const std::string& refused) {
  const Before before = before_of(f);
  const Screen screen = f.state().screen;
  open();
  ASSERT_EQ(f.state().dialog.kind, kind);
  f.key(key::kClearLine);  // Ctrl-U clears the field
  EXPECT_EQ(f.state().dialog.input, "");
  type_text(f, refused);
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, kind) << "a refused answer closed the prompt";
  EXPECT_EQ(f.state().dialog.input, refused);
  EXPECT_FALSE(f.state().dialog.error.empty());
  EXPECT_TRUE(prompt_has(prompt_screen_text(f.state()), refused)) << prompt_screen_text(f.state());
  f.type(kCommandLetters);
  EXPECT_EQ(f.state().dialog.kind, kind);
  EXPECT_EQ(f.state().dialog.input, refused + kCommandLetters);
  EXPECT_TRUE(prompt_has(prompt_screen_text(f.state()), refused + kCommandLetters)) << prompt_screen_text(f.state());
  f.key(key::kUp);  // a screen's key: named, not obeyed
  EXPECT_EQ(f.state().dialog.kind, kind);
  f.key(key::kEscape);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_EQ(f.state().screen, screen);  // back where it was opened
  expect_unchanged(f, before);
}

// A question takes only its answers: every other command letter is named and the question stays.
void expect_question_keeps_focus(ConsoleFixture& f, DialogKind kind, const std::function<void()>& open,
                                 const std::string& answers) {
  const Before before = before_of(f);
  open();
  ASSERT_EQ(f.state().dialog.kind, kind);
  for (char k : kCommandLetters) {
    if (answers.find(k) != std::string::npos) continue;
    f.key(k);
    ASSERT_EQ(f.state().dialog.kind, kind) << "'" << k << "' closed the question";
  }
  f.key(key::kEscape);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  expect_unchanged(f, before);
}

void to_file_entry(ConsoleFixture& f) {
  f.key('t');
  ASSERT_EQ(f.state().screen, Screen::kTrajectory);
  for (std::size_t i = 0; i < trajectory_library_names().size(); ++i) f.key(key::kDown);
}

TEST(UiPrompts, EveryPromptKeepsTheFocusUntilAnAnswerIsTaken) {
  ConsoleFixture f;
  f.arm_valves();  // the valves live: a stray r or n would run a trial
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));

  SCOPED_TRACE("K (N)");
  expect_prompt_keeps_focus(
      f, DialogKind::kAskIterations, [&] { f.key('N'); }, "2.5");
  {
    SCOPED_TRACE("K out of range");
    f.key('N');
    f.key(key::kClearLine);
    f.type(std::string(400, '7'));
    f.key(key::kEnter);
    EXPECT_TRUE(prompt_has(f.state().dialog.error, "(out of range)")) << f.state().dialog.error;
    f.key(key::kEscape);
  }
  {
    SCOPED_TRACE("the CSV path (t, the file entry)");
    to_file_entry(f);
    expect_prompt_keeps_focus(
        f, DialogKind::kTrajectoryPath, [&] { f.key(key::kEnter); }, "/nonexistent.csv");
    EXPECT_EQ(f.state().screen, Screen::kTrajectory);
    f.key(key::kEscape);
  }
  {
    SCOPED_TRACE("a gain or weight (w, Enter)");
    f.key('w');
    const double k_p = f.state().config.controller.k_p;
    expect_prompt_keeps_focus(
        f, DialogKind::kEditValue,
        [&] {
          f.key(key::kDown);  // k_p
          f.key(key::kEnter);
        },
        "０.５");
    EXPECT_EQ(f.state().config.controller.k_p, k_p);
    EXPECT_FALSE(f.logged("changed"));
    f.key('w');
    f.key(key::kEnter);
    f.key(key::kClearLine);
    f.type("1" + std::string(399, '0'));
    f.key(key::kEnter);
    EXPECT_TRUE(prompt_has(f.state().dialog.error, "is out of range")) << f.state().dialog.error;
    f.key(key::kEscape);
    f.key(key::kEscape);
  }
}

TEST(UiPrompts, EveryQuestionTakesOnlyItsAnswers) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  expect_question_keeps_focus(
      f, DialogKind::kConfirmArm, [&] { f.key('a'); }, "yYnNq");
  f.arm_valves();
  {
    SCOPED_TRACE("the valve test (b, v)");
    f.key('d');
    ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kSafe; }));
    f.key('b');
    expect_question_keeps_focus(
        f, DialogKind::kConfirmValveTest, [&] { f.key('v'); }, "yYnNq");
    f.key(key::kEscape);
  }
}

// Armed, a trajectory that starts elsewhere moves the arm at once (the engine holds its start, and
// the arm question promised the old one): the console asks first, naming both starts; no leaves the
// trajectory and the hold, yes moves the arm there.
TEST(UiPrompts, ATrajectoryStartingElsewhereAsksBeforeTheArmMoves) {
  const std::filesystem::path dir = bellows::testing::make_temp_dir("bellows-ui-prompts");
  std::string text = "time_s,angle_deg\n";
  for (int k = 0; k <= 100; ++k) text += format("%.2f,40\n", k * 0.02);
  const std::filesystem::path far = bellows::testing::write_file(dir, "far.csv", text);
  ConsoleFixture f;
  f.arm_valves();
  to_file_entry(f);
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kTrajectoryPath);
  f.type(far.string());
  f.key(key::kEnter);  // the preview, once read
  f.wait_for_trajectory_file();
  ASSERT_TRUE(f.state().chooser.preview) << f.state().chooser.preview_error;
  expect_question_keeps_focus(
      f, DialogKind::kConfirmStartMove, [&] { f.key(key::kEnter); }, "yYnNq");
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmStartMove);
  EXPECT_TRUE(prompt_has(prompt_screen_text(f.state()), "0.0 -> 40.0 deg")) << prompt_screen_text(f.state());
  f.key('n');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_EQ(f.state().experiment.trajectory->name, "paper");
  f.pump_for(1.0);
  EXPECT_NEAR(f.state().strip.angle_deg.back(), 0.0, 3.0) << "the arm moved after no";
  f.key(key::kEnter);
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmStartMove);
  f.key('y');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_EQ(f.state().experiment.samples(), 100);
  f.pump_for(3.0);
  EXPECT_NEAR(f.state().strip.angle_deg.back(), 40.0, 3.0);
}

TEST(UiPrompts, QuitAsksWhileTheValvesAreLiveAndTheEngineGoesOnUntilYes) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kRunning; }));
  EXPECT_TRUE(prompt_has(render_lines(f.state()).back(), "q Quit")) << "q Quit left the function bar while RUNNING";
  f.key('q');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmQuit);
  EXPECT_TRUE(prompt_has(prompt_screen_text(f.state()), "A trial is running with the valves live."))
      << prompt_screen_text(f.state());
  f.pump_for(0.5);
  EXPECT_EQ(f.core.state(), EngineState::kRunning);  // the engine goes on while the question waits
  EXPECT_FALSE(f.console->quit_requested());
  f.key('n');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  f.pump_for(0.2);
  EXPECT_EQ(f.core.state(), EngineState::kRunning);
  EXPECT_FALSE(f.console->quit_requested());
  f.key('q');
  f.key('y');
  ASSERT_TRUE(f.pump_until([&] { return f.console->quit_requested(); }));
  ASSERT_TRUE(f.pump_until([&] { return !valves_live(f.core.state()); }));  // quitting vents
}

TEST(UiPrompts, QuitDoesNotAskWhenVentedAndSaved) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('q');
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_TRUE(f.console->quit_requested());
}

TEST(UiPrompts, QAndEscCloseHelpAndQuestionsBackToWhereTheyCameFrom) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  f.key('c');
  ASSERT_EQ(f.state().screen, Screen::kInspector);
  for (int close : {static_cast<int>('q'), key::kEscape, static_cast<int>('?')}) {
    f.key('?');
    ASSERT_EQ(f.state().screen, Screen::kHelp);
    f.key(close);
    EXPECT_EQ(f.state().screen, Screen::kInspector) << key_name(close);
    EXPECT_FALSE(f.console->quit_requested());
    EXPECT_EQ(f.core.state(), EngineState::kArmed);
  }
  f.key('d');
  ASSERT_TRUE(f.pump_until([&] { return f.core.state() == EngineState::kSafe; }));
  f.key('a');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kConfirmArm);
  f.key('q');  // closes the question: not armed, not quit
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_EQ(f.state().screen, Screen::kInspector);
  EXPECT_FALSE(f.console->quit_requested());
  f.pump_for(0.2);
  EXPECT_EQ(f.core.state(), EngineState::kSafe);
}

TEST(UiPrompts, CtrlLRepaintsFromAnywhereAndChangesNothing) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key(key::kRepaint);
  EXPECT_EQ(f.console->repaints(), 1u);
  f.key('a');
  f.key(key::kRepaint);  // in a question too
  EXPECT_EQ(f.console->repaints(), 2u);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kConfirmArm);
  EXPECT_TRUE(f.state().dialog.error.empty());
  EXPECT_FALSE(prompt_has(f.state().status, "does nothing here")) << f.state().status;
}

TEST(UiPrompts, AStatusBelongsToTheScreenItWasSaidOn) {
  ConsoleFixture f;
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('z');  // "z does nothing here", on the main screen
  ASSERT_TRUE(
      prompt_has(render_lines(f.state())[static_cast<std::size_t>(f.state().height - 2)], "z does nothing here"));
  f.key('l');
  for (const std::string& line : render_lines(f.state())) EXPECT_FALSE(prompt_has(line, "z does nothing here")) << line;
  f.key(key::kEscape);
  EXPECT_TRUE(
      prompt_has(render_lines(f.state())[static_cast<std::size_t>(f.state().height - 2)], "z does nothing here"));
}

/// The name prompt on the real session store: a refused name keeps it open; a taken one renames the
/// directory and the manifest's name, through the store's one rename (`sessions rename`'s).
// A fault or the emergency stop that closes a prompt while the operator types into it: the keys typed
// next (the rest of the answer) go to a notice until Enter or Esc, never to the command table. Typed
// as commands, "Ready" would reset the fault (R), open the arm question (a) and answer it (y).
TEST(UiPrompts, AFaultOrTheStopThatClosesAPromptTakesTheKeysTypedNextUntilEnter) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('H');  // the heartbeat drill: the engine faults within its heartbeat limit
  f.key('N');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kAskIterations);
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kFault; }, 5.0));
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kInterrupted);
  EXPECT_TRUE(prompt_has(prompt_screen_text(f.state()), "Closed by the fault heartbeat-lost"))
      << prompt_screen_text(f.state());
  type_text(f, "Ready");
  f.pump_for(0.5);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kInterrupted);
  EXPECT_EQ(f.core.state(), EngineState::kFault) << "a key typed after the fault reset or armed";
  EXPECT_FALSE(f.logged("operator reset"));
  f.key('q');  // the quit key does not close the notice either: what follows would be commands again
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kInterrupted);
  f.key(key::kEnter);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
  EXPECT_EQ(f.core.state(), EngineState::kFault);

  f.key('R');
  ASSERT_TRUE(f.pump_until([&] { return f.state().engine_state == EngineState::kSafe; }));
  f.arm_valves();
  const Before before = before_of(f);
  f.key('N');
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kAskIterations);
  f.key(' ');  // the emergency stop, from the prompt
  ASSERT_EQ(f.state().dialog.kind, DialogKind::kInterrupted);
  type_text(f, "rn");
  f.pump_for(0.5);
  EXPECT_EQ(f.state().experiment.trials.size(), before.trials) << "a trial ran from a key typed after the stop";
  EXPECT_FALSE(f.logged("operator run"));
  f.key(key::kEscape);
  EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
}

// x while the next trial waits for the last one's save to finish: the trial does not begin.
TEST(UiPrompts, StopWhileATrialWaitsForTheSaveKeepsItFromBeginning) {
  ConsoleFixture f;
  f.arm_valves();
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
  f.sessions.hold_saves = true;  // the next save runs until released
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.state().experiment.trials.size() == 2u && !f.console->saves_settled(); }));
  f.key('n');  // learns, then waits for the save before its trial
  ASSERT_TRUE(f.pump_until([&] {
    return f.state().run.mode != RunProgress::Mode::kIdle && f.state().run.phase == RunProgress::Phase::kNone &&
           !f.state().learner_busy;
  }));
  ASSERT_EQ(f.state().experiment.trials.size(), 2u);
  ASSERT_NE(f.core.state(), EngineState::kRunning);
  f.key('x');
  f.sessions.hold_saves = false;
  ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
  f.pump_for(1.0);
  EXPECT_EQ(f.state().experiment.trials.size(), 2u) << "the trial began after x";
  EXPECT_EQ(f.core.state(), EngineState::kArmed);
  EXPECT_TRUE(f.idle());
}

TEST(UiPrompts, TheNamePromptChecksTheNameBeforeItCloses) {
  const std::filesystem::path data = bellows::testing::make_temp_dir("bellows-ui-prompts");
  StoreSessionGateway gateway("sim", nlohmann::ordered_json::object(), data.string());
  {
    ConsoleFixture f(Configuration{}, 3, &gateway);
    f.arm_valves();
    f.key('r');
    ASSERT_TRUE(f.pump_until([&] { return f.idle() && f.console->saves_settled(); }));
    ASSERT_FALSE(f.state().experiment.session_location.empty());
    std::filesystem::create_directories(data / "taken");
    for (const std::string bad : {"../escape", ".hidden", "taken", "a/b"}) {
      SCOPED_TRACE(bad);
      expect_prompt_keeps_focus(
          f, DialogKind::kSessionName, [&] { f.key('s'); }, bad);
    }
    const std::string old_location = f.state().experiment.session_location;
    EXPECT_TRUE(std::filesystem::is_directory(old_location));
    EXPECT_FALSE(std::filesystem::exists(data / "escape"));
    f.key('s');
    f.key(key::kClearLine);
    f.type("morning-run");
    f.key(key::kEnter);
    EXPECT_EQ(f.state().dialog.kind, DialogKind::kNone);
    ASSERT_TRUE(f.pump_until([&] { return f.console->saves_settled(); }));
    EXPECT_EQ(f.state().experiment.session_location, (data / "morning-run").string()) << f.state().status;
    EXPECT_EQ(load_manifest(data / "morning-run").name, "morning-run");  // what `sessions show` prints
    EXPECT_FALSE(std::filesystem::exists(old_location));
  }
  std::filesystem::remove_all(data);
}

}  // namespace
}  // namespace bellows::ui
