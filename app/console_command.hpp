// `bellows` (no arguments) and `bellows console`: the operator console on a device.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "app/device_factory.hpp"
#include "engine/rt/realtime_loop.hpp"

namespace bellows {

struct ConsoleOptions {
  DeviceOptions device;        // --device, --lcm, --t7, --rig-profile over [device]
  std::string speed = "1";     // the simulated arm's time warp: 1, 2, 5, 10 or max
  std::string clock = "wall";  // wall: the real-time loop; sim: simulated time (the simulated arm only)
  std::string config_path;
  std::string trajectory = "paper";  // library name or CSV file
  std::string session_dir;           // open this saved session at start
  std::string data_dir;              // where sessions are saved; empty: the default (XDG_DATA_HOME, HOME)
  RealtimeMode rt = RealtimeMode::kTry;
  std::uint64_t seed = 1;
  int stop_after_rises = 3;   // a run of K iterations stops when the RMS rose this often in a row
  double exit_after_s = 0.0;  // > 0: close by itself after this long (benchmarks)
  bool no_color = false;
};

/// Runs the console until the operator quits. Throws InputError for bad options before the
/// terminal opens. Prints a closing summary on `out`. Returns the exit status.
int console_command(const ConsoleOptions& options, std::ostream& out);

}  // namespace bellows
