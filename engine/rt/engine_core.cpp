#include "engine/rt/engine_core.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bellows {
namespace {
constexpr std::size_t kCommandCapacity = 256;
constexpr std::size_t kEventCapacity = 1024;
constexpr int kMaxCommandsPerTick = 16;  // bounds the work of one tick

void copy_text(const char* text, FaultDetail& out) {  // truncated to fit, no allocation
  std::size_t i = 0;
  for (; text[i] != '\0' && i + 1 < out.size(); ++i) out[i] = text[i];
  out[i] = '\0';
}
}  // namespace

EngineCore::EngineCore(Device& device, const ControllerParameters& controller, const TimingParameters& timing,
                       const SafetyParameters& safety)
    : device_(device),
      controller_(controller),
      timing_(timing),
      safety_(safety),
      control_(controller, timing),
      black_box_(static_cast<std::size_t>(std::lround(safety.black_box_s / timing.tick_s))),
      commands_(kCommandCapacity),
      events_(kEventCapacity),
      time_follows_ticks_(device.time_follows_ticks()) {}

TelemetryRing& EngineCore::add_telemetry_tap(std::size_t capacity) {
  taps_.push_back(std::make_unique<TelemetryRing>(capacity));
  return *taps_.back();
}

void EngineCore::emit(const EngineEvent& event) {
  if (!events_.push(event)) dropped_events_.fetch_add(1, std::memory_order_relaxed);
}

void EngineCore::change_state(EngineState next, double now_s, CommandKind cause, FaultCode fault_cause) {
  const EngineState from = state();
  if (from == next) return;
  state_.store(next, std::memory_order_release);
  EngineEvent event;
  event.kind = EventKind::kStateChanged;
  event.time_s = now_s;
  event.from = from;
  event.to = next;
  event.command = cause;
  event.fault = fault_cause != FaultCode::kNone ? fault_cause : fault();
  emit(event);
}

void EngineCore::hand_back_trial(EventKind kind, double now_s) {
  if (record_ == nullptr) return;
  EngineEvent event;
  event.kind = kind;
  event.time_s = now_s;
  event.record = record_;
  event.trial_id = trial_id_;
  event.from = event.to = state();
  if (kind == EventKind::kTrialAborted && fault() != FaultCode::kNone) event.detail = fault_detail_;
  emit(event);
  record_ = nullptr;
  correction_ = nullptr;
  joint_correction_ = nullptr;
  if (control_.trial_running()) control_.abort_trial();
}

bool EngineCore::at_trial_start(const SensorReading& reading) const {
  for (int j = 0; j < trajectory_->joints(); ++j) {
    const double off_rad = reading.joint[static_cast<std::size_t>(j)].angle_rad - trajectory_->joint(j)(0);
    if (!(std::abs(off_rad) <= settle_tolerance_rad_)) return false;
  }
  return true;
}

void EngineCore::start_control_trial() {
  if (joint_correction_ != nullptr) {
    control_.start_trial(*trajectory_, *joint_correction_, *record_);
  } else {
    control_.start_trial(*trajectory_, *correction_, *record_);
  }
}

const char* EngineCore::trial_refusal(const EngineCommand& command) const {
  const char* not_prepared = "the trial's trajectory, correction or record is missing or not prepared to its length";
  const Trajectory* trajectory = command.trajectory;
  const TrialRecord* record = command.record;
  if (trajectory == nullptr || record == nullptr ||
      (command.correction == nullptr) == (command.joint_correction == nullptr)) {
    return not_prepared;
  }
  if (const char* why = trajectory_refusal(*trajectory)) return why;
  const int joints = trajectory->joints();
  const int n = trajectory->learning_samples();
  if (command.correction != nullptr && command.correction->size() != n) return not_prepared;
  if (command.correction != nullptr
          ? joints != 1
          : command.joint_correction->rows() != n || command.joint_correction->cols() != joints) {
    return "the trial's correction is not one column of N values per joint of its trajectory";
  }
  if (record->joint_count() != joints) {
    return "the trial's record is not prepared for the joints of its trajectory";
  }
  const Eigen::Index tick_count = static_cast<Eigen::Index>(n) * timing_.ticks_per_sample;
  if (record->sample_time_s.size() != n + 1 || record->tick_time_s.size() != tick_count ||
      record->supply_bar.size() != tick_count) {
    return not_prepared;
  }
  for (int j = 0; j < joints; ++j) {
    if (record->joint_samples(j).error_rad.size() != n + 1 || record->joint_ticks(j).angle_rad.size() != tick_count) {
      return not_prepared;
    }
  }
  return nullptr;
}

