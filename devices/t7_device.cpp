#include "devices/t7_device.hpp"
#include "engine/rt/single_writer_counter.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "devices/t7_errors.hpp"
#include "engine/base/cancellation.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// How often the I/O thread looks for a new command: well under a tick, so that a command leaves
// within half a millisecond of the tick that wrote it, without the engine thread waking anyone
// (that would be a system call in the real-time loop).
constexpr double kOutboxPoll_s = 0.0005;
// The round-trip figures are taken over this many latest exchanges, refreshed this often.
constexpr std::size_t kRoundTripWindow = 4096;
constexpr std::size_t kRoundTripRefresh = 64;

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

void sleep_s(double seconds) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(seconds);
  t.tv_nsec = static_cast<long>((seconds - static_cast<double>(t.tv_sec)) * 1e9);
  nanosleep(&t, nullptr);
}

// The T7's wiring drives one joint: a command for another joint count vents it.
ValveCommand clamped(const ValveCommand& command) {
  const JointValves valves = single_joint_valves(command);
  ValveCommand c;  // the Device contract: clamp to [0, 1]; NaN -> closed inlet, open outlet
  for (int i = 0; i < kActuatorCount; ++i) {
    const double inlet = valves.inlet_duty[i], outlet = valves.outlet_duty[i];
    c.joint[0].inlet_duty[i] = std::isfinite(inlet) ? std::clamp(inlet, 0.0, 1.0) : 0.0;
    c.joint[0].outlet_duty[i] = std::isfinite(outlet) ? std::clamp(outlet, 0.0, 1.0) : 1.0;
  }
  return c;
}

}  // namespace

std::string T7Device::seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}

double T7Device::duty_of(const ValveCommand& command, ValveRole role) {
  const JointValves& c = command.joint[0];
  switch (role) {
    case ValveRole::kInletA:
      return c.inlet_duty[0];
    case ValveRole::kInletB:
      return c.inlet_duty[1];
    case ValveRole::kOutletA:
      return c.outlet_duty[0];
    case ValveRole::kOutletB:
      return c.outlet_duty[1];
  }
  return 0.0;
}

T7Device::T7Device(T7DeviceOptions options)
    : options_(std::move(options)),
      angle_zero_rad_(options_.profile.angle_zero_rad),
      address_(options_.host + ":" + std::to_string(options_.port)),
      client_(options_.host, options_.port),
      clock_(t7::pwm_clock_for(options_.profile.pwm_frequency_hz)) {
  validate_rig_profile(options_.profile);
  // Before any traffic: index 0 means the Pro's default here, the slower one (checked again for
  // the product that answers).
  t7::require_exchange_fits(options_.profile, t7::Product::kT7Pro, options_.tick_s, options_.link.response_timeout_s);
  int lowest = t7::kDioCount, highest = -1, highest_ain = 0;
  for (ValveRole role : kValveRoles) {
    lowest = std::min(lowest, options_.profile.dio(role));
    highest = std::max(highest, options_.profile.dio(role));
  }
  for (SensorRole role : kSensorRoles) highest_ain = std::max(highest_ain, options_.profile.input(role).ain);
  first_dio_ = lowest;
  dio_span_ = highest - lowest + 1;
  ain_registers_ = 2 * (highest_ain + 1);
  duty_registers_.assign(static_cast<std::size_t>(2 * dio_span_), 0);
  ain_buffer_.assign(static_cast<std::size_t>(ain_registers_), 0);
  round_trips_ms_.assign(kRoundTripWindow, 0.0);
  scratch_ms_.assign(kRoundTripWindow, 0.0);
  for (auto& v : volts_) v.store(0.0);

  // [t7] connect_timeout_s bounds the connection and the whole configuration together; a stop
  // signal ends either at once.
  const double connect_timeout_s = options_.link.connect_timeout_s;
  client_.set_stop(options_.stop);
  client_.set_deadline(now_s() + connect_timeout_s);
  client_.set_response_timeout(connect_timeout_s);
  if (const std::string why = client_.connect(connect_timeout_s); !why.empty()) {
    if (client_.interrupted()) throw Cancelled("t7 " + address_ + ": connecting interrupted");
    throw EnvironmentError("t7 " + address_ + ": cannot connect within [t7] connect_timeout_s = " +
                           seconds_text(connect_timeout_s) + " (" + why + ")");
  }
  configure();
  client_.set_stop(nullptr);  // from here on the I/O thread owns the link: its last word is a vent
  client_.clear_deadline();
  client_.set_response_timeout(options_.link.response_timeout_s);
  origin_s_ = now_s();
  thread_ = std::thread([this] { serve(); });
}

