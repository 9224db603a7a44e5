#include "devices/lcm_device.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "devices/lcm_channels.hpp"

namespace bellows {
namespace {

// How often the I/O thread looks for a new valve state from the engine: well under one tick, so
// a command leaves within about a millisecond of the tick that wrote it, without waking the I/O
// thread from the engine thread (that would be a system call in the real-time loop).
constexpr double kOutboxPoll_s = 0.001;
// health(): the link counts as up while a valid state arrived this recently (20 ticks at 200 Hz).
constexpr double kLinkAlive_s = 0.1;

void bump(std::atomic<std::uint64_t>& n) { n.store(n.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed); }

}  // namespace

LcmDevice::LcmDevice(std::int64_t session_id) : session_id_(session_id) {
  command_.session_id = session_id_;
  buffer_.resize(static_cast<std::size_t>(command_.getEncodedSize()));
  // Nothing goes out before the engine's first tick: a rig serving nobody takes the first session
  // that commands it, and would time out (and serve nobody again) if that session then fell silent.
}

std::int64_t LcmDevice::random_session_id() {
  std::random_device entropy;
  std::uniform_int_distribution<std::int64_t> pick(1, INT64_MAX);
  return pick(entropy);
}

// ---- engine thread ----

SensorReading LcmDevice::read_sensors() {
  if (!inbox_.read(reading_)) bump(stale_reads_);
  return reading_;
}

void LcmDevice::write_valves(const ValveCommand& command) {
  Outgoing out;
  out.armed = true;
  for (int i = 0; i < kActuatorCount; ++i) {  // the Device contract: clamp to [0, 1]; NaN -> closed inlet, open outlet
    const double inlet = command.inlet_duty[i], outlet = command.outlet_duty[i];
    out.valves.inlet_duty[i] = std::isfinite(inlet) ? std::clamp(inlet, 0.0, 1.0) : 0.0;
    out.valves.outlet_duty[i] = std::isfinite(outlet) ? std::clamp(outlet, 0.0, 1.0) : 1.0;
  }
  outbox_.write(out);
}

void LcmDevice::vent() { outbox_.write(Outgoing{ValveCommand::vented(), false}); }

// ---- I/O thread ----

void LcmDevice::attach(lcm::LCM& bus) { subscribe(bus, kIoStateChannel); }

void LcmDevice::on_message(const char*, const void* data, std::size_t size) {  // io_state_t only
  const DecodeStatus status = decode_checked(data, size, received_);
  if (status != DecodeStatus::kOk) return counters_.count(status);
  const io_state_t& s = received_;
  if (!valid_state(s)) return counters_.invalid();
  if (s.session_id != session_id_) {  // a rig serving nobody yet, or someone else
    last_foreign_session_.store(s.session_id, std::memory_order_relaxed);
    return counters_.foreign();
  }
  if (s.rig_id != rig_id_) {
    // Another rig answering for this session. Never switch while the valves are live; while
    // vented, the rig may have restarted: follow the new one.
    if (rig_id_ != 0 && last_armed_) return counters_.foreign();
    rig_id_ = s.rig_id;
    stats_rig_id_.store(rig_id_, std::memory_order_relaxed);
    last_state_seq_ = 0;
    last_echoed_seq_ = 0;
    last_rig_time_s_ = -INFINITY;
  }
  if (s.seq <= last_state_seq_ || !(s.time_s > last_rig_time_s_)) return counters_.out_of_order();
  if (s.command_seq > seq_ || s.command_seq < last_echoed_seq_) return counters_.invalid();  // a command never sent
  if (s.command_seq > last_echoed_seq_ && seq_ - s.command_seq < static_cast<std::int64_t>(sent_s_.size())) {
    round_trips_.record(1e3 * (monotonic_s() - sent_s_[static_cast<std::size_t>(s.command_seq) % sent_s_.size()]));
  }
  last_state_seq_ = s.seq;
  last_rig_time_s_ = s.time_s;
  last_echoed_seq_ = s.command_seq;
  last_fault_bits_.store(s.fault_bits, std::memory_order_relaxed);
  if (s.fault_bits != 0) return bump(rig_fault_states_);  // not a reading to control with
  counters_.accepted();
  pending_ = to_reading(s);
  pending_fresh_ = true;
}

double LcmDevice::service(lcm::LCM* bus, double now_s) {
  if (origin_s_ < 0.0) origin_s_ = now_s;
  if (pending_fresh_) {
    // The device's own clock, strictly increasing: the engine's stale guard watches it.
    pending_.time_s = std::max(now_s - origin_s_, std::nextafter(last_reading_time_s_, INFINITY));
    last_reading_time_s_ = pending_.time_s;
    inbox_.write(pending_);
    pending_fresh_ = false;
    last_state_s_.store(now_s, std::memory_order_relaxed);
    connected_.store(true, std::memory_order_release);
  }
  Outgoing outgoing;
  if (outbox_.read(outgoing) && bus != nullptr) publish(*bus, outgoing, now_s);
  return now_s + kOutboxPoll_s;
}

void LcmDevice::finish(lcm::LCM* bus, double now_s) {
  // Leave the rig vented, whatever the engine last asked for.
  if (bus != nullptr) publish(*bus, Outgoing{ValveCommand::vented(), false}, now_s);
}

void LcmDevice::publish(lcm::LCM& bus, const Outgoing& outgoing, double now_s) {
  command_.seq = ++seq_;
  sent_s_[static_cast<std::size_t>(seq_) % sent_s_.size()] = now_s;
  command_.utime = static_cast<std::int64_t>(now_s * 1e6);
  fill_command(outgoing.valves, outgoing.armed, command_);
  last_armed_ = outgoing.armed;
  const std::size_t size = encode_into(command_, buffer_);
  if (bus.publish(kIoCommandChannel, buffer_.data(), static_cast<unsigned int>(size)) != 0) {
    bump(publish_errors_);
    return;
  }
  bump(commands_sent_);
  if (!outgoing.armed) bump(vent_commands_sent_);
}

DeviceHealth LcmDevice::health() const {
  DeviceHealth h;
  h.has_link = true;
  h.connected = connected() && monotonic_s() - last_state_s() < kLinkAlive_s;
  round_trips_.summarize(h);
  const ReceiveCounts c = counters_.snapshot();
  h.link_errors = c.truncated + c.wrong_type + c.too_large + c.malformed + c.invalid + c.foreign + c.out_of_order +
                  rig_fault_states_.load(std::memory_order_relaxed) + publish_errors_.load(std::memory_order_relaxed);
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
  s.last_foreign_session = last_foreign_session_.load(relaxed);
  s.commands_sent = commands_sent_.load(relaxed);
  s.vent_commands_sent = vent_commands_sent_.load(relaxed);
  s.publish_errors = publish_errors_.load(relaxed);
  return s;
}

}  // namespace bellows