const char* EngineCore::trajectory_refusal(const Trajectory& trajectory) {
  if (!valid_joint_count(trajectory.joints())) return "the trajectory has more joints than bellows drives";
  for (int j = 0; j < trajectory.joints(); ++j) {
    if (trajectory.joint(j).size() != trajectory.joint(0).size() || trajectory.joint(0).size() == 0) {
      return "the trajectory's joints do not all have the same number of samples";
    }
  }
  return nullptr;
}

void EngineCore::hold_trajectory(const Trajectory* trajectory, double now_s) {
  trajectory_ = trajectory;
  // The sender may now free every trajectory it gave before this one.
  EngineEvent event;
  event.kind = EventKind::kTrajectorySelected;
  event.time_s = now_s;
  event.from = event.to = state();
  event.trajectory = trajectory;
  emit(event);
}

void EngineCore::enter_fault(const DeviceFault& fault, double now_s) {
  fault_detail_ = fault.text;
  fault_detail_.back() = '\0';
  if (fault_detail_[0] == '\0') copy_text(fault_message(fault.code), fault_detail_);
  latch_fault(fault.code, now_s, fault.joint);
}

void EngineCore::enter_fault(FaultCode code, double now_s, int joint) {
  copy_text(fault_message(code), fault_detail_);
  latch_fault(code, now_s, joint);
}

void EngineCore::latch_fault(FaultCode code, double now_s, int joint) {
  fault_joint_ = joint;
  fault_.store(code, std::memory_order_release);
  manual_ = false;
  device_.vent();
  hand_back_trial(EventKind::kTrialAborted, now_s);
  // The state change names the guard that fired (event.fault); only an operator's stop is a command.
  change_state(EngineState::kFault, now_s,
               code == FaultCode::kEmergencyStop ? CommandKind::kEmergencyStop : CommandKind::kGuard, code);
  EngineEvent event;
  event.kind = EventKind::kFault;
  event.time_s = now_s;
  event.fault = code;
  event.fault_joint = joint;
  event.detail = fault_detail_;
  event.from = event.to = EngineState::kFault;
  emit(event);
}

