#include "devices/lcm_rig_server.hpp"
#include "engine/rt/single_writer_counter.hpp"

#include <algorithm>
#include <cmath>

#include "devices/lcm_channels.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {}  // namespace

RigServer::RigServer(SimulatedArm& arm, RigServerParameters params, std::int64_t rig_id)
    : RigServer(arm, 1, arm.parameters().integration_step_s, std::move(params), rig_id) {}

RigServer::RigServer(Device& arm, int joints, double integration_step_s, RigServerParameters params,
                     std::int64_t rig_id)
    : arm_(arm), joints_(joints), integration_step_s_(integration_step_s), params_(std::move(params)), rig_id_(rig_id) {
  if (!valid_joint_count(joints_)) {
    throw InputError("a rig of " + std::to_string(joints_) + " joints: the LCM messages carry 1 to " +
                     std::to_string(kMaxJoints));
  }
  if (!(integration_step_s_ > 0.0)) throw InputError("the rig's integration step must be positive");
  if (!(params_.period_s > 0.0) || !(params_.command_timeout_s > 0.0)) {
    throw InputError("the rig's period and command timeout must be positive");
  }
  if (params_.seq_window < 1) throw InputError("the rig's sequence window must be at least 1");
  arm_.vent();  // the safe state until a session binds
  binding_ = random_nonzero_id();
  binding_shown_.store(binding_, std::memory_order_relaxed);
  state_.rig_id = rig_id_;
  limits_.rig_id = rig_id_;
  limits_.joint_count = static_cast<std::int8_t>(joints_);
  limits_.period_s = params_.period_s;
  limits_.command_timeout_s = params_.command_timeout_s;
  limits_.pressure_ceiling_bar = params_.limits.pressure_ceiling_bar;
  limits_.angle_limit_rad = params_.limits.angle_limit_rad;
  commanded_ = ValveCommand::vented(joints_);
  buffer_.resize(max_io_message_bytes());
}

void RigServer::attach(lcm::LCM& bus) { subscribe(bus, kIoCommandChannel); }

void RigServer::say(const std::string& line) const {
  if (params_.log) params_.log(line);
}

void RigServer::notice(Notice kind, const std::string& line) {
  bool& reported = reported_[static_cast<int>(kind)];
  if (!reported)
    say(line + (kind < Notice::kPressureLimit ? ": counted and ignored (further ones only counted)"
                                              : " (further ones only counted)"));
  reported = true;
}

void RigServer::on_message(const char*, const void* data, std::size_t size) {  // io_command_t or io_joints_command_t
  const DecodeStatus status = decode_io_command(data, size, received_, params_.key.present() ? &params_.key : nullptr);
  if (status != DecodeStatus::kOk) {
    counters_.count(status);
    if (status == DecodeStatus::kOldVersion) notice(Notice::kOldVersion, std::string("a command ") + explain(status));
    if (status == DecodeStatus::kUnauthenticated)
      notice(Notice::kUnauthenticated, std::string("a command ") + explain(status));
    return;
  }
  const io_joints_command_t& c = received_;
  if (!valid_command(c)) return counters_.invalid();
  if (c.rig_id != rig_id_)
    return bump(not_addressed_);   // to another rig, or to none yet: not for us to count as foreign
  if (c.joint_count != joints_) {  // meant for another arm: nothing of it is safe to apply, and it binds nothing
    notice(Notice::kOtherJoints, "a command for an arm of " + arm_joints_words(c.joint_count) +
                                     " but this rig's arm has " + arm_joints_words(joints_) +
                                     " (the engine's [arm] must be the rig's)");
    counters_.other_joints();
    if (!c.armed) {  // but a vent only makes the rig safer, whatever arm it was meant for
      io_joints_command_t vent = c;
      vent.joint_count = static_cast<std::int8_t>(joints_);
      obey_vent(vent);
    }
    return;
  }
  const bool outside_range = (limit_bits_ & io_state_t::FAULT_ANGLE_LIMIT) != 0;
  if (session_ == 0 && c.binding == binding_ && !c.armed && outside_range) {
    notice(Notice::kForeign,
           "session " + std::to_string(c.session_id) + " tried to bind while the arm is beyond the rig's angle range");
    return counters_.foreign();
  }
  if (session_ == 0 && c.binding == binding_ && !c.armed) {  // free: a session binds with a vent echoing the offer
    session_ = c.session_id;
    last_seq_ = c.seq - 1;
    serving_.store(session_, std::memory_order_relaxed);
    bump(sessions_served_);
    std::fill(std::begin(reported_), std::end(reported_), false);
    say("bound to session " + std::to_string(session_));
  }
  const bool own = session_ != 0 && c.session_id == session_ && c.binding == binding_;
  if (own && c.seq > last_seq_ && c.seq - last_seq_ <= params_.seq_window) {
    last_seq_ = c.seq;
    pending_ = c;
    pending_in_sequence_ = true;
    pending_fresh_ = true;
    return counters_.accepted();
  }
  if (!c.armed) return obey_vent(c);  // whatever its session or sequence number: it only makes the rig safer
  if (!own) {
    notice(Notice::kForeign, session_ == 0
                                 ? "a command of session " + std::to_string(c.session_id) + " that did not bind first"
                                 : "a command of session " + std::to_string(c.session_id) + " while serving session " +
                                       std::to_string(session_));
    return counters_.foreign();
  }
  if (c.seq <= last_seq_) return counters_.out_of_order();
  notice(Notice::kJump, "a command of session " + std::to_string(session_) + " jumping from seq " +
                            std::to_string(last_seq_) + " to " + std::to_string(c.seq) +
                            " (more than [lcm] seq_window)");
  counters_.out_of_order();
}

