// The engine: one tick of everything the loop does, whatever clock drives it.
//
// Per tick (tick()): first the emergency-stop latch (an atomic any thread or a signal handler may
// set: a stop never waits in a queue), then operator commands from the command queue, read the sensors, run the
// guards, run the control scheme when the valves are live (else vent), write the valves, record the
// tick in the black box, the telemetry taps and the latest-value snapshot, and emit events.
// A clock driver calls tick(): SimulatedClock (as fast as possible, same thread, deterministic) or
// RealtimeLoop (its own thread on absolute deadlines). tick() allocates nothing, takes no lock and
// does no I/O; the other threads talk to it only through the lock-free queues and buffers below.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <boost/lockfree/spsc_queue.hpp>

#include "engine/rt/black_box.hpp"
#include "engine/control/control_core.hpp"
#include "engine/control/device.hpp"
#include "engine/rt/engine_messages.hpp"
#include "engine/rt/latest_value.hpp"
#include "engine/base/parameters.hpp"
#include "engine/control/safety.hpp"

namespace bellows {

using TelemetryRing = boost::lockfree::spsc_queue<TickRecord>;

class EngineCore {
 public:
  EngineCore(Device& device, const ControllerParameters& controller, const TimingParameters& timing,
             const SafetyParameters& safety);

  // ---- operator side (one producer thread for commands, one consumer thread for events) ----
  /// Queue a command for the next tick. False when the queue is full: the caller must handle it.
  /// (An emergency stop is not queued: it sets the latch, see request_emergency_stop().)
  [[nodiscard]] bool send(const EngineCommand& command) {
    if (command.kind == CommandKind::kEmergencyStop) {
      request_emergency_stop();
      return true;
    }
    EngineCommand stamped = command;  // a reset queued before a stop must not undo it
    stamped.stops_seen = stop_requests_.load(std::memory_order_acquire);
    return commands_.push(stamped);
  }
  /// Latches an emergency stop: the next tick vents and faults (cause emergency-stop) before it
  /// looks at any queued command. Any thread; async-signal-safe (one lock-free atomic add).
  void request_emergency_stop() noexcept { stop_requests_.fetch_add(1, std::memory_order_acq_rel); }
  /// Whether the engine has acted on every emergency stop requested so far (the valves vented).
  bool emergency_stop_delivered() const noexcept {
    return stops_handled_.load(std::memory_order_acquire) == stop_requests_.load(std::memory_order_acquire);
  }
  bool poll_event(EngineEvent& event) { return events_.pop(event); }
  /// The latest tick (single reader).
  bool read_snapshot(TickRecord& out) { return snapshot_.read(out); }
  /// A telemetry ring fed every tick, for one consumer. Add all taps before the loop starts.
  TelemetryRing& add_telemetry_tap(std::size_t capacity);
  const BlackBox& black_box() const { return black_box_; }
  /// Fault heartbeat monitoring on: the console must send kHeartbeat while the valves are live.
  void monitor_heartbeat(bool on) { monitor_heartbeat_.store(on, std::memory_order_relaxed); }

  EngineState state() const { return state_.load(std::memory_order_acquire); }
  FaultCode fault() const { return fault_.load(std::memory_order_acquire); }
  std::uint64_t ticks() const { return tick_count_.load(std::memory_order_relaxed); }
  std::uint64_t dropped_telemetry() const { return dropped_telemetry_.load(std::memory_order_relaxed); }
  std::uint64_t dropped_events() const { return dropped_events_.load(std::memory_order_relaxed); }
  /// Missed deadlines the engine counted as warnings, not faults: on a device whose time follows
  /// the ticks (Device::time_follows_ticks()) a late tick harms nothing physical.
  std::uint64_t missed_deadline_warnings() const { return missed_warnings_.load(std::memory_order_relaxed); }
  /// Ticks that had no fresh reading and held the valves (ride-through), since the start.
  std::uint64_t held_ticks() const { return held_ticks_.load(std::memory_order_relaxed); }

  // ---- loop side ----
  /// One tick. `now_s`: engine (device) time; `wall_s`: monotonic wall time, for the heartbeat;
  /// `missed_deadlines`: periods missed since the previous tick (wall clock only).
  void tick(double now_s, double wall_s, int missed_deadlines);
  /// Vent and go to FAULT from outside the loop thread's tick (signal handling, shutdown): only
  /// call when the loop is not running.
  void vent_now();

  /// The joints the engine drives: its trajectory's (one without a trajectory). The guards fault
  /// on a reading of another joint count.
  int joints() const { return trajectory_ != nullptr ? trajectory_->joints() : 1; }
  /// The control scheme (for restoring a saved state before the loop starts).
  ControlCore& control() { return control_; }
  /// Before the first tick: ARMED, the control scheme in `state` (from a saved session), as if the
  /// engine had been armed and had run until then; a resumed run so continues exactly. Throws
  /// std::logic_error once the engine has ticked or left SAFE.
  void restore_armed(const ControlCore::State& state, double now_s);
  const TimingParameters& timing() const { return timing_; }

