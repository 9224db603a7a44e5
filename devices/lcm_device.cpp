#include "devices/lcm_device.hpp"
#include "engine/rt/single_writer_counter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "devices/lcm_channels.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// How often the I/O thread looks for a new valve state from the engine: well under one tick, so
// a command leaves within about a millisecond of the tick that wrote it, without waking the I/O
// thread from the engine thread (that would be a system call in the real-time loop).
constexpr double kOutboxPoll_s = 0.001;
// health(): the link counts as up while a valid state arrived this recently (20 ticks at 200 Hz).
constexpr double kLinkAlive_s = 0.1;
// Lockstep: how often advance() looks whether the rig's answer has arrived (far under a round trip).
constexpr double kAnswerPoll_s = 0.0001;

void sleep_s(double seconds) { std::this_thread::sleep_for(std::chrono::duration<double>(seconds)); }

}  // namespace

LcmDevice::LcmDevice(std::int64_t session_id, LcmKey key, double rig_silence_s, int joints)
    : session_id_(session_id), key_(key), rig_silence_s_(rig_silence_s), joints_(joints) {
  if (!valid_joint_count(joints_)) {
    throw InputError("an LCM rig of " + std::to_string(joints_) + " joints: the messages carry 1 to " +
                     std::to_string(kMaxJoints));
  }
  command_.session_id = session_id_;
  buffer_.resize(max_io_message_bytes());
  // Nothing goes out before the engine's first tick: a rig serving nobody takes the first session
  // that commands it, and would time out (and serve nobody again) if that session then fell silent.
}

// ---- engine thread ----

SensorReading LcmDevice::read_sensors() {
  if (inbox_.read(reading_)) {
    if (!lockstep_) phase_lock_.observe(monotonic_s() - reading_.handed_over_s);
  } else {
    bump(stale_reads_);
  }
  return reading_.reading;
}

double LcmDevice::tick_shift_s() {
  if (lockstep_) return 0.0;  // the rig's answers pace the ticks
  const double shift_s = phase_lock_.take_shift_s();
  phase_lead_ms_.store(1e3 * phase_lock_.lead_s(), std::memory_order_relaxed);
  phase_shifted_ms_.store(1e3 * phase_lock_.shifted_s(), std::memory_order_relaxed);
  return shift_s;
}

void LcmDevice::write_valves(const ValveCommand& command) {
  Outgoing out;
  out.armed = true;
  out.generation = ++written_;
  // A command for another joint count than the arm's is meant for another arm: every joint goes
  // out vented, and the engine's guard faults on readings of the arm's joint count.
  out.valves = ValveCommand::vented(joints_);
  if (command.joint_count != joints_) return outbox_.write(out);
  for (int j = 0; j < joints_; ++j) {
    const JointValves& valves = command.joint[static_cast<std::size_t>(j)];
    JointValves& sent = out.valves.joint[static_cast<std::size_t>(j)];
    for (int i = 0; i < kActuatorCount;
         ++i) {  // the Device contract: clamp to [0, 1]; NaN -> closed inlet, open outlet
      const double inlet = valves.inlet_duty[i], outlet = valves.outlet_duty[i];
      sent.inlet_duty[i] = std::isfinite(inlet) ? std::clamp(inlet, 0.0, 1.0) : 0.0;
      sent.outlet_duty[i] = std::isfinite(outlet) ? std::clamp(outlet, 0.0, 1.0) : 1.0;
    }
  }
  outbox_.write(out);
}

void LcmDevice::vent() { outbox_.write(Outgoing{ValveCommand::vented(joints_), false, ++written_}); }

void LcmDevice::set_lockstep(double answer_timeout_s) {
  if (!(answer_timeout_s > 0.0)) throw InputError("the lockstep answer timeout must be positive");
  lockstep_ = true;
  answer_timeout_s_ = answer_timeout_s;
}

void LcmDevice::advance(double dt_s) {
  if (!lockstep_) return;  // a real rig's time passes on its own
  const double start_s = monotonic_s();
  while (answered_.load(std::memory_order_acquire) < written_) {
    if (!serving_us_.load(std::memory_order_acquire)) return sleep_s(dt_s);  // no rig steps with us yet: its pace
    if (monotonic_s() - start_s > answer_timeout_s_) return;                 // no answer: a tick without a reading
    sleep_s(kAnswerPoll_s);
  }
}