void RigServer::obey_vent(const io_joints_command_t& vent) {
  if (!pending_fresh_ || !pending_in_sequence_) {  // never overwrite the session's own command unapplied
    pending_ = vent;
    pending_in_sequence_ = false;
    pending_fresh_ = true;
  } else {
    pending_.armed = false;  // the session's command, vented
  }
  bump(vents_out_of_sequence_);
}

static_assert(kRigPressureLimitBit == io_state_t::FAULT_PRESSURE_LIMIT &&
                  kRigAngleLimitBit == io_state_t::FAULT_ANGLE_LIMIT,
              "the rig limits' bits are io_state_t's");

void RigServer::apply_limits(bool write) {
  const LimitedValves limited = enforce_rig_limits(commanded_, arm_.read_sensors(), params_.limits);
  const std::int32_t before = limit_bits_;
  limit_bits_ = limited.fault_bits;
  limit_bits_since_state_ |= limit_bits_;
  const auto rising = [&](std::int32_t bit) { return (limit_bits_ & bit) != 0 && (before & bit) == 0; };
  if (rising(io_state_t::FAULT_PRESSURE_LIMIT)) {
    bump(pressure_trips_);
    notice(Notice::kPressureLimit, "a chamber above the rig's ceiling of " +
                                       std::to_string(params_.limits.pressure_ceiling_bar) +
                                       " bar: that chamber vented");
  }
  if (rising(io_state_t::FAULT_ANGLE_LIMIT)) {
    bump(angle_trips_);
    const std::string which = joints_ > 1 ? "joint " + std::to_string(limited.angle_joint + 1) : std::string("the arm");
    notice(Notice::kAngleLimit,
           which + " beyond the rig's angle range: vented" +
               (session_ != 0 ? ", session " + std::to_string(session_) + " dropped" : std::string()));
  }
  if (limited.angle_exceeded) {
    commanded_ = ValveCommand::vented(joints_);
    if (session_ != 0)
      release(std::int32_t{io_state_t::FAULT_NO_SESSION} | std::int32_t{io_state_t::FAULT_ANGLE_LIMIT});
  }
  // Written only when something changed: every write starts a new PWM period.
  if (write || limit_bits_ != 0 || before != 0) arm_.write_valves(limited.valves);
}

void RigServer::release(std::int32_t fault_bits) {
  constexpr std::int32_t kReasons =
      std::int32_t{io_state_t::FAULT_ANGLE_LIMIT} | std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT};
  if (session_ != 0 && (fault_bits & kReasons) != 0) {  // tripped: the states name the session dropped, and why
    tripped_session_ = session_;
    tripped_command_seq_ = applied_seq_;
    tripped_states_left_ = std::max(1, static_cast<int>(std::ceil(params_.command_timeout_s / params_.period_s)));
  }
  if (pending_fresh_) {  // a command of the dropped session not applied yet: only its vent remains
    pending_.armed = false;
    pending_in_sequence_ = false;
  }
  arm_.vent();
  commanded_ = ValveCommand::vented(joints_);
  session_ = 0;
  serving_.store(0, std::memory_order_relaxed);
  applied_seq_ = 0;
  binding_ = random_nonzero_id();  // commands of the old binding, replayed or late, now bind nothing
  binding_shown_.store(binding_, std::memory_order_relaxed);
  fault_bits_ = fault_bits;
  std::fill(std::begin(reported_), std::end(reported_), false);
}

void RigServer::advance_to(double now_s) { advance_by(now_s - origin_s_ - device_time_s_); }

void RigServer::advance_by(double dt_s) {
  // The limits are checked at every integration step, as a driver checks them at every sensor read.
  const double target_s = device_time_s_ + dt_s;
  while (target_s > device_time_s_) {
    const double dt = std::min(integration_step_s_, target_s - device_time_s_);
    arm_.advance(dt);
    device_time_s_ += dt;
    apply_limits(false);
  }
}

