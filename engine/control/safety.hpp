// Safety guards: each a named fault with a human message, every limit from `[safety]` (each
// joint's angle limit from its `[arm_jointN] angle_limit_deg`, default `[safety] angle_limit_deg`).
// find_guard_fault() looks at one tick's reading and loop health and names the first fault it finds
// and the joint it fired on. The engine runs it every tick while the valves are live (ARMED,
// RUNNING), after the device's own faults and the stale limit (EngineCore::tick(), where the device
// names a silence: link-lost); a fault vents in that tick. The order, each kind on every joint before
// the next kind: sensor-stale, sensor-nan, sensor-range, angle-limit, overpressure, supply-low,
// missed-deadlines, heartbeat-lost (the console silent for `heartbeat_timeout_s`).
//
// The stale limit, `stale_ticks` = 8 ticks = 40 ms at 200 Hz. A tick without a fresh reading is
// held (ControlCore::tick_held: every valve closed, the chambers keep their air, nothing learned
// from the sample); only a run of them is a fault. Why 40 ms, from the plant
// (../shared/spec/reference-system.md):
//  - a rig that no longer hears the engine keeps its last command until its own timeout
//    (`[lcm] rig_timeout_s`, 50 ms). At worst an inlet is fully open all along: mdot = C p_s rho0 psi
//    with C = 3.0e-9 m^3/(s Pa), p_s = 3 bar, psi(1.4/3) = 0.98 is 1.05 g/s, p_dot = mdot R T / V with
//    V0 = 0.45 L about 2.0 bar/s: in 40 ms a chamber gains at most 0.08 bar, a third of the 0.25 bar
//    between the set points' ceiling p_max and the overpressure guard;
//  - 40 ms is two time constants of the pressure loop (tau_p = 20 ms) and two ILC samples: a gap that
//    long costs two samples of control, which the next ones recover;
//  - it is below the rig's own command timeout, so the engine's fault, which names the cause, comes
//    before the rig vents itself; and above what this VM's link and scheduler do to a healthy link,
//    with margin for two CPU-bound processes beside it (docs/benchmarks.md, "Rig links under load").
// Missed deadlines: on a device whose time follows the ticks (Device::time_follows_ticks(), the
// in-process simulation) a late tick harms nothing and is only counted. On a rig, whose time is its
// own, the missed periods are held ticks (the trial's clock keeps the rig's time) and count towards
// the stale limit; when the late loop made at least half of a stale run the fault is
// missed-deadlines. `missed_deadline_streak` (8 = 40 ms, for the same reasons) bounds a run of late
// wake-ups even with fresh readings; a rig's own timeout reported in such a stall is named
// missed-deadlines too (the rig vented because the loop stopped). Meanwhile the rig's own bound
// holds: io-sim and an LCM rig vent after `[lcm] rig_timeout_s`, the T7 link's I/O thread after
// `[t7] command_timeout_s`, the T7's watchdog after `[t7] watchdog_timeout_s`.
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
  // inlet flow gains < 0.1 bar in it (the argument above).
  // Missed periods count as such ticks too (the rig had no command in them), and are held the same
  // way (the trial's clock goes on, nothing learned from them).
  int stale_ticks = 8;
  // Missed deadlines in a row (late wake-ups, summed) before a fault, on a rig whose time is its
  // own: 8 periods = 40 ms, the stale limit's time and reasons (the rig runs on its last command
  // meanwhile). Below it the loop rides through (above, "Missed deadlines").
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