// ---- I/O thread ----

void LcmDevice::attach(lcm::LCM& bus) {
  subscribe(bus, kIoStateChannel);
  subscribe(bus, kIoLimitsChannel);
}

void LcmDevice::on_limits(const void* data, std::size_t size) {
  io_rig_limits_t& l = limits_received_;
  if (decode_checked(data, size, l, key_.present() ? &key_ : nullptr) != DecodeStatus::kOk || !valid_rig_limits(l) ||
      l.rig_id != rig_id_) {  // only the rig addressed speaks for this session's rig
    return bump(limits_ignored_);
  }
  announced_timeout_s_ = l.command_timeout_s;
  limits_seen_.write(
      {now_s_, l.rig_id, l.joint_count, l.period_s, l.command_timeout_s, l.pressure_ceiling_bar, l.angle_limit_rad});
}

void LcmDevice::on_message(const char* channel, const void* data,
                           std::size_t size) {  // io_state_t or io_joints_state_t
  if (std::strcmp(channel, kIoLimitsChannel) == 0) return on_limits(data, size);
  const DecodeStatus status = decode_io_state(data, size, received_, key_.present() ? &key_ : nullptr);
  if (status != DecodeStatus::kOk) return counters_.count(status);
  const io_joints_state_t& s = received_;
  if (!valid_state(s)) return counters_.invalid();
  if (s.joint_count != joints_) {  // a rig of another arm: never bound to, whatever it offers
    last_other_joints_.store(s.joint_count, std::memory_order_relaxed);
    return counters_.other_joints();
  }
  if (s.rig_id == rig_id_ && rig_id_ != 0) {  // for the rig check: what the rig addressed says, whatever its session
    const RigStateSeen seen{now_s_, s.session_id, s.binding, s.command_seq, s.fault_bits, to_reading(s)};
    rig_seen_.write(seen);
    constexpr std::int32_t kTrip =
        std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT} | std::int32_t{io_state_t::FAULT_ANGLE_LIMIT};
    if (hold_seen_ && !trip_kept_ && (s.fault_bits & kTrip) != 0) {
      trip_seen_.write(seen);
      trip_kept_ = true;
    }
  }
  const bool rig_gone = now_s_ - last_rig_state_s_ > rig_silence_s_;  // e.g. it restarted, with a new id
  if (s.rig_id == rig_id_) last_rig_state_s_ = now_s_;
  // The rig addressed, tripped: it names this session with NO_SESSION and a new offer (docs/lcm-protocol.md).
  const bool tripped_ours = s.session_id == session_id_ && s.rig_id == rig_id_ && s.binding != binding_ &&
                            (s.fault_bits & io_state_t::FAULT_NO_SESSION) != 0;
  if (s.session_id == 0 || tripped_ours) {  // a free rig's offer
    // Ours dropped this session (timeout, angle range): a rig that offers at once, without a tripped
    // state naming this session, still gives its reason in the offer's bits.
    if (s.rig_id == rig_id_ && bound_ && last_armed_) report_trip(s, true);
    if (tripped_ours) {  // the rig's last word on this session: its reason, in the report too
      last_fault_bits_.store(s.fault_bits, std::memory_order_relaxed);
      bump(rig_fault_states_);
    }
    if (s.rig_id == rig_id_) bound_ = false;
    // Never switch while the valves are live; while vented, take the offer of any free rig until one
    // serves this session, a new offer of the rig addressed, and another rig's when ours is gone.
    if (!last_armed_ && (!bound_ || s.rig_id == rig_id_ || rig_gone) &&
        (s.rig_id != rig_id_ || s.binding != binding_)) {
      if (s.rig_id != rig_id_) announced_timeout_s_ = 0.0;  // until this rig announces its own
      rig_id_ = s.rig_id;
      binding_ = s.binding;
      bound_ = false;
      last_rig_state_s_ = now_s_;
      stats_rig_id_.store(rig_id_, std::memory_order_relaxed);
      last_state_seq_ = 0;
      last_echoed_seq_ = 0;
      last_rig_time_s_ = -INFINITY;
      reported_trip_bits_ = 0;
    }
    serving_us_.store(bound_, std::memory_order_release);
    return counters_.offer();  // what every engine hears before it binds: counted apart, not an error
  }
  if (s.session_id != session_id_) {  // a rig serving someone else
    last_foreign_session_.store(s.session_id, std::memory_order_relaxed);
    return counters_.foreign();
  }
  if (s.rig_id != rig_id_ || s.binding != binding_) return counters_.foreign();  // not the binding this session made
  bound_ = true;
  serving_us_.store(true, std::memory_order_release);
  if (s.seq <= last_state_seq_ || !(s.time_s > last_rig_time_s_)) return counters_.out_of_order();
  if (s.command_seq < last_echoed_seq_) return counters_.invalid();
  rig_foreign_commands_.store(s.foreign_commands, std::memory_order_relaxed);
  rig_unauthenticated_commands_.store(s.unauthenticated_commands, std::memory_order_relaxed);
  if (s.command_seq > seq_) {  // the rig applies a command of this session that this engine never sent
    bump(commands_not_ours_);
    return counters_.invalid();
  }
  if (s.command_seq > last_echoed_seq_ && seq_ - s.command_seq < static_cast<std::int64_t>(sent_s_.size())) {
    round_trips_.record(1e3 * (monotonic_s() - sent_s_[static_cast<std::size_t>(s.command_seq) % sent_s_.size()]));
  }
  last_state_seq_ = s.seq;
  last_rig_time_s_ = s.time_s;
  last_echoed_seq_ = s.command_seq;
  last_fault_bits_.store(s.fault_bits, std::memory_order_relaxed);
  report_trip(s, false);
  constexpr std::int32_t kNoReading = std::int32_t{io_state_t::FAULT_NO_SESSION} |
                                      std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT} |
                                      std::int32_t{io_state_t::FAULT_SENSOR} | std::int32_t{io_state_t::FAULT_VALVE};
  if ((s.fault_bits & kNoReading) != 0) return bump(rig_fault_states_);  // not a reading to control with
  counters_.accepted();
  pending_ = to_reading(s);
  pending_fresh_ = true;
  if (s.command_seq >= awaited_seq_) answer_generation_ = awaited_generation_;  // lockstep: the tick's answer
}