void EngineCore::apply(const EngineCommand& command, double now_s, double wall_s) {
  const EngineState from = state();
  const Transition t = transition(from, command.kind);
  auto refuse = [&](const char* why) {
    EngineEvent event;
    event.kind = EventKind::kCommandRefused;
    event.time_s = now_s;
    event.from = event.to = from;
    event.command = command.kind;
    event.refusal = why;
    emit(event);
  };
  if (!t.allowed) {
    refuse(t.refusal);
    return;
  }
  switch (command.kind) {
    case CommandKind::kHeartbeat:
      last_heartbeat_s_ = wall_s;
      return;
    case CommandKind::kGuard:  // refused by transition(): causes, never commands
    case CommandKind::kTrialEnd:
      return;
    case CommandKind::kEmergencyStop:
      enter_fault(FaultCode::kEmergencyStop, now_s);
      return;
    case CommandKind::kSelectTrajectory:
      if (const char* why = command.trajectory != nullptr ? trajectory_refusal(*command.trajectory) : nullptr) {
        refuse(why);
        return;
      }
      hold_trajectory(command.trajectory, now_s);
      if (from == EngineState::kArmed && trajectory_ != nullptr) control_.hold(trajectory_->setpoint_rad(0));
      // Without a trajectory the engine drives one joint: holding several would vent them all.
      if (from == EngineState::kArmed && trajectory_ == nullptr && control_.joints() != 1)
        control_.hold(last_angle_rad_);
      return;
    case CommandKind::kSetGains: {
      ControllerParameters gains = controller_;
      gains.k_ff = command.gains.k_ff;
      gains.k_p = command.gains.k_p;
      gains.k_i_per_s = command.gains.k_i_per_s;
      gains.k_d_s = command.gains.k_d_s;
      control_.set_controller_gains(gains);
      return;
    }
    case CommandKind::kValvePulse:
      manual_ = true;
      pulse_ = command.pulse;
      pulse_remaining_ = command.pulse.ticks;
      pulse_settle_remaining_ = command.pulse.settle_ticks;
      pulse_report_pending_ = false;
      return;
    case CommandKind::kArm: {
      manual_ = false;
      // Fresh controllers, holding the trajectory's start (or where the arm is, without one: one joint).
      control_.reset_pids();
      if (trajectory_ != nullptr) {
        control_.hold(trajectory_->setpoint_rad(0));
      } else {
        control_.hold(last_angle_rad_);
      }
      last_heartbeat_s_ = wall_s;
      break;
    }
    case CommandKind::kStartTrial:
      // The sender sizes the record (TrialRecord::prepare) so that the loop never allocates.
      if (const char* why = trial_refusal(command)) {
        refuse(why);
        return;
      }
      if (manual_) {  // back from the operator's valves: fresh controllers
        manual_ = false;
        control_.reset_pids();
      }
      hold_trajectory(command.trajectory, now_s);
      correction_ = command.correction;
      joint_correction_ = command.joint_correction;
      record_ = command.record;
      record_->complete = false;  // the engine owns the record from now on
      trial_id_ = command.trial_id;
      settle_remaining_ = command.settle_ticks;
      settle_extra_remaining_ = std::max(0, command.settle_max_ticks - command.settle_ticks);
      settle_tolerance_rad_ = command.settle_tolerance_rad;
      control_.hold(trajectory_->setpoint_rad(0));
      if (settle_remaining_ <= 0) start_control_trial();
      break;
    case CommandKind::kAbortTrial:
    case CommandKind::kDisarm:
      manual_ = false;
      hand_back_trial(EventKind::kTrialAborted, now_s);
      break;
    case CommandKind::kReset:
      if (command.stops_seen != stops_handled_.load(std::memory_order_relaxed)) {
        refuse("an emergency stop came after this reset was sent");
        return;
      }
      fault_.store(FaultCode::kNone, std::memory_order_release);
      fault_joint_ = -1;
      fault_detail_[0] = '\0';
      black_box_.clear();
      break;
  }
  change_state(t.next, now_s, command.kind);
}

void EngineCore::count_missed_deadlines(int missed, double now_s) {
  missed_streak_ = missed > 0 ? missed_streak_ + missed : 0;
  if (missed <= 0 || !time_follows_ticks_) return;
  // The device's time advances per tick: a late tick harms nothing physical. Counted and reported
  // (once per streak that would have faulted a real rig), never a fault.
  missed_warnings_.fetch_add(static_cast<std::uint64_t>(missed), std::memory_order_relaxed);
  if (missed_streak_ >= safety_.missed_deadline_streak && missed_streak_ - missed < safety_.missed_deadline_streak) {
    EngineEvent event;
    event.kind = EventKind::kWarning;
    event.time_s = now_s;
    event.from = event.to = state();
    event.fault = FaultCode::kMissedDeadlines;
    event.count = static_cast<std::uint32_t>(missed_streak_);
    emit(event);
  }
  missed_streak_ = std::min(missed_streak_, safety_.missed_deadline_streak);  // a warning, never the guard
}

