// Safety guards: each a named fault with a human message, every limit from `[safety]` (each
// joint's angle limit from its `[arm_jointN] angle_limit_deg`, default `[safety] angle_limit_deg`).
// find_guard_fault() looks at one tick's reading and loop health and names the first fault it finds
// and the joint it fired on.
#pragma once

#include <array>
#include <cstdint>

#include "engine/control/device.hpp"
#include "engine/control/fault_code.hpp"

namespace bellows {

struct SafetyParameters {
  double angle_limit_deg = 95.0;  // beyond it the arm is where no trajectory may take it
  // [arm_jointN] angle_limit_deg: joint N's own limit; 0 (the default): angle_limit_deg.
  std::array<double, kMaxJoints> joint_angle_limit_deg{};
  double pressure_margin_bar = 0.25;  // fault when a chamber exceeds p_max + margin
  double supply_min_bar = 2.0;        // absolute; below it the valves cannot do their job
  double sensor_min_bar = 0.5;        // plausible range of any pressure reading
  double sensor_max_bar = 10.0;
  double sensor_max_angle_deg = 180.0;  // plausible range of the encoder
  // Ticks in a row without a fresh reading: held (valves closed) below it, a fault at it. 8 ticks =
  // 40 ms at 200 Hz: below the rig's own 50 ms command timeout, and a chamber filling at the full
  // inlet flow gains < 0.1 bar in it (docs/architecture.md, "Riding through missing readings").
  // Missed periods count as such ticks too (the rig had no command in them), and are held the same
  // way (the trial's clock goes on, nothing learned from them).
  int stale_ticks = 8;
  // Missed deadlines in a row (late wake-ups, summed) before a fault, on a rig whose time is its
  // own: 8 periods = 40 ms, the stale limit's time and reasons (the rig runs on its last command
  // meanwhile). Below it the loop rides through (docs/architecture.md, missed deadlines).
  int missed_deadline_streak = 8;
  double heartbeat_timeout_s = 1.0;  // console silent for longer: fault
  double black_box_s = 2.0;          // ticks kept for the fault record

  /// Joint `joint`'s (0-based) angle limit in degrees: its own when set, else angle_limit_deg.
  double angle_limit_deg_of(int joint) const {
    const bool own = joint >= 0 && joint < kMaxJoints && joint_angle_limit_deg[static_cast<std::size_t>(joint)] > 0.0;
    return own ? joint_angle_limit_deg[static_cast<std::size_t>(joint)] : angle_limit_deg;
  }
};

/// What the guards need to know besides the reading.
struct GuardInputs {
  double p_max_bar = 1.4;
  int joint_count = 1;         // the joints the engine drives: a reading for another count is implausible
  int stale_count = 0;         // consecutive ticks without a fresh reading
  int missed_streak = 0;       // consecutive missed deadlines
  double heartbeat_age_s = 0;  // time since the console's last heartbeat (0 when not monitored)
};

/// A guard that fired and where: the joint (0-based) whose angle or chamber showed it, -1 for a
/// fault that is no joint's (supply, stale sensors, deadlines, heartbeat, an implausible joint count).
struct GuardFault {
  FaultCode code = FaultCode::kNone;
  int joint = -1;
};

/// The first fault the guards find in one tick (the most basic kind first, whichever joint shows
/// it; among joints of the same kind, the lowest) and the joint it fired on.
GuardFault find_guard_fault(const SensorReading& reading, const GuardInputs& inputs, const SafetyParameters& limits);
/// find_guard_fault()'s code alone.
inline FaultCode check_guards(const SensorReading& reading, const GuardInputs& inputs, const SafetyParameters& limits) {
  return find_guard_fault(reading, inputs, limits).code;
}

}  // namespace bellows
