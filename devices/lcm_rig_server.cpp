#include "devices/lcm_rig_server.hpp"

#include <algorithm>
#include <cmath>

#include "devices/lcm_channels.hpp"
#include "engine/errors.hpp"

namespace bellows {
namespace {
void bump(std::atomic<std::uint64_t>& n) { n.store(n.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }
}  // namespace

RigServer::RigServer(SimulatedArm& arm, const RigServerParameters& params, std::int64_t rig_id)
    : arm_(arm), params_(params), rig_id_(rig_id) {
  if (!(params.period_s > 0.0) || !(params.command_timeout_s > 0.0)) {
    throw InputError("the rig's period and command timeout must be positive");
  }
  arm_.vent();  // the safe state until the first valid command
  state_.rig_id = rig_id_;
  buffer_.resize(static_cast<std::size_t>(state_.getEncodedSize()));
}

void RigServer::attach(lcm::LCM& bus) { subscribe(bus, kIoCommandChannel); }

void RigServer::on_message(const char*, const void* data, std::size_t size) {  // io_command_t only
  const DecodeStatus status = decode_checked(data, size, received_);
  if (status != DecodeStatus::kOk) return counters_.count(status);
  const io_command_t& c = received_;
  if (!valid_command(c)) return counters_.invalid();
  if (session_ != 0 && c.session_id != session_) return counters_.foreign();
  if (c.session_id == last_session_ && c.seq <= last_seq_) return counters_.out_of_order();
  if (session_ == 0) {  // the first valid command since the start or since a timeout
    session_ = c.session_id;
    serving_.store(session_, std::memory_order_relaxed);
    bump(sessions_served_);
  }
  last_session_ = c.session_id;
  last_seq_ = c.seq;
  pending_ = c;
  pending_fresh_ = true;
  counters_.accepted();
}

void RigServer::advance_to(double now_s) {
  const double target_s = now_s - origin_s_;
  if (target_s > device_time_s_) {
    arm_.advance(target_s - device_time_s_);
    device_time_s_ = target_s;
  }
}

double RigServer::service(lcm::LCM* bus, double now_s) {
  if (origin_s_ < 0.0) {
    origin_s_ = now_s;
    next_publish_s_ = now_s;
  }
  advance_to(now_s);  // the physics catches up with the wall clock under the valves applied so far
  if (pending_fresh_) {
    arm_.write_valves(to_valves(pending_));
    applied_seq_ = pending_.seq;
    last_command_s_ = now_s;
    fault_bits_ = 0;
    pending_fresh_ = false;
  }
  if (session_ != 0 && now_s - last_command_s_ > params_.command_timeout_s) {
    arm_.vent();
    session_ = 0;
    serving_.store(0, std::memory_order_relaxed);
    applied_seq_ = 0;
    fault_bits_ = std::int32_t{io_state_t::FAULT_NO_SESSION} | std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT};
    bump(timeouts_);
  }
  if (now_s >= next_publish_s_) {
    if (bus != nullptr) publish_state(*bus, now_s);
    next_publish_s_ += params_.period_s;
    if (next_publish_s_ <= now_s) {  // woke too late: skip ahead rather than bursting
      const double behind = std::floor((now_s - next_publish_s_) / params_.period_s) + 1.0;
      missed_periods_.fetch_add(static_cast<std::uint64_t>(behind), std::memory_order_relaxed);
      next_publish_s_ += behind * params_.period_s;
    }
  }
  return session_ != 0 ? std::min(next_publish_s_, last_command_s_ + params_.command_timeout_s) : next_publish_s_;
}

void RigServer::finish(lcm::LCM* bus, double now_s) {
  arm_.vent();
  session_ = 0;
  serving_.store(0, std::memory_order_relaxed);
  applied_seq_ = 0;
  fault_bits_ = io_state_t::FAULT_NO_SESSION;
  if (bus != nullptr && origin_s_ >= 0.0) {
    advance_to(now_s);
    publish_state(*bus, now_s);
  }
}

void RigServer::publish_state(lcm::LCM& bus, double now_s) {
  fill_state(arm_.read_sensors(), state_);
  state_.seq = ++state_seq_;
  state_.session_id = session_;
  state_.command_seq = applied_seq_;
  state_.utime = static_cast<std::int64_t>(now_s * 1e6);
  state_.fault_bits = fault_bits_;
  const std::size_t size = encode_into(state_, buffer_);
  if (bus.publish(kIoStateChannel, buffer_.data(), static_cast<unsigned int>(size)) == 0) bump(states_published_);
}

RigServerStats RigServer::stats() const {
  constexpr auto relaxed = std::memory_order_relaxed;
  RigServerStats s;
  s.rig_id = rig_id_;
  s.commands = counters_.snapshot();
  s.states_published = states_published_.load(relaxed);
  s.sessions_served = sessions_served_.load(relaxed);
  s.timeouts = timeouts_.load(relaxed);
  s.missed_periods = missed_periods_.load(relaxed);
  s.serving = serving_.load(relaxed);
  return s;
}

}  // namespace bellows
