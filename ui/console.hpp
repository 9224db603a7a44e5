// The console's UI thread: starts the engine loop, opens the terminal, and runs the loop of
// "key (or 33 ms timeout) -> controller -> redraw at most 30 times a second" until the operator
// quits, a stop signal arrives or `exit_after_s` passes. It vents before it returns.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "engine/rt/engine_driver.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "ui/console_controller.hpp"

namespace bellows::ui {

struct ConsoleSetup {
  EngineCore* core = nullptr;
  RealtimeLoop* loop = nullptr;  // not started yet: the console adds its telemetry tap first
  /// Instead of `loop` (console --clock sim): the UI thread ticks it while the engine has work,
  /// `environment.speed` times as fast as the wall clock ("max": as fast as it can).
  SimulatedClock* simulated_clock = nullptr;
  RealtimeMode rt_mode = RealtimeMode::kTry;
  ConsoleEnvironment environment;  // core, telemetry and latency are filled in here
  Trajectory trajectory;
  std::optional<SessionSnapshot> session;        // open this saved session at start
  const std::atomic<bool>* stop_flag = nullptr;  // set by SIGINT/SIGTERM/SIGHUP/SIGQUIT
  double exit_after_s = 0.0;                     // > 0: quit by itself after this long (benchmarks, tests)
  bool allow_colors = true;
};

/// What the console measured about itself, printed when it exits.
struct ConsoleReport {
  double seconds = 0.0;
  std::uint64_t frames = 0;  // redraws
  double ui_cpu_s = 0.0;     // CPU time of the UI thread
  LatencySummary loop;       // the engine loop's wake-up latency and missed deadlines
  std::uint64_t ticks = 0;
  int iterations = 0;
  double best_rms_deg = -1.0;
  bool stopped_by_signal = false;
  std::string save_status;            // the session saved as it went (empty: none)
  std::string unsaved;                // what did not reach the disk (empty: nothing), a sentence
  bool unsaved_work_lost = false;     // saving was available and work is not on disk: exit non-zero
  std::uint64_t dropped_events = 0;   // engine events lost to a full queue
  std::uint64_t missed_warnings = 0;  // missed deadlines counted as warnings (simulated arm)
  bool exited_after_time = false;
  bool unicode = false;
  bool colors = false;
};

/// Runs the console. Throws InputError before the terminal opens (no terminal, --rt enforce
/// refused); the loop is stopped and the valves vented however it ends.
ConsoleReport run_console(ConsoleSetup setup);

}  // namespace bellows::ui
