// Screens as text for a given state: what the operator sees, without a terminal.
#include <gtest/gtest.h>

#include <numbers>

#include "engine/trial/trajectory.hpp"
#include "ui/key_map.hpp"
#include "tests/ui_sample_state.hpp"
#include "ui/render.hpp"

namespace bellows::ui {
namespace {

using testing::all;
using testing::ascii_only;
using testing::kDeg;
using testing::sample_state;

TEST(UiRender, DashboardShowsStateTrajectoryIterationsAndLiveValues) {
  const ConsoleState s = sample_state(3, false);
  const auto lines = render_lines(s);
  ASSERT_EQ(lines.size(), 40u);
  const std::string text = all(lines);
  EXPECT_TRUE(ascii_only(text)) << text;
  EXPECT_NE(lines[0].find("ARMED"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("valves live"), std::string::npos);
  EXPECT_NE(lines[0].find("paper (8.0 s)"), std::string::npos);
  // The header names the newest iteration run (0..2) and its RMS (docs/iterations.md).
  EXPECT_NE(lines[0].find("iteration 2  RMS 3.333 deg (best 3.333)"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find("p50 24 p99 51 max 80 us"), std::string::npos) << lines[1];
  // RMS per iteration, readable as numbers.
  EXPECT_NE(text.find("   0    10.000"), std::string::npos) << text;
  EXPECT_NE(text.find("   1     5.000"), std::string::npos);
  EXPECT_NE(text.find("   2     3.333*"), std::string::npos);
  // Live values and duty-cycle bars.
  EXPECT_NE(text.find("angle        12.50 deg"), std::string::npos) << text;
  EXPECT_NE(text.find("p A          1.234 bar"), std::string::npos);
  EXPECT_NE(text.find("in A  ##########"), std::string::npos);
  EXPECT_NE(text.find(" 50%"), std::string::npos);
  // The log panel leaves out routine entries; the status line shows the message.
  EXPECT_NE(text.find("12:00:01 SAFE -> ARMED (arm)"), std::string::npos);
  EXPECT_EQ(text.find("ARMED -> RUNNING"), std::string::npos);
  EXPECT_NE(lines[38].find("hello operator"), std::string::npos);
  // The function bar: what matters when armed.
  EXPECT_NE(lines[39].find("Space E-STOP"), std::string::npos) << lines[39];
  EXPECT_NE(lines[39].find("r Run"), std::string::npos);
  EXPECT_NE(lines[39].find("n Next"), std::string::npos);
  EXPECT_NE(lines[39].find("N Run K"), std::string::npos);
  EXPECT_EQ(lines[39].find("a Arm"), std::string::npos);
  // Plots: the last trial and the correction with the previous one overlaid.
  EXPECT_NE(text.find("Iteration 2: angle and set point (deg)"), std::string::npos);
  EXPECT_NE(text.find("* it 2"), std::string::npos);
  EXPECT_NE(text.find(". it 1"), std::string::npos);
}

TEST(UiRender, HeaderNamesNoIterationBeforeTheFirstTrial) {
  // Iteration 0 has not run yet: the header does not claim it (it named the next one before).
  const std::string header = render_lines(sample_state(0, false))[0];
  EXPECT_NE(header.find("iteration -"), std::string::npos) << header;
  EXPECT_EQ(header.find("RMS"), std::string::npos) << header;
}

TEST(UiRender, FunctionBarFollowsTheState) {
  ConsoleState s = sample_state(0, true);
  s.engine_state = EngineState::kSafe;
  std::string bar = render_lines(s).back();
  EXPECT_NE(bar.find("a Arm"), std::string::npos) << bar;
  EXPECT_EQ(bar.find("r Run"), std::string::npos);
  s.engine_state = EngineState::kFault;
  s.fault = FaultCode::kOverpressure;
  bar = render_lines(s).back();
  EXPECT_NE(bar.find("R Reset"), std::string::npos) << bar;
  EXPECT_EQ(bar.find("a Arm"), std::string::npos);
  s.engine_state = EngineState::kRunning;
  s.run.mode = RunProgress::Mode::kBatch;
  bar = render_lines(s).back();
  EXPECT_NE(bar.find("x Stop"), std::string::npos) << bar;
  EXPECT_EQ(bar.find("n Next"), std::string::npos);
}

TEST(UiRender, FaultIsShownInColourAndInWords) {
  ConsoleState s = sample_state(1, false);
  s.engine_state = EngineState::kFault;
  s.fault = FaultCode::kOverpressure;
  s.screen = Screen::kFault;
  s.fault_view.code = FaultCode::kOverpressure;
  s.fault_view.time_s = 10.0;
  for (int i = 0; i < 400; ++i) {
    TickRecord t;
    t.time_s = 10.0 - (399 - i) * 0.005;
    t.state = i == 399 ? EngineState::kFault : EngineState::kRunning;
    t.reading.joint[0].chamber_bar = {1.2 + 0.001 * i, 1.05};
    t.reading.supply_bar = 3.0;
    s.fault_view.black_box.push_back(t);
  }
  Canvas c(s.width, s.height);
  render(s, c);
  const auto lines = c.lines();
  EXPECT_NE(lines[0].find("FAULT: overpressure"), std::string::npos) << lines[0];
  const int at = static_cast<int>(lines[0].find("FAULT"));
  EXPECT_EQ(c.at(at, 0).role, Role::kFault);
  const std::string text = c.text();
  EXPECT_NE(text.find("a chamber pressure exceeded p_max plus the safety margin"), std::string::npos) << text;
  EXPECT_NE(text.find("Black box: last 2.0 s"), std::string::npos);
  EXPECT_NE(text.find("Last ticks before the fault"), std::string::npos);
  EXPECT_NE(text.find("0.000   FAULT"), std::string::npos);
  EXPECT_NE(text.find("-0.005   RUNNING"), std::string::npos);
}

TEST(UiRender, HelpGreysWhatIsNotAvailableNow) {
  ConsoleState s = sample_state(0, true);
  s.screen = Screen::kHelp;
  s.engine_state = EngineState::kSafe;
  const auto role_of = [](const ConsoleState& state, const std::string& description) {
    Canvas c(state.width, state.height);
    render(state, c);
    for (int y = 0; y < c.height(); ++y) {
      const auto x = c.line(y).find(description);
      if (x != std::string::npos) return c.at(static_cast<int>(decode_utf8(c.line(y).substr(0, x)).size()), y).role;
    }
    ADD_FAILURE() << description << " not on the help screen";
    return Role::kNormal;
  };
  EXPECT_EQ(role_of(s, "run a trial with the current correction"), Role::kDim);
  EXPECT_EQ(role_of(s, "arm the valves"), Role::kNormal);
  s.engine_state = EngineState::kArmed;
  EXPECT_EQ(role_of(s, "run a trial with the current correction"), Role::kNormal);
  EXPECT_EQ(role_of(s, "arm the valves"), Role::kDim);
  const std::string text = all(render_lines(s));
  for (const KeyBinding& b : key_bindings()) EXPECT_NE(text.find(b.description), std::string::npos) << b.description;
}

TEST(UiRender, BelowTheMinimumSizeAClearMessage) {
  for (auto [w, h] : {std::pair{79, 24}, std::pair{80, 23}, std::pair{40, 10}, std::pair{1, 1}}) {
    ConsoleState s = sample_state(2, true);
    s.width = w;
    s.height = h;
    const std::string text = all(render_lines(s));
    if (h >= 5 && w >= 40) {
      EXPECT_NE(text.find("Terminal too small"), std::string::npos) << w << "x" << h << "\n" << text;
      EXPECT_NE(text.find(std::to_string(w) + "x" + std::to_string(h)), std::string::npos);
      EXPECT_NE(text.find("80x24"), std::string::npos);
    }
  }
  ConsoleState small = sample_state(2, true);
  small.width = 70;
  small.height = 20;
  small.dialog = {
      DialogKind::kConfirmQuit, "Quit?", {"2 iterations are not saved."}, "", "q quit without saving   Esc cancel", ""};
  const std::string small_text = all(render_lines(small));
  EXPECT_NE(small_text.find("Quit?"), std::string::npos) << small_text;
  EXPECT_NE(small_text.find("q quit without saving   Esc cancel"), std::string::npos);

  ConsoleState s = sample_state(2, true);
  s.width = 80;
  s.height = 24;
  const auto lines = render_lines(s);
  EXPECT_EQ(all(lines).find("too small"), std::string::npos);
  EXPECT_EQ(lines[0].rfind(" Bellows", 0), 0u);
  EXPECT_NE(lines[23].find("r Run"), std::string::npos) << lines[23];
  EXPECT_NE(all(lines).find("RMS per iteration"), std::string::npos);
}

TEST(UiRender, EveryScreenAtEverySizeInBothGlyphSets) {
  for (bool unicode : {false, true}) {
    for (auto [w, h] :
         {std::pair{80, 24}, std::pair{81, 25}, std::pair{100, 30}, std::pair{120, 40}, std::pair{240, 70}}) {
      for (Screen screen : {Screen::kMain, Screen::kHelp, Screen::kTrajectory, Screen::kInspector, Screen::kTuning,
                            Screen::kLog, Screen::kSessions, Screen::kFault}) {
        for (bool dialog : {false, true}) {
          ConsoleState s = sample_state(4, unicode);
          s.width = w;
          s.height = h;
          s.screen = screen;
          s.inspector.trial = 3;
          s.fault_view.code = FaultCode::kHeartbeatLost;
          s.chooser.names = {"paper", "from a file..."};
          s.chooser.preview = s.experiment.trajectory;
          if (dialog)
            s.dialog = {DialogKind::kAskIterations,
                        "Run K iterations",
                        {"text"},
                        "12345678901234567890123456789012345678901234567890123456789012345678901234567890",
                        "hint",
                        ""};
          const auto lines = render_lines(s);
          ASSERT_EQ(static_cast<int>(lines.size()), h);
          for (const auto& line : lines) EXPECT_LE(text_width(line), w);
          EXPECT_NE(lines[0].find("ARMED"), std::string::npos) << w << "x" << h;
          if (!unicode) {
            EXPECT_TRUE(ascii_only(all(lines))) << all(lines);
          }
        }
      }
    }
  }
}

TEST(UiRender, InspectorReadsTheValuesAtTheCursor) {
  ConsoleState s = sample_state(3, false);
  s.screen = Screen::kInspector;
  s.inspector = {1, 35, 0};
  const std::string text = all(render_lines(s));
  // Trial 1 at sample 35 (t = 0.7 s): the paper's first move is under way.
  const auto trajectory = library_trajectory("paper", 0.02);
  const double setpoint_deg = trajectory.joint(0)(35) / kDeg;
  EXPECT_NE(text.find("Iteration 1 of 0..2"), std::string::npos) << text;
  EXPECT_NE(text.find("(learned from 0)"), std::string::npos);
  EXPECT_NE(text.find("sample     35 / 400"), std::string::npos);
  EXPECT_NE(text.find("time       0.70 s"), std::string::npos);
  EXPECT_NE(text.find(format("set point  %.2f deg", setpoint_deg)), std::string::npos) << setpoint_deg;
  EXPECT_NE(text.find(format("angle      %.2f deg", setpoint_deg * 0.75)), std::string::npos);
  EXPECT_NE(text.find(format("error      %.2f deg", setpoint_deg * 0.25)), std::string::npos);
  EXPECT_NE(text.find("u_pid      0.0350 bar"), std::string::npos);
  EXPECT_NE(text.find("u_ilc      0.0100 bar"), std::string::npos);
  EXPECT_NE(text.find("p A        1.100 bar"), std::string::npos);
  // The selected, the previous and the chosen iteration's corrections in the legend.
  EXPECT_NE(text.find("* it 1"), std::string::npos);
  EXPECT_NE(text.find(". it 0"), std::string::npos);
  s.inspector = {2, 0, 0};
  const std::string overlay = all(render_lines(s));
  EXPECT_NE(overlay.find("o it 0"), std::string::npos) << overlay;
  EXPECT_NE(overlay.find("overlay: it 0"), std::string::npos);
}

TEST(UiRender, DialogsShowTheirTextInputAndKeys) {
  ConsoleState s = sample_state(1, true);
  s.dialog = {
      DialogKind::kAskIterations, "Run K iterations", {"Each iteration learns."}, "12", "Enter run   Esc cancel", ""};
  const std::string text = all(render_lines(s));
  EXPECT_NE(text.find("Run K iterations"), std::string::npos);
  EXPECT_NE(text.find("Each iteration learns."), std::string::npos);
  EXPECT_NE(text.find("> 12_"), std::string::npos) << text;
  EXPECT_NE(text.find("Enter run   Esc cancel"), std::string::npos);
}

TEST(UiRender, TrajectoryChooserPreviewsTheCandidate) {
  ConsoleState s = sample_state(0, false);
  s.screen = Screen::kTrajectory;
  s.chooser.names = {"paper", "steps", "sine", "from a file..."};
  s.chooser.descriptions = {"a", "b", "c", "CSV"};
  s.chooser.selected = 1;
  s.chooser.preview = std::make_shared<const Trajectory>(library_trajectory("steps", 0.02));
  std::string text = all(render_lines(s));
  EXPECT_NE(text.find("paper  (in use)"), std::string::npos) << text;
  EXPECT_NE(text.find("> steps"), std::string::npos);
  EXPECT_NE(text.find("steps: 10.0 s, 500 samples, -40.0 to 40.0 deg"), std::string::npos);
  s.chooser.selected = 3;
  s.chooser.preview.reset();
  s.chooser.preview_error = "bad.csv line 3: not a number";
  text = all(render_lines(s));
  EXPECT_NE(text.find("bad.csv line 3: not a number"), std::string::npos);
}

TEST(UiRender, TuningLogAndSessionScreens) {
  ConsoleState s = sample_state(1, false);
  s.screen = Screen::kTuning;
  s.tuning.selected = 1;
  s.convergence = "may diverge: contraction 3.6 > 1 at 4.38 Hz";
  s.convergence_warning = true;
  s.log.add(
      {"12:01:00", 2.0, LogSource::kOperator, "k_p changed 0.3 -> 0.4 ([controller] k_p)", false, false, "", 0, {}});
  std::string text = all(render_lines(s));
  EXPECT_NE(text.find("> k_p            0.3"), std::string::npos) << text;
  EXPECT_NE(text.find("  W            2e-05"), std::string::npos) << text;
  EXPECT_NE(text.find("12:01:00  k_p changed 0.3 -> 0.4"), std::string::npos);
  EXPECT_NE(text.find("may diverge: contraction 3.6 > 1 at 4.38 Hz"), std::string::npos);
  EXPECT_NE(text.find("  law          noilc       [ilc] law"), std::string::npos) << text;
  s.tuning.selected = TuningForm::kLawRow;
  s.config.ilc.law = "pd";
  text = all(render_lines(s));
  EXPECT_NE(text.find("> law             pd       [ilc] law"), std::string::npos) << text;
  EXPECT_NE(text.find("  M                1"), std::string::npos) << text;  // the weights follow the law's row

  s.screen = Screen::kLog;
  text = all(render_lines(s));
  EXPECT_NE(text.find("Event log (4 entries)"), std::string::npos) << text;
  EXPECT_NE(text.find("engine   ARMED -> RUNNING (start trial)"), std::string::npos);

  s.screen = Screen::kSessions;
  s.sessions_available = false;
  s.sessions_unavailable_reason = "no store";
  EXPECT_NE(all(render_lines(s)).find("Not available: no store"), std::string::npos);
  s.sessions_available = true;
  s.browser.sessions = {{"/d/a", "2024-05-01_14-03-07_paper", "2024-05-01 14:03", "paper", 31, 0.987, "", "sim", ""},
                        {"/d/c", "bench", "2024-05-02 09:00", "steps", 12, 1.5, "", "t7",
                         "recorded on the device 't7'; this console drives 'sim'"},
                        {"/d/b", "broken", "", "", 0, -1, "manifest.json: missing", "", ""}};
  text = all(render_lines(s));
  EXPECT_NE(text.find("> 2024-05-01 14:03  sim    paper            0..30      0.987  2024-05-01_14-03-07_paper"),
            std::string::npos)
      << text;
  // Another device's session: marked in its row, and the reason on the last line when chosen.
  EXPECT_NE(text.find("  2024-05-02 09:00  t7     steps            0..11      1.500  bench  (other device)"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("cannot open it here"), std::string::npos) << text;
  s.browser.selected = 1;
  text = all(render_lines(s));
  EXPECT_NE(text.find("cannot open it here: recorded on the device 't7'; this console drives 'sim'"), std::string::npos)
      << text;
  EXPECT_NE(text.find("broken: cannot be read: manifest.json: missing"), std::string::npos);
}

}  // namespace
}  // namespace bellows::ui
