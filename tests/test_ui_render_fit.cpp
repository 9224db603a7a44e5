// Screens that must hold up in a small window and with long text: the header keeps what must be
// seen at a glance at 80 columns in every state, the log wraps instead of cutting, a refused answer
// shows in its dialog, and every screen other than the main one offers the way back.
#include <gtest/gtest.h>

#include "tests/ui_sample_state.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::all;
using testing::sample_state;

ConsoleState small_state(EngineState state) {
  ConsoleState s = sample_state(3, true);
  s.width = kMinWidth;
  s.height = kMinHeight;
  s.engine_state = state;
  s.fault = state == EngineState::kFault ? FaultCode::kHeartbeatLost : FaultCode::kNone;
  s.loop.speed = "10";
  s.loop.missed = 12345;
  s.loop.max_us = 12345;
  return s;
}

TEST(UiRenderFit, HeaderKeepsStateTrajectoryIterationAndRmsAt80Columns) {
  for (EngineState state : {EngineState::kSafe, EngineState::kArmed, EngineState::kRunning, EngineState::kFault}) {
    for (bool unicode : {true, false}) {
      ConsoleState s = small_state(state);
      s.unicode = unicode;
      const std::vector<std::string> lines = render_lines(s);
      const std::string& header = lines[0];
      SCOPED_TRACE(header);
      EXPECT_NE(header.find(state == EngineState::kFault ? "FAULT: heartbeat-lost" : to_string(state)),
                std::string::npos);
      EXPECT_NE(header.find("sim: ok"), std::string::npos);
      EXPECT_NE(header.find("paper (8.0 s)"), std::string::npos);
      EXPECT_NE(header.find("it 2  RMS 3.333 deg"), std::string::npos);
      EXPECT_NE(header.find("RMS 3.333 deg"), std::string::npos);  // the last trial's, 10/3
      const std::string& loop = lines[1];
      SCOPED_TRACE(loop);
      EXPECT_NE(loop.find("missed 12345"), std::string::npos);
      EXPECT_NE(loop.find("max 12345 us"), std::string::npos);
      EXPECT_NE(loop.find("law noilc"), std::string::npos);
      EXPECT_NE(loop.find("unsaved"), std::string::npos);
    }
  }
  // Wide enough: the words and labels are there.
  ConsoleState wide = small_state(EngineState::kArmed);
  wide.width = 160;
  const std::string header = render_lines(wide)[0];
  EXPECT_NE(header.find("ARMED  valves live  device sim: ok  trajectory paper (8.0 s)  iteration 2  RMS"),
            std::string::npos)
      << header;
  EXPECT_NE(header.find("(best 3.333)"), std::string::npos) << header;
}

TEST(UiRenderFit, TheLogScreenWrapsLongEntries) {
  ConsoleState s = small_state(EngineState::kArmed);
  s.screen = Screen::kLog;
  const std::string long_text =
      "learning law 'noilc' may diverge if the arm differs from the model by up to 30 %: contraction 3.606 > 1 "
      "at 4.38 Hz for kappa x1.30, omega0 x1.30 (11 of 25 grid points; nominal 0.750) END";
  s.log.add({"12:00:03", 2.0, LogSource::kLearner, long_text, true, false, "", 0, {}});
  const std::string screen = all(render_lines(s));
  EXPECT_NE(screen.find("learning law 'noilc' may diverge"), std::string::npos) << screen;
  EXPECT_NE(screen.find("END"), std::string::npos) << screen;
  EXPECT_NE(screen.find("grid points;"), std::string::npos) << screen;
  // The newest entry stays at the bottom, and the older ones above it.
  EXPECT_NE(screen.find("console started"), std::string::npos) << screen;
}

TEST(UiRenderFit, ARefusedAnswerShowsInItsDialogWithWhatWasTyped) {
  ConsoleState s = small_state(EngineState::kArmed);
  s.dialog = {DialogKind::kAskIterations, "Run K iterations",
              {"Each iteration learns."}, "2.5",
              "Enter run   Esc cancel",   "K must be a whole number from 1 to 1000, not '2.5'"};
  const std::string screen = all(render_lines(s));
  EXPECT_NE(screen.find("> 2.5_"), std::string::npos) << screen;
  EXPECT_NE(screen.find("K must be a whole number from 1 to 1000, not '2.5'"), std::string::npos) << screen;
  EXPECT_NE(screen.find("Enter run   Esc cancel"), std::string::npos) << screen;
}