double RigServer::service(lcm::LCM* bus, double now_s) {
  if (origin_s_ < 0.0) {
    origin_s_ = now_s;
    next_publish_s_ = now_s;
    next_limits_s_ = now_s;
  }
  if (!params_.stepped)
    advance_to(now_s);  // the physics catches up with the wall clock under the valves applied so far
  if (pending_fresh_) {
    commanded_ = to_valves(pending_);
    const bool step = params_.stepped && pending_in_sequence_;
    if (pending_in_sequence_) {  // only the session's own commands keep it bound
      applied_seq_ = pending_.seq;
      last_command_s_ = now_s;
      fault_bits_ = 0;
    }
    pending_fresh_ = false;
    apply_limits(true);
    if (step) {  // lockstep: one period under this command, and its answer at once
      advance_by(params_.period_s);
      if (bus != nullptr && session_ != 0) publish_state(*bus, now_s);
    }
  }
  if (session_ != 0 && params_.command_timeout_enforced && now_s - last_command_s_ > params_.command_timeout_s) {
    say("the commands of session " + std::to_string(session_) + " stopped: vented, session dropped");
    release(std::int32_t{io_state_t::FAULT_NO_SESSION} | std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT});
    bump(timeouts_);
  }
  if (now_s >= next_limits_s_) {
    if (bus != nullptr) publish_limits(*bus, now_s);
    next_limits_s_ = now_s + kIoLimitsPeriod_s;
  }
  const bool answers_only = params_.stepped && session_ != 0;  // its time stands still between commands
  if (now_s >= next_publish_s_) {
    if (bus != nullptr && !answers_only) publish_state(*bus, now_s);
    next_publish_s_ += params_.period_s;
    if (next_publish_s_ <= now_s) {  // woke too late: skip ahead rather than bursting
      const double behind = std::floor((now_s - next_publish_s_) / params_.period_s) + 1.0;
      missed_periods_.fetch_add(static_cast<std::uint64_t>(behind), std::memory_order_relaxed);
      next_publish_s_ += behind * params_.period_s;
    }
  }
  const double next_s = std::min(next_publish_s_, next_limits_s_);
  return session_ != 0 && params_.command_timeout_enforced
             ? std::min(next_s, last_command_s_ + params_.command_timeout_s)
             : next_s;
}

void RigServer::finish(lcm::LCM* bus, double now_s) {
  if (bus != nullptr && origin_s_ >= 0.0 && !params_.stepped) advance_to(now_s);
  release(io_state_t::FAULT_NO_SESSION);
  if (bus != nullptr && origin_s_ >= 0.0) publish_state(*bus, now_s);
}

void RigServer::publish_state(lcm::LCM& bus, double now_s) {
  // A stepped rig's offers repeat its last reading: a sensor read draws the simulated arm's noise,
  // and the number of offers depends on the wall clock, which must not change a lockstep run.
  if (!params_.stepped || session_ != 0 || !reading_taken_) last_reading_ = arm_.read_sensors();
  reading_taken_ = true;
  fill_state(last_reading_, state_);
  state_.seq = ++state_seq_;
  const bool tripped = tripped_states_left_ > 0 && session_ == 0;
  if (tripped) --tripped_states_left_;
  state_.binding = binding_;  // tripped: already the new offer (a bind is refused while beyond the range)
  state_.session_id = tripped ? tripped_session_ : session_;
  state_.command_seq = tripped ? tripped_command_seq_ : applied_seq_;
  state_.utime = static_cast<std::int64_t>(now_s * 1e6);
  state_.fault_bits = fault_bits_ | limit_bits_ | limit_bits_since_state_;  // a limit that acted between two states too
  limit_bits_since_state_ = 0;
  const ReceiveCounts c = counters_.snapshot();
  state_.foreign_commands = static_cast<std::int64_t>(c.foreign + c.out_of_order + c.old_version + c.other_joints);
  state_.unauthenticated_commands = static_cast<std::int64_t>(c.unauthenticated);
  const std::size_t size = encode_io_state(state_, params_.key, buffer_);
  if (bus.publish(kIoStateChannel, buffer_.data(), static_cast<unsigned int>(size)) == 0) bump(states_published_);
}

void RigServer::publish_limits(lcm::LCM& bus, double now_s) {
  ++limits_.seq;
  limits_.utime = static_cast<std::int64_t>(now_s * 1e6);
  const std::size_t size = encode_signed(limits_, params_.key, buffer_);
  bus.publish(kIoLimitsChannel, buffer_.data(), static_cast<unsigned int>(size));
}

RigServerStats RigServer::stats() const {
  constexpr auto relaxed = std::memory_order_relaxed;
  RigServerStats s;
  s.rig_id = rig_id_;
  s.commands = counters_.snapshot();
  s.vents_obeyed_out_of_sequence = vents_out_of_sequence_.load(relaxed);
  s.not_addressed = not_addressed_.load(relaxed);
  s.states_published = states_published_.load(relaxed);
  s.sessions_served = sessions_served_.load(relaxed);
  s.timeouts = timeouts_.load(relaxed);
  s.pressure_limit_trips = pressure_trips_.load(relaxed);
  s.angle_limit_trips = angle_trips_.load(relaxed);
  s.missed_periods = missed_periods_.load(relaxed);
  s.serving = serving_.load(relaxed);
  s.binding = binding_shown_.load(relaxed);
  return s;
}

}  // namespace bellows