T7Device::~T7Device() { stop(); }

void T7Device::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

// ---- engine thread ----

SensorReading T7Device::read_sensors() {
  if (!inbox_.read(reading_)) bump(stale_readings_);
  return reading_;
}

void T7Device::write_valves(const ValveCommand& command) { outbox_.write(Outgoing{clamped(command)}); }

void T7Device::vent() { outbox_.write(Outgoing{ValveCommand::vented()}); }

// ---- I/O thread ----

void T7Device::serve() {
  if (options_.realtime) {
    sched_param param{};
    param.sched_priority = options_.priority;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);  // refused: run without, as the loop does
  }
  pthread_setname_np(pthread_self(), "bellows-t7-io");  // as htop -H, ps -L and gdb show it
  ValveCommand current = ValveCommand::vented();
  double last_command_s = now_s();
  double next_idle_s = 0.0;
  while (!stop_.load(std::memory_order_acquire)) {
    Outgoing out;
    const double now = now_s();
    io_turns_.turn(now);
    const bool fresh = outbox_.read(out);
    if (fresh) {
      current = out.valves;
      last_command_s = now;
    } else if (now - last_command_s > options_.link.command_timeout_s) {
      current = ValveCommand::vented();  // the engine fell silent: do not keep its last duties
    }
    // Without commands, one exchange every other tick keeps the readings and the watchdog alive.
    if (fresh || now >= next_idle_s) {
      exchange(current);
      next_idle_s = now + 2.0 * options_.tick_s;
    } else if (take_late_read()) {
      // The read of an exchange that missed its deadline answered after all: hand it over, it is
      // usually in time for the next tick, which then holds nothing.
      late_readings_.store(client_.late_reads_taken(), std::memory_order_release);
      const double end = now_s();
      record_round_trip((end - exchange_start_s_) * 1e3);
      publish_reading(end);
    } else {
      sleep_s(kOutboxPoll_s);
    }
  }
  exchange(ValveCommand::vented());  // the last word: vented, whatever the engine last asked for
}

bool T7Device::take_late_read() {
  const bool taken = client_.take_late_read(ain_buffer_.data());
  heard_s_.store(client_.last_receive_s(), std::memory_order_release);
  return taken;
}

void T7Device::encode_duties(const ValveCommand& valves) {
  std::fill(duty_registers_.begin(), duty_registers_.end(), 0);  // lines in the block bellows does not use
  for (ValveRole role : kValveRoles) {
    const int offset = 2 * (options_.profile.dio(role) - first_dio_);
    t7::put_u32(clock_.config_a(duty_of(valves, role)), &duty_registers_[static_cast<std::size_t>(offset)]);
  }
}

bool T7Device::exchange(const ValveCommand& valves) {
  encode_duties(valves);
  const double start = now_s();
  exchange_start_s_ = start;
  client_.set_deadline(start + options_.link.response_timeout_s);  // the write and the read together
  const int write_at = t7::kDioEfConfigA(first_dio_);
  bool ok = client_.write(write_at, 2 * dio_span_, duty_registers_.data());
  const int failed_at = ok ? t7::kAin(0) : write_at;
  ok = ok && client_.read(t7::kAin(0), ain_registers_, ain_buffer_.data());
  client_.clear_deadline();
  const double end = now_s();
  heard_s_.store(client_.last_receive_s(), std::memory_order_release);
  late_answers_.store(client_.late_answers(), std::memory_order_relaxed);
  reconnects_.store(client_.reconnects(), std::memory_order_relaxed);
  if (!ok) {
    bump(link_errors_);
    // A late answer stays on the connection and is dropped by its transaction id; a lost
    // connection is opened again by the next request (the old one closed first).
    if (client_.last_exception() != 0) {
      const std::string why = refusal(failed_at == write_at ? "writing" : "reading", failed_at);
      if (!refusal_pending_.load(std::memory_order_acquire)) {  // the engine took the last one
        std::snprintf(refusal_text_.data(), refusal_text_.size(), "t7 %s: %s", address_.c_str(), why.c_str());
        refusal_pending_.store(true, std::memory_order_release);
      }
      fail_link(why);
    } else {
      fail_link(client_.last_error());
    }
    return false;
  }
  record_round_trip((end - start) * 1e3);
  bump(exchanges_);
  publish_reading(end);
  return true;
}