TEST(UiRenderFit, ADialogWrapsALongLineInsteadOfCuttingIt) {
  ConsoleState s = small_state(EngineState::kArmed);  // 80 columns
  const std::string why =
      "Saving is not available: no data directory: neither XDG_DATA_HOME nor HOME is an absolute "
      "path; pass --data-dir";
  s.dialog = {DialogKind::kConfirmQuit,
              "Quit?",
              {"1 iteration is not saved.", why},
              "",
              "q quit without saving   Esc cancel",
              ""};
  const std::string screen = all(render_lines(s));
  for (const std::string words :
       {"1 iteration is not saved.", "absolute path; pass --data-dir", "q quit without saving"}) {
    EXPECT_NE(screen.find(words), std::string::npos) << words << "\n" << screen;  // cut at the box's edge before
  }
}

TEST(UiRenderFit, EveryOtherScreenOffersTheWayBack) {
  for (Screen screen : {Screen::kHelp, Screen::kTrajectory, Screen::kInspector, Screen::kTuning, Screen::kLog,
                        Screen::kSessions, Screen::kFault}) {
    ConsoleState s = small_state(EngineState::kArmed);
    s.screen = screen;
    const std::string bar = render_lines(s).back();
    EXPECT_EQ(bar.rfind("Space E-STOP  Esc Back", 0), 0u) << bar;
  }
  ConsoleState s = small_state(EngineState::kArmed);
  EXPECT_EQ(render_lines(s).back().find("Esc Back"), std::string::npos);
}

TEST(UiRenderFit, TheFaultScreenSaysWhichGuardAndWhenInFullAt80Columns) {
  ConsoleState s = small_state(EngineState::kFault);
  s.fault = FaultCode::kOverpressure;
  s.screen = Screen::kFault;
  s.fault_view.code = FaultCode::kOverpressure;
  s.fault_view.time_s = 1234.5;
  for (int i = 0; i < 400; ++i) {
    TickRecord t;
    t.time_s = 1234.5 - 0.005 * (399 - i);
    t.state = i == 399 ? EngineState::kFault : EngineState::kRunning;
    t.reading.joint[0].chamber_bar = {1.0 + 0.003 * i, 1.0};
    t.reading.supply_bar = 3.0;
    s.fault_view.black_box.push_back(t);
  }
  const std::string screen = all(render_lines(s));
  std::string joined;  // the wrapped lines read as one text
  for (const std::string& line : render_lines(s)) {
    const auto first = line.find_first_not_of(' ');
    if (first != std::string::npos) joined += line.substr(first, line.find_last_not_of(' ') + 1 - first) + " ";
  }
  EXPECT_NE(screen.find("overpressure"), std::string::npos) << screen;
  EXPECT_NE(joined.find("a chamber pressure exceeded p_max plus the safety margin"), std::string::npos) << screen;
  EXPECT_NE(joined.find("latched: R resets to SAFE, then a arms again."), std::string::npos) << screen;
  EXPECT_NE(screen.find("Black box"), std::string::npos) << screen;
  EXPECT_NE(screen.find("Last ticks before the fault"), std::string::npos) << screen;
  EXPECT_NE(screen.find("FAULT"), std::string::npos) << screen;
}

TEST(UiRenderFit, NoNegativeZeroInTheReadouts) {
  ConsoleState s = small_state(EngineState::kArmed);
  s.width = 120;
  s.height = 40;
  s.live.reading.joint[0].angle_rad = -1e-9;
  s.live.joint(0).desired_rad = 0.0;
  const std::string screen = all(render_lines(s));
  EXPECT_NE(screen.find("angle         0.00 deg"), std::string::npos) << screen;
  EXPECT_EQ(screen.find("-0.00"), std::string::npos) << screen;
}

TEST(UiRenderFit, TheFunctionBarKeepsStopBackHelpAndQuitAt80Columns) {
  for (EngineState state : {EngineState::kSafe, EngineState::kArmed, EngineState::kFault}) {
    for (Screen screen : {Screen::kMain, Screen::kTuning, Screen::kRig, Screen::kLog}) {
      ConsoleState s = small_state(state);
      s.fault_view.code = state == EngineState::kFault ? FaultCode::kHeartbeatLost : FaultCode::kNone;
      s.screen = screen;
      const std::string bar = render_lines(s).back();
      SCOPED_TRACE(bar);
      if (state == EngineState::kArmed) {
        EXPECT_NE(bar.find("Space E-STOP"), std::string::npos);
      }
      if (screen != Screen::kMain) {
        EXPECT_NE(bar.find("Esc Back"), std::string::npos);
      }
      EXPECT_NE(bar.find("?/F1 Help"), std::string::npos);
      EXPECT_NE(bar.find("q Quit"), std::string::npos);
      EXPECT_LE(static_cast<int>(bar.find_last_not_of(' ')), kMinWidth - 1);
    }
  }
}

