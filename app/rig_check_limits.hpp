// `bellows rig check --device lcm`, the rig's own limits (docs/lcm-protocol.md, "The check"), in
// two parts, both safe on real hardware:
// - announced: the limits the rig says it enforces (its io_rig_limits_t: state period, command
//   timeout, pressure ceiling, angle range, joints) against what this configuration expects of it
//   ([timing] tick_s, [lcm] rig_timeout_s, [controller] p_max_bar + [lcm] rig_pressure_margin_bar,
//   [lcm] rig_angle_limit_deg) and against the engine's own guards, which must act first. The
//   ceiling and the range are not provoked: that would take a chamber beyond p_max or the arm into
//   its stops.
// - provoked: the command timeout. Armed, the chambers holding a little air (both inlets for
//   [rig_check] fill_s, then every valve closed), the engine falls silent; the rig must trip within
//   [lcm] rig_timeout_s +- [rig_check] timeout_tolerance_s with a state naming this session, its last
//   command and FAULT_NO_SESSION | FAULT_COMMAND_TIMEOUT, vent (the air goes), the engine must name
//   it `rig-timeout`, and the rig must serve this engine again once it speaks.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devices/lcm_device.hpp"
#include "engine/config/configuration.hpp"
#include "engine/control/fault_code.hpp"
#include "engine/rt/engine_driver.hpp"

namespace bellows {

/// One line of the check: what was found, and why it fails (`problem` empty: it passed).
struct LimitVerdict {
  std::string name;   // "pressure ceiling", "command timeout (provoked)", ...
  std::string found;  // "1.750 bar"
  std::string
      expected;  // "[controller] p_max_bar 1.40 + [lcm] rig_pressure_margin_bar 0.35; the engine's guard 1.650 bar"
  std::string problem;
  bool pass() const { return problem.empty(); }
};

/// The announced limits against `config` (pure). `announced` null: the rig announced none, one
/// failed verdict saying so.
std::vector<LimitVerdict> judge_announced_limits(const RigAnnouncedLimits* announced, const Configuration& config,
                                                 int joints);

/// What the provoked timeout showed.
struct TimeoutObservation {
  std::string not_provoked;  // not empty: why the engine could not set it up (nothing judged)
  std::int64_t session_id = 0;
  std::int64_t last_command_seq = 0;  // the last command before the silence
  bool tripped = false;
  double delay_s = 0.0;       // from the last command to the first trip state's arrival
  double silent_for_s = 0.0;  // how long the engine waited without a trip
  RigStateSeen trip{};        // the first trip state
  SensorReading before{};     // the chambers holding their air, just before the silence
  SensorReading after{};      // the rig's latest state once it had had [rig_check] vent_s to vent
  bool served_again = false;
  double served_again_s = 0.0;                // after the engine spoke again
  FaultCode engine_fault = FaultCode::kNone;  // what the engine named
  std::string engine_detail;
};

/// Sets up and provokes the rig's command timeout through `driver` (the engine SAFE or ARMED) and
/// `device`, then lets the engine speak again. `stop` set: ends early (vented), not provoked.
TimeoutObservation provoke_command_timeout(EngineDriver& driver, LcmDevice& device, const Configuration& config,
                                           double link_lag_s, const std::atomic<bool>* stop);

/// The verdict on what it showed (pure).
LimitVerdict judge_command_timeout(const TimeoutObservation& seen, const Configuration& config);

/// The report's "limits" object: every verdict, and what the timeout showed.
nlohmann::json limits_json(const std::vector<LimitVerdict>& verdicts, const RigAnnouncedLimits* announced,
                           const TimeoutObservation* timeout);

}  // namespace bellows