void T7Device::publish_reading(double end) {
  if (!link_up_.exchange(true, std::memory_order_relaxed)) {
    std::fprintf(stderr, "bellows: t7 link %s answers again\n", address_.c_str());
  }
  SensorReading r;
  const RigProfile& p = options_.profile;
  for (SensorRole role : kSensorRoles) {
    const SensorCalibration& c = p.input(role);
    const double volts = t7::get_float(&ain_buffer_[static_cast<std::size_t>(2 * c.ain)]);
    volts_[static_cast<int>(role)].store(volts, std::memory_order_relaxed);
    const bool valid = c.valid(volts);
    const double value = c.value(volts);
    switch (role) {
      case SensorRole::kChamberA:
        r.joint[0].chamber_bar[0] = valid ? value : kOutOfRangePressure_bar;
        break;
      case SensorRole::kChamberB:
        r.joint[0].chamber_bar[1] = valid ? value : kOutOfRangePressure_bar;
        break;
      case SensorRole::kSupply:
        r.supply_bar = valid ? value : kOutOfRangePressure_bar;
        break;
      case SensorRole::kAngle:
        r.joint[0].angle_rad = valid ? value - angle_zero_rad() : kOutOfRangeAngle_rad;
        break;
      case SensorRole::kTemperature:
        r.temperature_K = valid ? value : NAN;
        break;  // no guard watches it
    }
  }
  // The device's own clock, strictly increasing: the engine's stale guard watches it.
  r.time_s = std::max(end - origin_s_, std::nextafter(last_time_s_, INFINITY));
  last_time_s_ = r.time_s;
  inbox_.write(r);
}

void T7Device::fail_link(const std::string& why) {
  if (!link_up_.load(std::memory_order_relaxed))
    return;  // reported at the start of the streak (only this thread writes it)
  if (!error_published_.load(std::memory_order_acquire)) {
    link_error_ = why;
    error_published_.store(true, std::memory_order_release);
  }
  link_up_.store(false, std::memory_order_release);  // after the error: whoever sees the link down can read why
  std::fprintf(stderr,
               "bellows: t7 link %s: %s: no fresh readings while it lasts (the engine holds, then faults and vents)\n",
               address_.c_str(), why.c_str());
}

void T7Device::record_round_trip(double ms) {
  round_trips_ms_[round_trip_count_ % kRoundTripWindow] = ms;
  ++round_trip_count_;
  if (ms > max_ms_.load(std::memory_order_relaxed)) max_ms_.store(ms, std::memory_order_relaxed);
  if (round_trip_count_ % kRoundTripRefresh != 0 && round_trip_count_ > kRoundTripRefresh) return;
  const std::size_t n = std::min(round_trip_count_, kRoundTripWindow);
  std::copy_n(round_trips_ms_.begin(), n, scratch_ms_.begin());
  const auto at = [&](double q) {
    const std::size_t k = std::min(n - 1, static_cast<std::size_t>(q * static_cast<double>(n)));
    std::nth_element(scratch_ms_.begin(), scratch_ms_.begin() + static_cast<std::ptrdiff_t>(k),
                     scratch_ms_.begin() + static_cast<std::ptrdiff_t>(n));
    return scratch_ms_[k];
  };
  p50_ms_.store(at(0.50), std::memory_order_relaxed);
  p99_ms_.store(at(0.99), std::memory_order_relaxed);
}

// ---- any thread ----

