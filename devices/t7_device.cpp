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

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

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

double duty_of(const ValveCommand& command, ValveRole role) {
  const JointValves& c = command.joint[0];
  switch (role) {
    case ValveRole::kInletA: return c.inlet_duty[0];
    case ValveRole::kInletB: return c.inlet_duty[1];
    case ValveRole::kOutletA: return c.outlet_duty[0];
    case ValveRole::kOutletB: return c.outlet_duty[1];
  }
  return 0.0;
}

}  // namespace

T7Device::T7Device(T7DeviceOptions options)
    : options_(std::move(options)),
      angle_zero_rad_(options_.profile.angle_zero_rad),
      address_(options_.host + ":" + std::to_string(options_.port)),
      client_(options_.host, options_.port),
      clock_(t7::pwm_clock_for(options_.profile.pwm_frequency_hz)) {
  validate_rig_profile(options_.profile);
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

  if (const std::string why = client_.connect(options_.link.connect_timeout_s); !why.empty()) {
    throw EnvironmentError("t7 " + address_ + ": cannot connect (" + why + ")");
  }
  configure();
  client_.set_response_timeout(options_.link.response_timeout_s);
  origin_s_ = now_s();
  thread_ = std::thread([this] { serve(); });
}

T7Device::~T7Device() { stop(); }

void T7Device::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

// ---- configuration (constructor, before the I/O thread) ----

void T7Device::require(bool ok, const char* what) {
  if (!ok) throw EnvironmentError("t7 " + address_ + ": " + what + " refused (" + client_.last_error() + ")");
}

void T7Device::configure() {
  double product = 0.0;
  require(client_.read_float(t7::kProductId, product), "reading PRODUCT_ID");
  if (product != t7::kT7ProductId) {
    char why[160];
    std::snprintf(why, sizeof why, "t7 %s: answers Modbus but is not a T7 (PRODUCT_ID %g)", address_.c_str(), product);
    throw EnvironmentError(why);
  }
  configure_watchdog();
  for (SensorRole role : kSensorRoles) {
    const SensorCalibration& c = options_.profile.input(role);
    require(client_.write_float(t7::kAinRange(c.ain), c.range_V), "setting AIN#_RANGE");
  }
  // The clock must be disabled while it is configured.
  require(client_.write_u16(t7::kClock0Enable, 0), "disabling DIO_EF_CLOCK0");
  require(client_.write_u16(t7::kClock0Divisor, static_cast<std::uint16_t>(clock_.divisor)), "setting DIO_EF_CLOCK0_DIVISOR");
  require(client_.write_u32(t7::kClock0RollValue, clock_.roll), "setting DIO_EF_CLOCK0_ROLL_VALUE");
  require(client_.write_u16(t7::kClock0Enable, 1), "enabling DIO_EF_CLOCK0");
  const ValveCommand vented = ValveCommand::vented();
  for (ValveRole role : kValveRoles) {
    const int dio = options_.profile.dio(role);
    require(client_.write_u32(t7::kDioEfEnable(dio), 0), "disabling DIO#_EF_ENABLE");
    require(client_.write_u32(t7::kDioEfIndex(dio), t7::kEfIndexPwmOut), "setting DIO#_EF_INDEX");
    require(client_.write_u32(t7::kDioEfClockSource(dio), 0), "setting DIO#_EF_CLOCK_SOURCE");
    require(client_.write_u32(t7::kDioEfConfigA(dio), clock_.config_a(duty_of(vented, role))), "setting DIO#_EF_CONFIG_A");
    require(client_.write_u32(t7::kDioEfEnable(dio), 1), "enabling DIO#_EF_ENABLE");
  }
}

