// Everything a console screen shows, as plain values: the controller keeps it up to date from the
// engine and the operator's keys; render() turns it into text. Tests build one by hand.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/config/configuration.hpp"
#include "engine/rt/engine_messages.hpp"
#include "engine/rt/engine_state.hpp"
#include "engine/base/iteration_numbering.hpp"
#include "engine/control/safety.hpp"
#include "ui/event_log.hpp"
#include "ui/experiment.hpp"
#include "ui/session_gateway.hpp"

namespace bellows::ui {

enum class Screen { kMain, kHelp, kTrajectory, kInspector, kTuning, kLog, kSessions, kFault, kRig };

enum class DialogKind {
  kNone,
  kConfirmArm,        // y/n
  kAskIterations,     // a number K
  kTrajectoryPath,    // a file path
  kEditValue,         // a number for the tuning field
  kConfirmQuit,       // s / q / Esc
  kConfirmDiscard,    // y/n: unsaved trials would be lost
  kConfirmValveTest,  // y/n: the valves open one by one, the arm moves
  kConfirmZeroAngle,  // y/n: the angle read now becomes the rig profile's zero (its file is written)
  kSessionName,       // a name for the session saved as the console goes
  kInterrupted,       // a fault or the emergency stop closed the dialog being answered: Enter or Esc
  kConfirmStartMove,  // y/n: armed, another trajectory's start moves the arm at once
};

struct Dialog {
  DialogKind kind = DialogKind::kNone;
  std::string title;
  std::vector<std::string> text;
  std::string input;  // what the operator typed (prompts)
  std::string hint;   // the keys, e.g. "y arm   n cancel"
  std::string error;  // why the last answer was not taken (the dialog stays open, the input kept)
};

struct DeviceHealth {
  std::string name = "sim";
  bool ok = false;
  std::string status = "no data";  // with a link: its round trip, errors and stale readings too
};

/// The Rig screen (the first day at the bench): the inputs live and the valve test.
struct RigView {
  std::string where;        // the link: "in-process", an LCM URL, a T7's address
  std::string rig_profile;  // its name ("" without one)
  RawInputs raw;            // raw volts beside calibrated values (none for the simulated arm)
  struct ValveLine {
    std::string valve;  // "inlet A"
    bool tested = false;
    bool pass = false;
    std::string text;  // the changes, or the problem
  };
  std::vector<ValveLine> valves;  // the last valve test's verdicts (empty: none yet)
  bool test_running = false;
  bool verdicts_logged = false;  // the finished test's verdicts are in the log
  std::string test_progress;     // "inlet B: pulsing (2 of 4)", "done", "stopped: ..."
};

struct LoopHealth {
  std::uint64_t ticks = 0;
  std::uint64_t missed = 0;
  double p50_us = 0, p99_us = 0, max_us = 0;
  std::string rt = "other";
  std::string speed = "1";  // "1", "2", "5", "10", "max"
  double tick_hz = 200.0;
  std::uint64_t dropped_telemetry = 0;
  std::uint64_t dropped_events = 0;  // engine events lost to a full event queue
  bool realtime = true;              // false on a simulated clock (no latency to show)
  std::string clock = "wall";        // "wall" (the real-time loop) or "sim" (console --clock sim)
};

/// The last seconds of the live signals at the ILC rate, oldest first, for the live plot; time in
/// seconds before the newest sample (so it ends at 0).
struct LiveStrip {
  std::vector<double> time_s, angle_deg, setpoint_deg;
};

/// What the console is doing about trials.
struct RunProgress {
  enum class Mode { kIdle, kTrial, kStep, kBatch };
  Mode mode = Mode::kIdle;
  enum class Phase { kNone, kLearning, kSettling, kRunning };
  Phase phase = Phase::kNone;
  int batch_first = 0;  // a batch runs iterations batch_first..batch_first + batch_total - 1
  int batch_total = 0;  // trials of a batch: K, or K + 1 with iteration 0 (docs/iterations.md)
  int batch_done = 0;   // trials finished in the batch
  int sample = -1;      // sample of the running trial
  bool stop_requested = false;
};

/// The iterations a batch runs, "0..5" (docs/iterations.md).
inline std::string batch_span(const RunProgress& r) {
  return std::to_string(r.batch_first) + ".." + std::to_string(r.batch_first + r.batch_total - 1);
}

struct InspectorView {
  int trial = -1;   // index into experiment.trials
  int sample = 0;   // cursor, 0..N
  int chosen = -1;  // an iteration overlaid for comparison (-1: none)
  int peak = -1;    // which of the trial's |error| peaks e last jumped to (0: the largest; -1: none)
};

struct TrajectoryChooser {
  std::vector<std::string> names;  // library names, then the file entry
  std::vector<std::string> descriptions;
  int selected = 0;
  std::shared_ptr<const Trajectory> preview;
  std::string preview_error;
  std::string file_path;                              // the file entry's path, once given
  std::shared_ptr<const Trajectory> file_trajectory;  // ...loaded from it (off the UI thread)
};

/// The tuning screen's rows, in order: k_ff, k_p, k_i, k_d, the learning law, M, S, W.
struct TuningForm {
  static constexpr int kRows = 8;
  static constexpr int kLawRow = 4;
  int selected = 0;
  /// The tuning_fields() index of a row; -1 for the law row.
  static int field_of(int row) { return row < kLawRow ? row : (row == kLawRow ? -1 : row - 1); }
};

struct SessionBrowser {
  std::vector<SessionListing> sessions;
  int selected = 0;
  bool loading = false;
  std::string error;
};

struct FaultView {
  FaultCode code = FaultCode::kNone;
  double time_s = 0.0;
  std::vector<TickRecord> black_box;  // oldest first, ending with the fault tick
  std::string where;                  // on a J-joint arm: the joint (and chamber) the guard fired on
  int joint = -1;                     // the joint the engine named (0-based); -1: no joint's
  std::string detail;  // the fault's own sentence (a device's words: the rig's reason, the link's silence)
};

struct ConsoleState;
/// The joint shown (0-based), within the experiment's joints.
int selected_joint(const ConsoleState& s);

struct ConsoleState {
  // The terminal.
  int width = 120, height = 40;
  bool unicode = true;  // braille plots and box drawing (UTF-8 locale)

