// `bellows run`: trials headless, learning between them, on simulated or wall-clock time.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "app/device_factory.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/realtime_loop.hpp"

namespace bellows {

struct RunOptions {
  std::string trajectory = "paper";
  bool trajectory_given = false;  // --trajectory on the command line; else an [arm] preset of J joints runs paperJ
  int iterations = 30;            // learning iterations after the feedback-only iteration 0 (docs/iterations.md)
  std::string config_path;
  std::uint64_t seed = 1;
  bool json = false;
  bool verbose = false;               // --verbose: a line per iteration even on a terminal
  bool quiet = false;                 // --quiet: nothing but errors (and the JSON with --json)
  bool progress_on_terminal = false;  // the progress stream is a terminal: one redrawn line
  // sim: as fast as possible, deterministic; wall: the real-time loop; empty: the device's own
  // (resolve_clock: sim for the simulated arm, wall for a rig).
  std::string clock;
  std::string speed = "1";   // wall clock with the simulated arm: 1, 2, 5, 10 or max
  bool speed_given = false;  // --speed on the command line: refused with the simulated clock
  RealtimeMode rt = RealtimeMode::kTry;
  // Sessions: saved as the run goes into data_dir/session_name unless no_save.
  bool no_save = false;
  std::string data_dir;                    // empty: $XDG_DATA_HOME/bellows/sessions or ~/.local/share/bellows/sessions
  std::string session_name;                // empty: start time and trajectory
  std::string resume_dir;                  // continue this session (its configuration, trajectory and state)
  DeviceOptions device;                    // --device, --t7, --rig-profile over [device] (lcm, t7: the wall clock)
  std::string lcm_url;                     // --lcm URL: publish telemetry there (and find an lcm rig there)
  bool lcm_log = false;                    // --lcm-log [FILE]: an LCM event log of the telemetry,
  std::string lcm_log_file;                //   in FILE, or (no FILE) in the session directory
  std::vector<std::string> transfer_from;  // --transfer-from SESSION...: the first correction from these
  std::string transfer_method = "auto";    // --transfer-method
};

/// The clock of a run: `given` (--clock) when set, else the device's own: wall for a rig (lcm, t7),
/// whose time passes on its own, sim for the simulated arm. Throws InputError for --clock sim with a
/// rig, and for a clock that is neither.
std::string resolve_clock(const std::string& given, const std::string& device_kind);

/// Parses a --speed value ("1", "2", "5", "10", "max"); max is 0. Throws InputError.
double parse_speed(const std::string& speed);

/// Runs and reports. Progress goes to `progress` (app/run_progress.hpp); with --json one object goes to `out`.
/// Throws InputError for bad input (before any trial runs). Returns the exit status.
int run_command(const RunOptions& options, std::ostream& out, std::ostream& progress);

}  // namespace bellows