double LcmDevice::service(lcm::LCM* bus, double now_s) {
  now_s_ = now_s;
  // How long the rig addressed has said nothing at all, on this thread's clock (explain_silence()).
  rig_silent_s_.store(rig_id_ == 0 ? INFINITY : now_s - last_rig_state_s_, std::memory_order_relaxed);
  io_turns_.turn(monotonic_s());
  if (timeout_applied_seq_ >= 0) name_command_timeout(now_s);  // before this turn sends anything
  if (origin_s_ < 0.0) origin_s_ = now_s;
  if (pending_fresh_) {
    // The device's own clock, strictly increasing: the engine's stale guard watches it.
    pending_.time_s = std::max(now_s - origin_s_, std::nextafter(last_reading_time_s_, INFINITY));
    last_reading_time_s_ = pending_.time_s;
    inbox_.write(Handover{pending_, monotonic_s()});
    answered_.store(answer_generation_, std::memory_order_release);  // after the reading it answers with
    pending_fresh_ = false;
    last_state_s_.store(now_s, std::memory_order_relaxed);
    connected_.store(true, std::memory_order_release);
  }
  const bool hold = hold_commands_.load(std::memory_order_acquire);
  if (hold && !hold_seen_) trip_kept_ = false;  // a new hold: watch for the trip anew
  hold_seen_ = hold;
  Outgoing outgoing;
  if (outbox_.read(outgoing) && bus != nullptr && !hold) {
    // The engine's commands only (not finish()'s last vent), and none across a hold (the rig check's).
    if (const double gap_s = now_s - last_engine_command_s_;
        gap_s > longest_command_gap_s_.load(std::memory_order_relaxed)) {
      longest_command_gap_s_.store(gap_s, std::memory_order_relaxed);
    }
    last_engine_command_s_ = now_s;
    publish(*bus, outgoing, now_s);
  }
  if (hold) last_engine_command_s_ = NAN;
  commands_held_.store(hold, std::memory_order_release);
  return now_s + kOutboxPoll_s;
}

void LcmDevice::finish(lcm::LCM* bus, double now_s) {
  // Leave the rig vented, whatever the engine last asked for.
  if (bus != nullptr) publish(*bus, Outgoing{ValveCommand::vented(joints_), false}, now_s);
}