  // What is on screen.
  Screen screen = Screen::kMain;
  Screen previous_screen = Screen::kMain;  // where help was opened from
  Dialog dialog;
  std::string status;  // the latest message for the operator
  bool status_important = false;
  Screen status_screen = Screen::kMain;  // where it was said: another screen does not show it
  int log_scroll = 0;                    // log screen: entries scrolled back from the newest
  int help_scroll = 0;                   // help screen: its first line shown
  bool rms_log_scale = false;            // the RMS plot's y axis (L toggles)

  // The engine and the rig.
  EngineState engine_state = EngineState::kSafe;
  FaultCode fault = FaultCode::kNone;
  DeviceHealth device;
  LoopHealth loop;
  bool live_valid = false;
  TickRecord live;  // the latest tick
  LiveStrip strip;
  bool heartbeat_drill = false;  // heartbeats withheld on purpose

  // The learning.
  Configuration config;  // current gains and weights included
  Experiment experiment;
  int joint = 0;  // the joint the live strip, plots and inspector show (0-based; j selects)
  std::string law_name;
  bool law_ready = false;
  std::string convergence;           // the law's predicted contraction per trial, in words
  bool convergence_warning = false;  // it may diverge for a plausible model error
  bool learner_busy = false;
  std::string learner_task;  // "building the learning law", "learning", "saving", ...
  RunProgress run;
  int stop_after_rises = 3;

  // Screens' own state.
  InspectorView inspector;
  TrajectoryChooser chooser;
  TuningForm tuning;
  SessionBrowser browser;
  FaultView fault_view;
  RigView rig;
  EventLog log;

  bool sessions_available = false;
  std::string sessions_unavailable_reason;
};

inline int selected_joint(const ConsoleState& s) {
  return s.joint < 0 || s.joint >= s.experiment.joints() ? 0 : s.joint;
}

}  // namespace bellows::ui