 private:
  void apply(const EngineCommand& command, double now_s, double wall_s);
  void change_state(EngineState next, double now_s, CommandKind cause, FaultCode fault_cause = FaultCode::kNone);
  /// `joint`: the joint (0-based) the guard fired on, -1 when the fault is no joint's.
  void enter_fault(FaultCode code, double now_s, int joint = -1);
  /// A fault with its own sentence (a device's, DeviceFault::text).
  void enter_fault(const DeviceFault& fault, double now_s);
  /// Both: latch `code` with the sentence in fault_detail_, vent, hand back the trial, emit.
  void latch_fault(FaultCode code, double now_s, int joint);
  void count_missed_deadlines(int missed, double now_s);
  void hold_trajectory(const Trajectory* trajectory, double now_s);
  void hand_back_trial(EventKind kind, double now_s);
  void start_control_trial();
  /// Every joint of the trial's trajectory within the settle tolerance of its first set point.
  bool at_trial_start(const SensorReading& reading) const;
  /// Why a kStartTrial's buffers cannot run its trial (static text), or nullptr when they can.
  const char* trial_refusal(const EngineCommand& command) const;
  /// Why a trajectory cannot be held or run (a joint count beyond kMaxJoints, joints of unequal
  /// length: the tick would index beyond them), or nullptr.
  static const char* trajectory_refusal(const Trajectory& trajectory);
  void emit(const EngineEvent& event);

  Device& device_;
  ControllerParameters controller_;
  TimingParameters timing_;
  SafetyParameters safety_;
  ControlCore control_;
  BlackBox black_box_;
  boost::lockfree::spsc_queue<EngineCommand> commands_;
  boost::lockfree::spsc_queue<EngineEvent> events_;
  std::vector<std::unique_ptr<TelemetryRing>> taps_;
  LatestValue<TickRecord> snapshot_;

  std::atomic<EngineState> state_{EngineState::kSafe};
  std::atomic<FaultCode> fault_{FaultCode::kNone};
  std::atomic<bool> monitor_heartbeat_{false};
  std::atomic<std::uint32_t> stop_requests_{0};  // the latch: requests made ...
  std::atomic<std::uint32_t> stops_handled_{0};  // ... and acted on by a tick
  static_assert(std::atomic<std::uint32_t>::is_always_lock_free, "the stop latch is set from signal handlers");
  std::atomic<std::uint64_t> missed_warnings_{0};
  std::atomic<std::uint64_t> tick_count_{0};
  std::atomic<std::uint64_t> held_ticks_{0};
  std::atomic<std::uint64_t> dropped_telemetry_{0};
  std::atomic<std::uint64_t> dropped_events_{0};

  // Loop-thread state.
  const Trajectory* trajectory_ = nullptr;
  const Eigen::VectorXd* correction_ = nullptr;        // one joint's correction, or ...
  const Eigen::MatrixXd* joint_correction_ = nullptr;  // ... every joint's (N x J)
  TrialRecord* record_ = nullptr;
  std::uint32_t trial_id_ = 0;
  int settle_remaining_ = 0;
  int settle_extra_remaining_ = 0;     // ticks the hold may still go on while a joint is off its start
  double settle_tolerance_rad_ = 0.0;  // ... by more than this
  double last_reading_time_s_ = -1.0;
  double last_angle_rad_ = 0.0;  // last finite angle read: where arming without a trajectory holds
  int stale_count_ = 0;          // ticks in a row the rig went without a fresh reading (missed periods too)
  int skipped_in_gap_ = 0;       // of them, the periods the loop missed (not the link's)
  int fault_joint_ = -1;         // the joint the latched fault fired on (-1: none, or no joint's)
  FaultDetail fault_detail_{};   // the latched fault's sentence, for its events
  int missed_streak_ = 0;
  const bool time_follows_ticks_;  // the device's, read once: missed deadlines warn instead of fault
  double last_heartbeat_s_ = 0.0;
  // The operator's valves (kValvePulse): instead of the control scheme while `manual_` is set.
  bool manual_ = false;
  ValvePulse pulse_{};
  int pulse_remaining_ = 0;
  bool pulse_report_pending_ = false;  // the pulse is over: report it with the next fresh reading
  int pulse_settle_remaining_ = 0;     // ticks of `after` still to wait before that
  double pulse_end_reading_s_ = 0.0;   // the newest reading's time when the pulse's last valves went out
};

}  // namespace bellows