DeviceHealth T7Device::health() const {
  constexpr auto relaxed = std::memory_order_relaxed;
  DeviceHealth h;
  h.has_link = true;
  h.connected = link_up_.load(std::memory_order_acquire);
  h.round_trip_p50_ms = p50_ms_.load(relaxed);
  h.round_trip_p99_ms = p99_ms_.load(relaxed);
  h.round_trip_max_ms = max_ms_.load(relaxed);
  h.exchanges = exchanges_.load(relaxed);
  h.link_errors = link_errors_.load(relaxed);
  h.stale_readings = stale_readings_.load(relaxed);
  return h;
}

RawInputs T7Device::raw_inputs() const {
  RawInputs raw;
  for (SensorRole role : kSensorRoles) {
    const SensorCalibration& c = options_.profile.input(role);
    RawInput& in = raw.inputs[static_cast<std::size_t>(raw.count++)];
    in.name = to_string(role);
    in.volts = volts_[static_cast<int>(role)].load(std::memory_order_relaxed);
    in.value = c.value(in.volts);
    in.unit = calibrated_unit(role);
    if (role == SensorRole::kAngle) {  // shown in degrees, from the zero
      in.value = (in.value - angle_zero_rad()) * 180.0 / std::numbers::pi;
      in.unit = "deg";
    } else if (role == SensorRole::kTemperature) {
      in.unit = "K";
    }
  }
  return raw;
}

bool T7Device::take_refusal(std::array<char, kRefusalChars>& text) {
  if (!refusal_pending_.load(std::memory_order_acquire)) return false;
  text = refusal_text_;
  refusal_pending_.store(false, std::memory_order_release);
  return true;
}

bool T7Device::take_fault(DeviceFault& fault) {
  std::array<char, kRefusalChars> text{};
  if (!take_refusal(text)) return false;
  fault.set(FaultCode::kDeviceError, -1, "%s", text.data());
  return true;
}

void T7Device::explain_silence(double silent_s, DeviceFault& fault) const {
  // Every turn of the I/O thread ends within the exchange's deadline and a poll: a longer wait since
  // its last turn is this host holding the thread off its core, not the T7.
  const double longest_turn_s = options_.link.response_timeout_s + 2.0 * kOutboxPoll_s;
  if (const double io_idle_s = io_turns_.held_off_s(now_s(), silent_s, longest_turn_s); !std::isnan(io_idle_s)) {
    fault.set(FaultCode::kLinkLost, -1,
              "no reading of the T7 at %s for %.0f ms: this host's T7 I/O thread did not run for %.0f ms (the "
              "machine stalled: lighten its load, --rt enforce)",
              address_.c_str(), silent_s * 1e3, io_idle_s * 1e3);
    return;
  }
  if (link_answers()) {
    Device::explain_silence(silent_s, fault);
    return;
  }
  // Bytes came from it within the window (as LcmDevice judges a rig): it answers, late; a dead T7 sends none.
  if (now_s() - heard_s_.load(std::memory_order_acquire) < 0.5 * silent_s) {
    fault.set(FaultCode::kSensorStale, -1,
              "the T7 at %s answers, but late: no reading within [t7] response_timeout_s = %.1f ms for %.0f ms (%llu "
              "late answers): check the network and the inputs' read time",
              address_.c_str(), options_.link.response_timeout_s * 1e3, silent_s * 1e3,
              static_cast<unsigned long long>(late_answers_.load(std::memory_order_relaxed)));
    return;
  }
  fault.set(FaultCode::kLinkLost, -1, "the T7 at %s has answered nothing for %.0f ms: check its power and cable",
            address_.c_str(), silent_s * 1e3);
}

bool T7Device::wait_for_reading(double timeout_s, const std::atomic<bool>& stop) const {
  // A reading in time or one that came late (late_readings_): either is a reading of the inputs.
  const auto readings = [this] {
    return exchanges_.load(std::memory_order_acquire) + late_readings_.load(std::memory_order_acquire);
  };
  const std::uint64_t before = readings();
  const double deadline = now_s() + timeout_s;
  while (readings() <= before) {
    if (stop.load(std::memory_order_relaxed) || now_s() > deadline) return false;
    sleep_s(0.002);
  }
  return true;
}

std::string T7Device::link_error() const {
  return error_published_.load(std::memory_order_acquire) ? link_error_ : std::string();
}

}  // namespace bellows