void T7Device::configure_watchdog() {
  // On timeout: reset the IO configuration to its power-up defaults (ends PWM on every line), and
  // drive the valve lines as outputs, inlets low and outlets high: vented (docs/labjack-t7.md).
  std::uint32_t direction = 0, state = 0;
  for (ValveRole role : kValveRoles) {
    direction |= 1u << options_.profile.dio(role);
    if (role == ValveRole::kOutletA || role == ValveRole::kOutletB) state |= 1u << options_.profile.dio(role);
  }
  const std::pair<int, std::uint32_t> wanted[] = {
      {t7::kWatchdogAdvanced, t7::kWatchdogAdvancedIoConfigToDefault},
      {t7::kWatchdogTimeout_s, static_cast<std::uint32_t>(options_.link.watchdog_timeout_s)},
      {t7::kWatchdogStrictEnable, 0},
      {t7::kWatchdogResetEnable, 0},
      {t7::kWatchdogDioEnable, 1},
      {t7::kWatchdogDioState, state},
      {t7::kWatchdogDioDirection, direction},
  };
  // The _DEFAULT registers live in flash: rewrite them only when they differ.
  std::uint32_t enabled = 0;
  bool same = client_.read_u32(t7::kWatchdogEnable, enabled) && enabled == 1;
  for (const auto& [address, value] : wanted) {
    std::uint32_t current = 0;
    same = same && client_.read_u32(address, current) && current == value;
  }
  if (same) return;
  require(client_.write_u32(t7::kWatchdogEnable, 0), "disabling WATCHDOG_ENABLE_DEFAULT");
  for (const auto& [address, value] : wanted) require(client_.write_u32(address, value), "configuring the watchdog");
  require(client_.write_u32(t7::kWatchdogEnable, 1), "enabling WATCHDOG_ENABLE_DEFAULT");
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
  ValveCommand current = ValveCommand::vented();
  double last_command_s = now_s();
  double next_idle_s = 0.0;
  while (!stop_.load(std::memory_order_acquire)) {
    Outgoing out;
    const double now = now_s();
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
    } else {
      sleep_s(kOutboxPoll_s);
    }
  }
  exchange(ValveCommand::vented());  // the last word: vented, whatever the engine last asked for
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
  const bool ok = client_.write(t7::kDioEfConfigA(first_dio_), 2 * dio_span_, duty_registers_.data()) &&
                  client_.read(t7::kAin(0), ain_registers_, ain_buffer_.data());
  const double end = now_s();
  if (!ok) {
    bump(link_errors_);
    fail_link();
    client_.reconnect();  // a clean stream: the next request reads its own answer (or fails at once)
    return false;
  }
  record_round_trip((end - start) * 1e3);
  bump(exchanges_);
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
      case SensorRole::kChamberA: r.joint[0].chamber_bar[0] = valid ? value : kOutOfRangePressure_bar; break;
      case SensorRole::kChamberB: r.joint[0].chamber_bar[1] = valid ? value : kOutOfRangePressure_bar; break;
      case SensorRole::kSupply: r.supply_bar = valid ? value : kOutOfRangePressure_bar; break;
      case SensorRole::kAngle: r.joint[0].angle_rad = valid ? value - angle_zero_rad() : kOutOfRangeAngle_rad; break;
      case SensorRole::kTemperature: r.temperature_K = valid ? value : NAN; break;  // no guard watches it
    }
  }
  // The device's own clock, strictly increasing: the engine's stale guard watches it.
  r.time_s = std::max(end - origin_s_, std::nextafter(last_time_s_, INFINITY));
  last_time_s_ = r.time_s;
  inbox_.write(r);
  return true;
}

void T7Device::fail_link() {
  if (!link_up_.load(std::memory_order_relaxed)) return;  // reported at the start of the streak (only this thread writes it)
  if (!error_published_.load(std::memory_order_acquire)) {
    link_error_ = client_.last_error();
    error_published_.store(true, std::memory_order_release);
  }
  link_up_.store(false, std::memory_order_release);  // after the error: whoever sees the link down can read why
  std::fprintf(stderr, "bellows: t7 link %s: %s: no fresh readings while it lasts (the engine faults sensor-stale and vents)\n",
               address_.c_str(), client_.last_error().c_str());
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

std::string T7Device::link_error() const {
  return error_published_.load(std::memory_order_acquire) ? link_error_ : std::string();
}

}  // namespace bellows