void EngineCore::tick(double now_s, double wall_s, int missed_deadlines) {
  // The stop latch before anything queued: a full command queue can never delay a stop.
  const std::uint32_t stops = stop_requests_.load(std::memory_order_acquire);
  if (stops != stops_handled_.load(std::memory_order_relaxed)) {
    device_.vent();
    if (state() != EngineState::kFault) enter_fault(FaultCode::kEmergencyStop, now_s);
    stops_handled_.store(stops, std::memory_order_release);
  }
  EngineCommand command;
  for (int i = 0; i < kMaxCommandsPerTick && commands_.pop(command); ++i) apply(command, now_s, wall_s);

  const SensorReading reading = device_.read_sensors();
  const bool fresh = reading.time_s > last_reading_time_s_;  // else: no reading this tick (device.hpp)
  // On a rig whose time is its own, the periods the loop missed passed there without a command:
  // each is a tick without a reading, held like one (the trial's clock goes on, nothing learned).
  const int skipped = time_follows_ticks_ ? 0 : std::max(0, missed_deadlines);
  const int unattended = stale_count_ + skipped + (fresh ? 0 : 1);  // ticks the rig went uncontrolled
  const int late_ticks = skipped_in_gap_ + skipped;                 // of them, the loop's
  // Only ticks with live valves count: a rig vented while the engine is safe is not uncontrolled,
  // and the tick that arms must not inherit the silence of a rig that was not serving yet.
  const bool counting = !fresh && valves_live(state());
  skipped_in_gap_ = counting ? late_ticks : 0;
  stale_count_ = counting ? unattended : 0;
  last_reading_time_s_ = std::max(last_reading_time_s_, reading.time_s);
  if (std::isfinite(reading.joint[0].angle_rad)) last_angle_rad_ = reading.joint[0].angle_rad;
  count_missed_deadlines(missed_deadlines, now_s);

  // What the device found itself is taken every tick (and acted on only while the valves are live).
  DeviceFault device_fault;
  const bool device_faulted = device_.take_fault(device_fault);
  // A rig that timed out while this loop was stalled past its limits timed out because of the stall:
  // the loop's guards below name it (missed-deadlines), not the rig's report that raced them here.
  const bool stale_limit = unattended >= safety_.stale_ticks;
  const bool mostly_late = 2 * late_ticks >= unattended;  // the late loop made most of the silence
  const bool loop_stalled =
      !time_follows_ticks_ && (missed_streak_ >= safety_.missed_deadline_streak || (stale_limit && mostly_late));
  const bool stall_explains_it = device_fault.code == FaultCode::kRigTimeout && loop_stalled;
  if (valves_live(state()) && device_faulted && !stall_explains_it) enter_fault(device_fault, now_s);
  if (valves_live(state()) && stale_limit) {
    // The stale limit, on the time the rig went without a command from a fresh reading: the
    // device names why (a lost link, or frozen sensors), unless the late loop made most of it.
    DeviceFault silence;
    if (mostly_late) {
      silence.set(FaultCode::kMissedDeadlines, -1,
                  "the rig went %.0f ms without the loop's commands, %.0f ms of it because the loop was late "
                  "([safety] stale_ticks): lighten the machine's load, or use --rt enforce",
                  unattended * timing_.tick_s * 1e3, late_ticks * timing_.tick_s * 1e3);
    } else {
      device_.explain_silence(unattended * timing_.tick_s, silence);
      if (silence.code == FaultCode::kNone) silence.code = FaultCode::kSensorStale;
    }
    enter_fault(silence, now_s);
  }
  if (valves_live(state())) {
    GuardInputs inputs;
    inputs.p_max_bar = controller_.p_max_bar;
    inputs.joint_count = joints();
    inputs.stale_count = stale_count_;
    inputs.missed_streak = time_follows_ticks_ ? 0 : missed_streak_;
    inputs.heartbeat_age_s = monitor_heartbeat_.load(std::memory_order_relaxed) ? wall_s - last_heartbeat_s_ : 0.0;
    const GuardFault fired = find_guard_fault(reading, inputs, safety_);
    if (fired.code != FaultCode::kNone) enter_fault(fired.code, now_s, fired.joint);
  }

  ValveCommand valves = ValveCommand::vented(joints());
  if (valves_live(state())) {
    if (state() == EngineState::kRunning && settle_remaining_ > 0 && --settle_remaining_ == 0) {
      if (settle_extra_remaining_ > 0 && !at_trial_start(reading)) {
        --settle_extra_remaining_;
        settle_remaining_ = 1;
      } else {
        start_control_trial();
      }
    }
    if (!manual_) {
      // The periods the loop missed, held as they passed on the rig (fewer than the limits above).
      for (int i = 0; i < skipped; ++i) control_.tick_held(reading);
      held_ticks_.fetch_add(static_cast<std::uint64_t>(skipped), std::memory_order_relaxed);
    }
    if (manual_) {
      // The pulse's ticks, then `after`; its end is reported after `settle_ticks` of `after` (the
      // link's lag) with the first fresh reading: one taken after the pulse's last valves went out
      // (a rig's reading repeated while no new one arrived is not, however long the wait).
      if (pulse_remaining_ > 0) {
        valves = pulse_.valves;
        if (--pulse_remaining_ == 0) {
          pulse_report_pending_ = true;
          pulse_end_reading_s_ = last_reading_time_s_;
        }
      } else {
        valves = pulse_.after;
        if (pulse_report_pending_ && pulse_settle_remaining_ > 0) {
          --pulse_settle_remaining_;
        } else if (pulse_report_pending_ && reading.time_s > pulse_end_reading_s_) {
          pulse_report_pending_ = false;
          EngineEvent event;
          event.kind = EventKind::kValvePulseDone;
          event.time_s = now_s;
          event.trial_id = pulse_.id;
          event.reading = reading;
          event.from = event.to = state();
          emit(event);
        }
      }
    } else if (fresh) {
      valves = control_.tick(reading);
    } else {  // ride through: the valves held closed, the trial's clock going on, until a reading returns
      valves = control_.tick_held(reading);
      held_ticks_.fetch_add(1, std::memory_order_relaxed);
    }
    device_.write_valves(valves);
    if (record_ != nullptr && record_->complete) {
      EngineEvent event;
      event.kind = EventKind::kTrialComplete;
      event.time_s = now_s;
      event.record = record_;
      event.trial_id = trial_id_;
      event.from = event.to = EngineState::kRunning;
      emit(event);
      record_ = nullptr;
      correction_ = nullptr;
      joint_correction_ = nullptr;
      change_state(EngineState::kArmed, now_s, CommandKind::kTrialEnd);
    }
  } else {
    device_.vent();
  }

  TickRecord tick;
  tick.tick = tick_count_.load(std::memory_order_relaxed);
  tick.time_s = now_s;
  tick.state = state();
  tick.fault = fault();
  tick.fault_joint = fault_joint_;
  tick.reading = reading;
  for (int j = 0; j < control_.joints(); ++j) {  // every joint's, for the black box and the telemetry
    tick.joint(j) = {control_.desired_angle_rad(j), control_.last_u_total_bar(j), control_.setpoints(j)};
  }
  tick.valves = valves;
  tick.sample = control_.sample_index();
  tick.trial_id = trial_id_;
  black_box_.record(tick);
  if (state() == EngineState::kFault && !black_box_.frozen()) black_box_.freeze();
  for (auto& tap : taps_) {
    if (!tap->push(tick)) dropped_telemetry_.fetch_add(1, std::memory_order_relaxed);
  }
  snapshot_.write(tick);
  tick_count_.fetch_add(1, std::memory_order_relaxed);
}

void EngineCore::restore_armed(const ControlCore::State& state, double now_s) {
  if (ticks() != 0 || this->state() != EngineState::kSafe) {
    throw std::logic_error("EngineCore::restore_armed: only before the first tick, in SAFE");
  }
  control_.set_state(state);
  last_angle_rad_ = state.joints[0].hold_rad;
  change_state(EngineState::kArmed, now_s, CommandKind::kArm);
}

void EngineCore::vent_now() {
  device_.vent();
  if (state() != EngineState::kFault) enter_fault(FaultCode::kEmergencyStop, 0.0);
  stops_handled_.store(stop_requests_.load(std::memory_order_acquire), std::memory_order_release);
}

}  // namespace bellows