void LcmDevice::publish(lcm::LCM& bus, const Outgoing& outgoing, double now_s) {
  command_.seq = ++seq_;
  sent_s_[static_cast<std::size_t>(seq_) % sent_s_.size()] = now_s;
  command_.rig_id = rig_id_;
  command_.binding = binding_;
  command_.utime = static_cast<std::int64_t>(now_s * 1e6);
  fill_command(outgoing.valves, outgoing.armed, command_);
  last_armed_ = outgoing.armed;
  const std::size_t size = encode_io_command(command_, key_, buffer_);
  if (bus.publish(kIoCommandChannel, buffer_.data(), static_cast<unsigned int>(size)) != 0) {
    bump(publish_errors_);
    return;
  }
  bump(commands_sent_);
  if (!outgoing.armed) bump(vent_commands_sent_);
  last_sent_seq_.store(seq_, std::memory_order_relaxed);
  last_sent_s_.store(now_s, std::memory_order_release);
  awaited_seq_ = seq_;
  awaited_generation_ = outgoing.generation;
}

DeviceHealth LcmDevice::health() const {
  DeviceHealth h;
  h.has_link = true;
  h.connected = connected() && monotonic_s() - last_state_s() < kLinkAlive_s;
  round_trips_.summarize(h);
  const ReceiveCounts c = counters_.snapshot();
  // The rig's offers before binding are not errors (ReceiveCounts::offers): only what went wrong.
  h.link_errors =
      c.ignored() + rig_fault_states_.load(std::memory_order_relaxed) + publish_errors_.load(std::memory_order_relaxed);
  h.stale_readings = stale_reads_.load(std::memory_order_relaxed);
  return h;
}

LcmDeviceStats LcmDevice::stats() const {
  constexpr auto relaxed = std::memory_order_relaxed;
  LcmDeviceStats s;
  s.session_id = session_id_;
  s.rig_id = stats_rig_id_.load(relaxed);
  s.states = counters_.snapshot();
  s.rig_fault_states = rig_fault_states_.load(relaxed);
  s.last_fault_bits = last_fault_bits_.load(relaxed);
  s.last_trip_bits = last_trip_bits_.load(relaxed);
  s.last_foreign_session = last_foreign_session_.load(relaxed);
  s.joints = joints_;
  s.last_other_joints = last_other_joints_.load(relaxed);
  s.commands_sent = commands_sent_.load(relaxed);
  s.vent_commands_sent = vent_commands_sent_.load(relaxed);
  s.publish_errors = publish_errors_.load(relaxed);
  s.longest_command_gap_s = longest_command_gap_s_.load(relaxed);
  s.commands_not_ours = commands_not_ours_.load(relaxed);
  s.rig_foreign_commands = rig_foreign_commands_.load(relaxed);
  s.rig_unauthenticated_commands = rig_unauthenticated_commands_.load(relaxed);
  s.keyed = key_.present();
  return s;
}

std::string LcmDevice::diagnosis() const {
  const LcmDeviceStats s = stats();
  const std::string advice =
      s.keyed ? "" : " (set the same [lcm] key_file on the rig and the engine: docs/lcm-protocol.md)";
  if (s.commands_not_ours > 0) {
    return "another sender is commanding this rig: it applied commands this session never sent (" +
           std::to_string(s.commands_not_ours) + " states)" + advice;
  }
  if (s.states.unauthenticated > 0) {
    return "another sender publishes rig states on this bus: " + std::to_string(s.states.unauthenticated) +
           " failed authentication and were ignored (or the rig has a different [lcm] key_file)";
  }
  if (s.states.other_joints > 0) {
    return "a rig on this bus serves an arm of " + arm_joints_words(s.last_other_joints) + " but this arm has " +
           arm_joints_words(s.joints) + ": " + std::to_string(s.states.other_joints) +
           " states ignored (the engine's [arm] must be the rig's: docs/lcm-protocol.md)";
  }
  if (s.states.old_version > 0) {
    return "a rig on this bus speaks protocol version 1: " + std::to_string(s.states.old_version) +
           " states ignored (update it: docs/lcm-protocol.md)";
  }
  if (s.rig_foreign_commands > 0 || s.rig_unauthenticated_commands > 0) {
    return "other senders are on this rig's bus: the rig ignored " + std::to_string(s.rig_foreign_commands) +
           " commands of other sessions and " + std::to_string(s.rig_unauthenticated_commands) +
           " unauthenticated ones" + advice;
  }
  return "";
}

}  // namespace bellows
