// The T7's configuration, in the constructor before the I/O thread starts: inputs, clock 0, the valve
// lines' PWM and the watchdog, each in the order LabJack's documents require (docs/labjack-t7.md).
#include "devices/t7_device.hpp"

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

#include "devices/t7_errors.hpp"
#include "engine/base/cancellation.hpp"
#include "engine/base/errors.hpp"

namespace bellows {

// "writing DIO2_EF_CONFIG_A (44304) refused: Modbus exception 4 (SLAVE DEVICE FAILURE), LabJack
// error 2565 EF_VALUE_GREATER_THAN_PERIOD": a T7 keeps its own error number in LAST_ERR_DETAIL.
std::string T7Device::refusal(const char* what, int address) {
  std::string why = std::string(what) + " (" + t7::register_name(address) + ", " + std::to_string(address) +
                    ") refused: " + client_.last_error();
  if (client_.last_exception() != 0) {
    std::uint16_t detail = 0;
    if (client_.read_u16(t7::kLastErrDetail, detail) && detail != 0) {
      why += ", LabJack error " + std::to_string(detail);
      if (*t7::error_name(detail) != '\0')
        why += std::string(" ") + t7::error_name(detail) + ": " + t7::error_description(detail);
    }
  }
  return why;
}

void T7Device::require(bool ok, const char* what, int address) {
  if (ok) return;
  if (client_.interrupted()) throw Cancelled("t7 " + address_ + ": configuring interrupted");
  if (client_.timed_out()) {
    throw EnvironmentError("t7 " + address_ + ": no answer within [t7] connect_timeout_s = " +
                           seconds_text(options_.link.connect_timeout_s) + " while configuring (" + what + " " +
                           t7::register_name(address) + ")");
  }
  throw EnvironmentError("t7 " + address_ + ": " + refusal(what, address));
}

void T7Device::configure() {
  double product = 0.0;
  require(client_.read_float(t7::kProductId, product), "reading", t7::kProductId);
  if (product != t7::kT7ProductId) {
    char why[160];
    std::snprintf(why, sizeof why, "t7 %s: answers Modbus but is not a T7 (PRODUCT_ID %g)", address_.c_str(), product);
    throw EnvironmentError(why);
  }
  std::uint32_t hardware = 0;
  require(client_.read_u32(t7::kHardwareInstalled, hardware), "reading", t7::kHardwareInstalled);
  product_ = (hardware & t7::kHardwareHighResolutionAdc) != 0 ? t7::Product::kT7Pro : t7::Product::kT7;
  // A stream started by another program on the T7's other connection (LJM, Kipling, LJStreamM): the
  // analog inputs are not read command-response meanwhile (docs/labjack-t7.md), so every exchange
  // would be refused. Said once, before anything is written.
  std::uint32_t streaming = 0;
  require(client_.read_u32(t7::kStreamEnable, streaming), "reading", t7::kStreamEnable);
  if (streaming != 0) {
    throw EnvironmentError("t7 " + address_ +
                           ": another program streams from this T7 (STREAM_ENABLE = 1: LJM, Kipling or LJStreamM on "
                           "its other connection); bellows reads the inputs command-response: stop that stream first");
  }
  for (SensorRole role : kSensorRoles) {
    const SensorCalibration& c = options_.profile.input(role);
    if (c.resolution_index > t7::max_resolution_index(product_)) {
      throw EnvironmentError("t7 " + address_ + ": rig profile " + options_.profile.source + ": [inputs." +
                             to_string(role) + "] resolution_index = " + std::to_string(c.resolution_index) +
                             " needs a T7-Pro; this is a " + t7::to_string(product_) + " (indices 1..8)");
    }
  }
  try {
    t7::require_exchange_fits(options_.profile, product_, options_.tick_s, options_.link.response_timeout_s);
  } catch (const InputError& error) {
    throw EnvironmentError("t7 " + address_ + ": " + error.what());
  }
  configure_watchdog();
  configure_inputs();
  configure_clock();
  configure_lines();
}

void T7Device::configure_inputs() {
  const int highest = ain_registers_ / 2 - 1;
  for (int ain = 0; ain <= highest; ++ain) {  // an input in the read block no sensor uses: the fastest index
    require(client_.write_u16(t7::kAinResolutionIndex(ain), 1), "setting", t7::kAinResolutionIndex(ain));
  }
  for (SensorRole role : kSensorRoles) {
    const SensorCalibration& c = options_.profile.input(role);
    require(client_.write_float(t7::kAinRange(c.ain), c.range_V), "setting", t7::kAinRange(c.ain));
    require(client_.write_u16(t7::kAinResolutionIndex(c.ain), static_cast<std::uint16_t>(c.resolution_index)),
            "setting", t7::kAinResolutionIndex(c.ain));
    require(client_.write_float(t7::kAinSettling_us(c.ain), c.settling_us), "setting", t7::kAinSettling_us(c.ain));
  }
}

// Clock 0 is the 32-bit clock: clocks 1 and 2 must be off before it starts (LabJack error 2558),
// and it must be off while configured; disabling a clock that is not running is itself refused
// (2554), so each is read first. Another program may have left any of them running.
void T7Device::configure_clock() {
  for (int clock : {1, 2, 0}) {
    std::uint16_t enabled = 0;
    require(client_.read_u16(t7::kClockEnable(clock), enabled), "reading", t7::kClockEnable(clock));
    if (enabled != 0) require(client_.write_u16(t7::kClockEnable(clock), 0), "disabling", t7::kClockEnable(clock));
  }
  require(client_.write_u16(t7::kClock0Divisor, static_cast<std::uint16_t>(clock_.divisor)), "setting",
          t7::kClock0Divisor);
  require(client_.write_u32(t7::kClock0RollValue, clock_.roll), "setting", t7::kClock0RollValue);
  require(client_.write_u16(t7::kClock0Enable, 1), "enabling", t7::kClock0Enable);
}

// Each valve line: its EF off while configured (and before its index changes: 2566), PWM out on
// clock 0 at the vented duty (CONFIG_A below the roll value: 2565), the line an output driven low
// (2563), then PWM on.
void T7Device::configure_lines() {
  // Every tick writes the CONFIG_A of each line from the lowest valve line to the highest in one
  // request: a line between them that is no valve's (DIO1 between DIO0 and DIO2) gets 0. Harmless
  // while its extended feature is off; one that runs (another program's counter, say) is refused here.
  for (int dio = first_dio_; dio < first_dio_ + dio_span_; ++dio) {
    bool valve = false;
    for (ValveRole role : kValveRoles) valve = valve || options_.profile.dio(role) == dio;
    if (valve) continue;
    std::uint32_t enabled = 0;
    require(client_.read_u32(t7::kDioEfEnable(dio), enabled), "reading", t7::kDioEfEnable(dio));
    if (enabled != 0) {
      throw EnvironmentError("t7 " + address_ + ": DIO" + std::to_string(dio) + " runs an extended feature (DIO" +
                             std::to_string(dio) +
                             "_EF_ENABLE = 1) between the valve lines, whose CONFIG_A every tick writes: stop it, "
                             "or give the valves lines without it between them ([valves] in the rig profile)");
    }
  }
  const ValveCommand vented = ValveCommand::vented();
  for (ValveRole role : kValveRoles) {
    const int dio = options_.profile.dio(role);
    std::uint32_t enabled = 0;
    require(client_.read_u32(t7::kDioEfEnable(dio), enabled), "reading", t7::kDioEfEnable(dio));
    if (enabled != 0) require(client_.write_u32(t7::kDioEfEnable(dio), 0), "disabling", t7::kDioEfEnable(dio));
    require(client_.write_u32(t7::kDioEfIndex(dio), t7::kEfIndexPwmOut), "setting", t7::kDioEfIndex(dio));
    require(client_.write_u32(t7::kDioEfClockSource(dio), 0), "setting", t7::kDioEfClockSource(dio));
    require(client_.write_u32(t7::kDioEfConfigA(dio), clock_.config_a(duty_of(vented, role))), "setting",
            t7::kDioEfConfigA(dio));
    require(client_.write_u16(t7::kFio(dio), 0), "driving low", t7::kFio(dio));
    require(client_.write_u32(t7::kDioEfEnable(dio), 1), "enabling", t7::kDioEfEnable(dio));
  }
}

void T7Device::configure_watchdog() {
  // On timeout: reset the IO configuration to the factory's (ends PWM on every line; the power-up
  // defaults would not if a lab saved them with PWM running), and drive the valve lines as outputs,
  // inlets low and outlets high: vented (docs/labjack-t7.md).
  // The watchdog's DIO inhibit leaves every other line alone and none of the valve lines.
  std::uint32_t direction = 0, state = 0;
  for (ValveRole role : kValveRoles) {
    direction |= 1u << options_.profile.dio(role);
    if (role == ValveRole::kOutletA || role == ValveRole::kOutletB) state |= 1u << options_.profile.dio(role);
  }
  const std::uint32_t all_lines = (1u << t7::kDioCount) - 1;
  const std::pair<int, std::uint32_t> wanted[] = {
      {t7::kWatchdogAdvanced, t7::kWatchdogAdvancedIoConfigToFactory},
      {t7::kWatchdogTimeout_s, static_cast<std::uint32_t>(options_.link.watchdog_timeout_s)},
      {t7::kWatchdogStrictEnable, 0},
      {t7::kWatchdogResetEnable, 0},
      {t7::kWatchdogDioEnable, 1},
      {t7::kWatchdogDioState, state},
      {t7::kWatchdogDioDirection, direction},
      {t7::kWatchdogDioInhibit, all_lines & ~direction},
  };
  // The _DEFAULT registers live in flash: rewrite them only when they differ.
  std::uint32_t enabled = 0;
  require(client_.read_u32(t7::kWatchdogEnable, enabled), "reading", t7::kWatchdogEnable);
  bool same = enabled == 1;
  for (const auto& [address, value] : wanted) {
    std::uint32_t current = 0;
    require(client_.read_u32(address, current), "reading", address);
    same = same && current == value;
  }
  if (same) return;
  // The watchdog must be disabled before its other registers are written (WATCHDOG_ENABLE_DEFAULT).
  if (enabled != 0) require(client_.write_u32(t7::kWatchdogEnable, 0), "disabling", t7::kWatchdogEnable);
  for (const auto& [address, value] : wanted) require(client_.write_u32(address, value), "setting", address);
  require(client_.write_u32(t7::kWatchdogEnable, 1), "enabling", t7::kWatchdogEnable);
}

}  // namespace bellows
