#include "devices/t7_sim_registers.hpp"

#include <modbus/modbus.h>

#include <algorithm>
#include <utility>

#include "devices/t7_registers.hpp"

namespace bellows {
namespace {
constexpr std::uint8_t kUnknown = 0, kReadOnly = 1, kReadWrite = 2;

/// The IO configuration's registers as (first, count): the systems IO_CONFIG_* affect (AIN, DIO,
/// DIO_EF and its clocks; ljm_constants.json) that t7-sim models.
std::vector<std::pair<int, int>> io_config_blocks() {
  using namespace t7;
  std::vector<std::pair<int, int>> blocks = {{kAinRange(0), 2 * kAinCount},
                                             {kAinResolutionIndex(0), kAinCount},
                                             {kAinSettling_us(0), 2 * kAinCount},
                                             {kDioState, 2},
                                             {kDioDirection, 2}};
  for (int first : {kDioEfEnable(0), kDioEfIndex(0), kDioEfClockSource(0), kDioEfConfigA(0)})
    blocks.emplace_back(first, 2 * kDioCount);
  for (int clock = 0; clock < 3; ++clock) blocks.emplace_back(kClockEnable(clock), 6);
  return blocks;
}
}  // namespace

T7SimRegisters::T7SimRegisters(bool high_resolution_adc) : registers_(kSize, 0), access_(kSize, kUnknown) {
  using namespace t7;
  allow(kAin(0), 2 * kAinCount, false);
  allow(kAinRange(0), 2 * kAinCount, true);
  allow(kAinResolutionIndex(0), kAinCount, true);
  allow(kAinSettling_us(0), 2 * kAinCount, true);
  allow(kAinAllResolutionIndex, 1, true);
  allow(kAinAllResolutionIndex + 1, 2, true);  // AIN_ALL_SETTLING_US
  for (int first : {kDioEfEnable(0), kDioEfIndex(0), kDioEfClockSource(0), kDioEfConfigA(0)})
    allow(first, 2 * kDioCount, true);
  for (int clock = 0; clock < 3; ++clock) {
    allow(kClockEnable(clock), 6, true);  // ENABLE, DIVISOR, OPTIONS, ROLL_VALUE
    allow(kClockCount(clock), 2, false);
    registers_[static_cast<std::size_t>(kClockDivisor(clock))] = 1;
  }
  allow(kFio(0), kFioCount, true);
  allow(kDioState, 2, true);
  allow(kDioDirection, 2, true);
  allow(kDioInhibit, 2, true);
  allow(kHardwareInstalled, 2, false);
  allow(kLastErrDetail, 1, false);
  allow(55002, 1, false);  // LAST_ERR_FRAME
  allow(kLastErrTransactionId, 1, false);
  set_u32(kHardwareInstalled, high_resolution_adc ? kHardwareHighResolutionAdc : 0u);
  allow(kProductId, 2, false);
  allow(kFirmwareVersion, 2, false);
  allow(kSerialNumber, 2, false);
  for (int first :
       {kWatchdogEnable, kWatchdogAdvanced, kWatchdogTimeout_s, kWatchdogStartupDelay_s, kWatchdogStrictEnable,
        kWatchdogStrictKey, kWatchdogStrictClear, kWatchdogResetEnable, kWatchdogDioEnable, kWatchdogDioState,
        kWatchdogDioDirection, kWatchdogDioInhibit, 61640, 61642, 61650, 61652}) {
    allow(first, 2, true);
  }
  allow(kStreamEnable, 2, false);  // read-write on a T7; t7-sim starts no stream (its drill sets it)
  allow(kIoConfigCheckForFactory, 2, false);
  allow(kIoConfigSetBootupToCurrent, 2, true);
  allow(kIoConfigSetBootupToFactory, 2, true);
  factory_io_config_ = io_config();
  set_bootup(factory_io_config_);
  put_float(kT7ProductId, &registers_[kProductId]);
  put_float(1.0299, &registers_[kFirmwareVersion]);
  set_u32(kSerialNumber, 470000000u);
}

void T7SimRegisters::wrote(int address, int count) {
  using namespace t7;
  for (int a = address; a < address + count; ++a) {
    if (a >= kFio(0) && a < kFio(kFioCount)) {
      const std::uint32_t bit = 1u << (a - kFio(0));
      set_u32(kDioDirection, u32(kDioDirection) | bit);
      set_u32(kDioState,
              registers_[static_cast<std::size_t>(a)] != 0 ? (u32(kDioState) | bit) : (u32(kDioState) & ~bit));
    }
    // The UINT32 commands act on the write of their second register (a write of both, as LJM makes it).
    if (a == kIoConfigSetBootupToCurrent + 1 && u32(kIoConfigSetBootupToCurrent) == 1) set_bootup(io_config());
    if (a == kIoConfigSetBootupToFactory + 1 && u32(kIoConfigSetBootupToFactory) == 1) set_bootup(factory_io_config_);
    if (a == kAinAllResolutionIndex) {
      for (int n = 0; n < kAinCount; ++n)
        registers_[static_cast<std::size_t>(kAinResolutionIndex(n))] = registers_[static_cast<std::size_t>(a)];
    }
  }
}

std::vector<std::uint16_t> T7SimRegisters::io_config() const {
  std::vector<std::uint16_t> values;
  for (const auto& [first, count] : io_config_blocks()) {
    values.insert(values.end(), registers_.begin() + first, registers_.begin() + first + count);
  }
  return values;
}

void T7SimRegisters::set_io_config(const std::vector<std::uint16_t>& values) {
  auto from = values.begin();
  for (const auto& [first, count] : io_config_blocks()) {
    std::copy(from, from + count, registers_.begin() + first);
    from += count;
  }
}

void T7SimRegisters::set_bootup(const std::vector<std::uint16_t>& values) {
  bootup_io_config_ = values;
  set_u32(t7::kIoConfigCheckForFactory, bootup_io_config_ == factory_io_config_ ? 1u : 0u);
}

void T7SimRegisters::allow(int first, int count, bool writable) {
  for (int a = first; a < first + count; ++a) access_[static_cast<std::size_t>(a)] = writable ? kReadWrite : kReadOnly;
}

int T7SimRegisters::check(int function, int address, int count) const {
  const bool write = function == MODBUS_FC_WRITE_SINGLE_REGISTER || function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS;
  if (!write && function != MODBUS_FC_READ_HOLDING_REGISTERS && function != MODBUS_FC_READ_INPUT_REGISTERS) {
    return MODBUS_EXCEPTION_ILLEGAL_FUNCTION;
  }
  if (count < 1 || address < 0 || address + count > kSize) return t7::kExceptionIllegalDataAddress;
  for (int a = address; a < address + count; ++a) {
    const std::uint8_t access = access_[static_cast<std::size_t>(a)];
    if (access == kUnknown || (write && access != kReadWrite)) return t7::kExceptionIllegalDataAddress;
  }
  return 0;
}

std::uint32_t T7SimRegisters::u32(int address) const {
  return t7::get_u32(&registers_[static_cast<std::size_t>(address)]);
}
void T7SimRegisters::set_u32(int address, std::uint32_t value) {
  t7::put_u32(value, &registers_[static_cast<std::size_t>(address)]);
}

void T7SimRegisters::set_ain(int ain, double volts) {
  t7::put_float(volts, &registers_[static_cast<std::size_t>(t7::kAin(ain))]);
}

double T7SimRegisters::line_duty(int dio) const {
  using namespace t7;
  const bool clock_on = registers_[kClock0Enable] == 1;
  if (u32(kDioEfEnable(dio)) == 1 && u32(kDioEfIndex(dio)) == kEfIndexPwmOut && clock_on) {
    PwmClock clock{registers_[kClock0Divisor], u32(kClock0RollValue)};
    return clock.duty(u32(kDioEfConfigA(dio)));
  }
  const std::uint32_t bit = 1u << dio;
  if ((u32(kDioDirection) & bit) != 0) return (u32(kDioState) & bit) != 0 ? 1.0 : 0.0;
  return 0.0;  // an input: the driver's pull-down holds the valve closed
}

bool T7SimRegisters::watchdog_enabled() const { return u32(t7::kWatchdogEnable) == 1; }
std::uint32_t T7SimRegisters::watchdog_timeout_s() const { return u32(t7::kWatchdogTimeout_s); }

bool T7SimRegisters::run_watchdog(double now_s) {
  using namespace t7;
  if (!watchdog_enabled()) return false;
  const double timeout = static_cast<double>(std::max<std::uint32_t>(1, watchdog_timeout_s()));
  if (now_s - last_answer_s_ < timeout) return false;
  last_answer_s_ = now_s;  // it acts again after another timeout of silence
  // A restart comes up in the power-up defaults, as the second advanced action restores them.
  if (u32(kWatchdogResetEnable) == 1 || u32(kWatchdogAdvanced) == kWatchdogAdvancedIoConfigToBootup) {
    set_io_config(bootup_io_config_);
  } else if (u32(kWatchdogAdvanced) == kWatchdogAdvancedIoConfigToFactory) {
    set_io_config(factory_io_config_);  // no EF, no clock, every line an input
  }
  if (u32(kWatchdogDioEnable) == 1) {
    // Direction and state only: a line an EF still drives keeps its PWM (see the header).
    const std::uint32_t direction =
        u32(kWatchdogDioDirection) & ~u32(kWatchdogDioInhibit);  // inhibited lines are left alone
    set_u32(kDioDirection, u32(kDioDirection) | direction);
    set_u32(kDioState, (u32(kDioState) & ~direction) | (u32(kWatchdogDioState) & direction));
  }
  return true;
}

}  // namespace bellows