TEST(UiRenderFit, TheStatusLineWrapsAtAWordAndNeverCutsOne) {
  ConsoleState s = small_state(EngineState::kArmed);
  s.unicode = false;
  s.status =
      "Run: arm the valves first (a); the learning law is rebuilt after every change of the weights, "
      "which takes a moment on a slow machine ENDWORD";
  std::vector<std::string> lines = render_lines(s);
  const std::string two = lines[lines.size() - 3] + "\n" + lines[lines.size() - 2];
  EXPECT_NE(two.find("Run: arm the valves first (a);"), std::string::npos) << two;
  EXPECT_NE(two.find("ENDWORD"), std::string::npos) << two;  // all of it, on two lines
  for (const char* word : {"rebuilt", "weights,", "machine"}) EXPECT_NE(two.find(word), std::string::npos) << word;

  std::string very_long;
  for (int i = 0; i < 60; ++i) very_long += "word" + std::to_string(i) + " ";
  s.status = very_long;
  lines = render_lines(s);
  const std::string last = lines[lines.size() - 2];
  SCOPED_TRACE(last);
  const auto end = last.find_last_not_of(' ');
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(last.substr(end - 3, 4), " ...");  // abbreviated after a whole word
  const std::string before = last.substr(0, end - 3);
  const std::string tail = before.substr(before.find_last_of(' ') + 1);
  EXPECT_NE(very_long.find(" " + tail + " "), std::string::npos) << tail;  // a whole word, not a piece of one
  // The function bar stays below it.
  EXPECT_NE(lines.back().find("Space E-STOP"), std::string::npos) << lines.back();
}

TEST(UiRenderFit, TheTuningScreenSaysHowToEditAValueAt80x24) {
  ConsoleState s = small_state(EngineState::kArmed);
  s.screen = Screen::kTuning;
  s.run.mode = RunProgress::Mode::kIdle;
  s.tuning.selected = 1;
  std::string screen = all(render_lines(s));
  EXPECT_NE(screen.find("Up/Down choose   Enter edit: type the value, Enter applies, Esc cancels"), std::string::npos)
      << screen;
  s.tuning.selected = TuningForm::kLawRow;
  screen = all(render_lines(s));
  EXPECT_NE(screen.find("Enter or Right: next law   Left: the one before"), std::string::npos) << screen;
  s.run.mode = RunProgress::Mode::kBatch;
  screen = all(render_lines(s));
  EXPECT_NE(screen.find("changes wait: trials are running (x stops them)"), std::string::npos) << screen;
  s = small_state(EngineState::kFault);
  s.screen = Screen::kTuning;
  screen = all(render_lines(s));
  EXPECT_NE(screen.find("changes wait: a fault is latched (R resets)"), std::string::npos) << screen;
}

TEST(UiRenderFit, VentedTheLivePanelShowsNoSetPointAndNoTrackingError) {
  // After an emergency stop in the middle of `paper`: the engine still knows its last set point
  // (40 deg), the arm has sagged to 3 deg.
  ConsoleState s = small_state(EngineState::kFault);
  s.live.state = EngineState::kFault;
  s.live.joint(0).desired_rad = 40.0 * testing::kDeg;
  s.live.reading.joint[0].angle_rad = 3.0 * testing::kDeg;
  std::string screen = all(render_lines(s));
  EXPECT_NE(screen.find("angle         3.00 deg"), std::string::npos) << screen;
  EXPECT_NE(screen.find("set point  none: vented"), std::string::npos) << screen;
  EXPECT_NE(screen.find("error      no trial"), std::string::npos) << screen;
  EXPECT_EQ(screen.find("40.00"), std::string::npos) << screen;
  EXPECT_EQ(screen.find("37.00"), std::string::npos) << screen;
  // Armed, the engine holds a set point, still no trial; running, the tracking error is shown.
  s.engine_state = s.live.state = EngineState::kArmed;
  screen = all(render_lines(s));
  EXPECT_NE(screen.find("set point    40.00 deg hold"), std::string::npos) << screen;
  EXPECT_NE(screen.find("error      no trial"), std::string::npos) << screen;
  s.engine_state = s.live.state = EngineState::kRunning;
  screen = all(render_lines(s));
  EXPECT_NE(screen.find("error        37.00 deg"), std::string::npos) << screen;
}

}  // namespace
}  // namespace bellows::ui
