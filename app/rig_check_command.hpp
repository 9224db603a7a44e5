// `bellows rig check`: the first day at the bench, headless. Shows every input (raw volts beside
// the calibrated value, where the device has volts), then, with the operator's confirmation, pulses
// each valve in turn through the engine (engine/operator/valve_test) and reports each pass or fail. With
// --zero-angle it makes the angle read now the rig profile's zero instead (written into the file).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "app/device_factory.hpp"
#include "engine/rt/realtime_loop.hpp"

namespace bellows {

/// Exit status of a rig check in which a valve failed (or the test could not finish).
inline constexpr int kExitRigCheckFailed = 5;

struct RigCheckOptions {
  std::string config_path;
  DeviceOptions device;
  std::uint64_t seed = 1;
  RealtimeMode rt = RealtimeMode::kTry;
  bool yes = false;          // no question before the valves open
  bool inputs_only = false;  // no valve opens
  bool zero_angle = false;   // the angle read now becomes the rig profile's zero (written to its file); no valve opens
  bool json = false;
  // The check is recorded in a session like a run (the device, the configuration, one event per
  // input, valve verdict and angle zero) unless no_save.
  bool no_save = false;
  std::string data_dir;      // empty: the default sessions folder
  std::string session_name;  // empty: start time and trajectory
};

/// Runs the check. The question comes from `in` (a line starting with y goes on); the report goes to
/// `progress` (one line per valve; failed ones start with "FAIL"), JSON to `out`. Returns 0 when
/// every valve passed, kExitRigCheckFailed otherwise, 128 + N after signal N. Throws InputError for
/// bad options or an unconfirmed test (nothing opened), EnvironmentError when no rig answers.
int rig_check_command(const RigCheckOptions& options, std::istream& in, std::ostream& out, std::ostream& progress);

}  // namespace bellows
