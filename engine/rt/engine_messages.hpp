// What crosses thread boundaries around the engine: operator commands in, events and tick records
// out. All plain values (pointers to buffers the sender owns), so queues can copy them without
// allocating. Commands travel in an SPSC queue: a full one refuses the command (EngineCore::send()
// returns false, [[nodiscard]]). Events travel in another: a full one drops the event, counted
// (EngineCore::dropped_events(): the console's header and log, the run's JSON, a session event).
// The engine writes a trial's record and hands it back with kTrialComplete or kTrialAborted, and
// says with kTrajectorySelected when the sender may free the trajectories it selected before.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Dense>

#include "engine/control/device.hpp"
#include "engine/rt/engine_state.hpp"
#include "engine/control/safety.hpp"
#include "engine/trial/setpoints.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

struct PidGains {
  double k_ff = 0.0, k_p = 0.0, k_i_per_s = 0.0, k_d_s = 0.0;
};

/// The operator holds the valves (the valve test of rig bring-up): `valves` for `ticks` ticks, then
/// `after` until the next pulse, a disarm or a trial. The guards keep running; the PID does not.
struct ValvePulse {
  ValveCommand valves{};
  ValveCommand after{};  // default: every valve closed (the chambers keep their air)
  int ticks = 0;
  int settle_ticks = 0;  // of `after` before the end is reported: the link's lag, so that the
                         // reported reading shows the whole pulse (a rig over LCM lags)
  std::uint32_t id = 0;  // echoed in the kValvePulseDone event
};

/// An operator command. Buffers named by pointer stay owned by the sender, who must keep them
/// alive and unchanged until the engine hands them back (TrialComplete / TrialAborted event).
struct EngineCommand {
  CommandKind kind = CommandKind::kHeartbeat;
  const Trajectory* trajectory = nullptr;             // kSelectTrajectory, kStartTrial
  const Eigen::VectorXd* correction = nullptr;        // kStartTrial: u_ilc(0..N-1), bar (one joint)
  const Eigen::MatrixXd* joint_correction = nullptr;  // kStartTrial instead, for J joints: N x J, bar
  TrialRecord* record = nullptr;                      // kStartTrial: where the trial is written, prepared
                                                      // (TrialRecord::prepare) to the trajectory's length
                                                      // and joint count
  int settle_ticks = 0;                               // kStartTrial: hold at the start before sample 0
  int settle_max_ticks = 0;                           // kStartTrial: and on, up to this many ticks in all,
  double settle_tolerance_rad = 0.0;                  // while a joint is farther than this from its start
  std::uint32_t trial_id = 0;                         // kStartTrial: echoed in the trial's events
  PidGains gains{};                                   // kSetGains
  ValvePulse pulse{};                                 // kValvePulse
  std::uint32_t stops_seen = 0;                       // set by EngineCore::send(): stops requested before it

  /// A command that carries nothing but its kind (arm, disarm, reset, e-stop, heartbeat, ...).
  static EngineCommand of(CommandKind kind) {
    EngineCommand c;
    c.kind = kind;
    return c;
  }
  static EngineCommand start_trial(const Trajectory& trajectory, const Eigen::VectorXd& correction, TrialRecord& record,
                                   int settle_ticks, std::uint32_t trial_id) {
    EngineCommand c = trial_of(trajectory, record, settle_ticks, trial_id);
    c.correction = &correction;
    return c;
  }
  /// A trial of the trajectory's J joints, `correction` one column per joint (N x J).
  static EngineCommand start_trial(const Trajectory& trajectory, const Eigen::MatrixXd& correction, TrialRecord& record,
                                   int settle_ticks, std::uint32_t trial_id) {
    EngineCommand c = trial_of(trajectory, record, settle_ticks, trial_id);
    c.joint_correction = &correction;
    return c;
  }
  static EngineCommand valve_pulse(const ValvePulse& pulse) {
    EngineCommand c = of(CommandKind::kValvePulse);
    c.pulse = pulse;
    return c;
  }
  static EngineCommand select_trajectory(const Trajectory& trajectory) {
    EngineCommand c = of(CommandKind::kSelectTrajectory);
    c.trajectory = &trajectory;
    return c;
  }

 private:
  /// A trial's command before its correction (one vector, or one column per joint) is set.
  static EngineCommand trial_of(const Trajectory& trajectory, TrialRecord& record, int settle_ticks,
                                std::uint32_t trial_id) {
    EngineCommand c = of(CommandKind::kStartTrial);
    c.trajectory = &trajectory;
    c.record = &record;
    c.settle_ticks = settle_ticks;
    c.trial_id = trial_id;
    return c;
  }
};

enum class EventKind : std::uint8_t {
  kStateChanged,
  kCommandRefused,
  kFault,
  kTrialComplete,
  kTrialAborted,        // the record is handed back incomplete (disarm, abort, fault)
  kValvePulseDone,      // a valve pulse's `ticks` and `settle_ticks` are over; `reading`: the first fresh one
                        // after them (taken after the pulse's last command); `trial_id`: its id
  kWarning,             // something the operator should know that is not a fault (`fault` names it)
  kTrajectorySelected,  // the engine holds `trajectory` now: earlier selections are handed back
};

struct EngineEvent {
  EventKind kind = EventKind::kStateChanged;
  double time_s = 0.0;
  EngineState from = EngineState::kSafe;
  EngineState to = EngineState::kSafe;
  CommandKind command = CommandKind::kHeartbeat;  // the command concerned, if any
  const char* refusal = "";                       // kCommandRefused: why (static text)
  FaultCode fault = FaultCode::kNone;
  int fault_joint = -1;                    // kFault: the joint (0-based) the guard fired on; -1: no joint's
  TrialRecord* record = nullptr;           // kTrialComplete / kTrialAborted
  const Trajectory* trajectory = nullptr;  // kTrajectorySelected
  std::uint32_t trial_id = 0;
  SensorReading reading{};  // kValvePulseDone: read after the pulse's last tick
  std::uint32_t count = 0;  // kWarning: how many (e.g. deadlines missed in a row)
  FaultDetail detail{};     // kFault, kTrialAborted by a fault: the fault's own sentence
                            // (the device's words: the rig's reason, the link's silence)
};

/// One joint's controller outputs at a tick.
struct TickJoint {
  double desired_rad = 0.0;
  double u_total_bar = 0.0;
  ChamberSetpoints setpoints{};
};

/// One tick as the loop saw it: for the telemetry ring, the black box and the live snapshot.
struct TickRecord {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  EngineState state = EngineState::kSafe;
  FaultCode fault = FaultCode::kNone;
  int fault_joint = -1;  // the joint (0-based) the latched fault fired on; -1: none or no joint's
  SensorReading reading{};
  std::array<TickJoint, kMaxJoints> joints{};  // [0, reading.joint_count): each joint's (the console's live strips)
  ValveCommand valves{};
  int sample = -1;  // ILC sample of the running trial, -1 otherwise
  std::uint32_t trial_id = 0;

  /// Joint `joint`'s (0-based, within kMaxJoints) outputs.
  TickJoint& joint(int joint) { return joints[static_cast<std::size_t>(joint)]; }
  const TickJoint& joint(int joint) const { return joints[static_cast<std::size_t>(joint)]; }
};

}  // namespace bellows
