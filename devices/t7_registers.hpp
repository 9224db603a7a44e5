// The subset of the LabJack T7's Modbus map bellows uses (LabJack's public register map,
// labjack/ljm_constants LabJack/LJM/ljm_constants.json; docs/labjack-t7.md). Registers are 16-bit
// and big-endian; FLOAT32 and UINT32 values take two registers, high word first.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

namespace bellows::t7 {

inline constexpr int kAinCount = 14;                             // AIN0..AIN13 on the T7's screw terminals and DB37
inline constexpr int kAin(int n) { return 2 * n; }               // AIN# FLOAT32 volts, read only
inline constexpr int kAinRange(int n) { return 40000 + 2 * n; }  // AIN#_RANGE FLOAT32 (+-V)
inline constexpr int kAinResolutionIndex(int n) { return 41500 + n; }  // UINT16: 0 default, 1..8 (12 on a Pro)
inline constexpr int kAinSettling_us(int n) { return 42000 + 2 * n; }  // FLOAT32 us: 0 auto, max 50000
inline constexpr int kAinAllResolutionIndex = 43903;                   // UINT16, every AIN at once

inline constexpr int kDioCount = 23;                                         // DIO0..DIO22
inline constexpr int kDioEfEnable(int dio) { return 44000 + 2 * dio; }       // UINT32
inline constexpr int kDioEfIndex(int dio) { return 44100 + 2 * dio; }        // UINT32, 0 = PWM out
inline constexpr int kDioEfClockSource(int dio) { return 44200 + 2 * dio; }  // UINT32, 0 = clock 0
inline constexpr int kDioEfConfigA(int dio) { return 44300 + 2 * dio; }  // UINT32, PWM: count where the line goes low
inline constexpr std::uint32_t kEfIndexPwmOut = 0;
/// The T7 lines that can carry PWM out: FIO0 and FIO2..FIO5 (T-Series datasheet 13.2.2).
inline constexpr std::array<int, 5> kPwmCapableDio = {0, 2, 3, 4, 5};
inline constexpr bool pwm_capable(int dio) {
  for (int d : kPwmCapableDio) {
    if (d == dio) return true;
  }
  return false;
}

// DIO_EF_CLOCK0/1/2: clock 0 is the 32-bit clock; clocks 1 and 2 are 16-bit and share its counter
// (so clock 0 needs them both disabled: LabJack error 2558).
inline constexpr int kClockEnable(int clock) { return 44900 + 10 * clock; }     // UINT16
inline constexpr int kClockDivisor(int clock) { return 44901 + 10 * clock; }    // UINT16: 1, 2, 4, 8, 16, 32, 64 or 256
inline constexpr int kClockOptions(int clock) { return 44902 + 10 * clock; }    // UINT32
inline constexpr int kClockRollValue(int clock) { return 44904 + 10 * clock; }  // UINT32, 0 = the maximum
inline constexpr int kClockCount(int clock) { return 44908 + 10 * clock; }      // UINT32, read only
inline constexpr int kClock0Enable = kClockEnable(0);
inline constexpr int kClock0Divisor = kClockDivisor(0);
inline constexpr int kClock0Options = kClockOptions(0);
inline constexpr int kClock0RollValue = kClockRollValue(0);
inline constexpr double kCoreClock_Hz = 80e6;
inline constexpr std::array<int, 8> kClockDivisors = {1, 2, 4, 8, 16, 32, 64, 256};

inline constexpr int kFio(int n) {
  return 2000 + n;
}  // FIO#(0:7) UINT16: a write sets the line an output at that level
inline constexpr int kFioCount = 8;
inline constexpr int kDioState = 2800;      // UINT32 bit mask
inline constexpr int kDioDirection = 2850;  // UINT32 bit mask, 1 = output
inline constexpr int kDioInhibit = 2900;    // UINT32 bit mask, 1 = _STATE/_DIRECTION writes ignore the line

inline constexpr int kProductId = 60000;        // FLOAT32, 7 for a T7 / T7-Pro
inline constexpr int kFirmwareVersion = 60004;  // FLOAT32
inline constexpr int kHardwareInstalled =
    60010;  // UINT32 bits: 0 high-resolution ADC (a T7-Pro), 1 WiFi, 2 RTC, 3 microSD
inline constexpr std::uint32_t kHardwareHighResolutionAdc = 1u;
inline constexpr int kSerialNumber = 60028;          // UINT32
inline constexpr int kStreamEnable = 4990;           // UINT32: "returns 1 when stream is enabled"
inline constexpr int kLastErrDetail = 55000;         // UINT16: the last LabJack error number the device met
inline constexpr int kLastErrTransactionId = 55003;  // UINT16: the Modbus TCP transaction that caused it
inline constexpr double kT7ProductId = 7.0;

inline constexpr int kWatchdogEnable = 61600;     // UINT32; disable before writing the others
inline constexpr int kWatchdogAdvanced = 61602;   // UINT32: 1 IO config to factory, 2 to power-up defaults
inline constexpr int kWatchdogTimeout_s = 61604;  // UINT32 whole seconds
inline constexpr int kWatchdogStartupDelay_s = 61606;
inline constexpr int kWatchdogStrictEnable = 61610;
inline constexpr int kWatchdogStrictKey = 61612;
inline constexpr int kWatchdogStrictClear = 61614;
inline constexpr int kWatchdogResetEnable = 61620;   // UINT32: 1 restarts the device on timeout
inline constexpr int kWatchdogDioEnable = 61630;     // UINT32: 1 sets DIO on timeout
inline constexpr int kWatchdogDioState = 61632;      // UINT32 mask: high/low after timeout
inline constexpr int kWatchdogDioDirection = 61634;  // UINT32 mask: output/input after timeout
inline constexpr int kWatchdogDioInhibit = 61636;    // UINT32 mask: 1 = the watchdog leaves that line alone
// WATCHDOG_ADVANCED_DEFAULT's actions (ljm_constants.json): 1 IO_CONFIG_SET_CURRENT_TO_FACTORY, 2 the
// power-up defaults saved in flash (IO_CONFIG_SET_CURRENT_TO_BOOTUP), which a lab may have saved with PWM running.
inline constexpr std::uint32_t kWatchdogAdvancedIoConfigToFactory = 1;
inline constexpr std::uint32_t kWatchdogAdvancedIoConfigToBootup = 2;
inline constexpr int kIoConfigCheckForFactory = 49000;  // UINT32 R: 1 if the power-up defaults are the factory's
inline constexpr int kIoConfigSetBootupToCurrent =
    49002;  // UINT32 W: 1 saves the current IO config as power-up defaults
inline constexpr int kIoConfigSetBootupToFactory = 49004;  // UINT32 W: 1 saves the factory's as power-up defaults

/// Modbus exception a T7 answers for an address it does not have (or a write to a read-only one):
/// 2, ILLEGAL DATA ADDRESS (LJM error 1202, LJME_MBE2_ILLEGAL_DATA_ADDRESS).
inline constexpr int kExceptionIllegalDataAddress = 2;
/// ...for a value a register cannot take (LJM 1203, LJME_MBE3_ILLEGAL_DATA_VALUE).
inline constexpr int kExceptionIllegalDataValue = 3;
/// ...for a write the device refuses with one of its own errors (2554, 2558, 2563, 2565, 2566...):
/// 4, SLAVE DEVICE FAILURE (LJM 1204 "The device encountered an error"), the error itself in
/// LAST_ERR_DETAIL. Not stated in the pages we could read: see docs/labjack-t7.md.
inline constexpr int kExceptionDeviceFailure = 4;

/// LabJack's name of a register bellows or t7-sim uses ("DIO2_EF_CONFIG_A"; "register N" otherwise),
/// for messages.
inline std::string register_name(int a) {
  const auto indexed = [](const char* prefix, int n, const char* suffix) {
    return prefix + std::to_string(n) + suffix;
  };
  if (a >= kAin(0) && a < kAin(kAinCount)) return indexed("AIN", a / 2, "");
  if (a >= kFio(0) && a < kFio(kFioCount)) return indexed("FIO", a - kFio(0), "");
  if (a >= kAinRange(0) && a < kAinRange(kAinCount)) return indexed("AIN", (a - kAinRange(0)) / 2, "_RANGE");
  if (a >= kAinResolutionIndex(0) && a < kAinResolutionIndex(kAinCount))
    return indexed("AIN", a - kAinResolutionIndex(0), "_RESOLUTION_INDEX");
  if (a >= kAinSettling_us(0) && a < kAinSettling_us(kAinCount))
    return indexed("AIN", (a - kAinSettling_us(0)) / 2, "_SETTLING_US");
  const std::pair<int, const char*> ef[] = {{kDioEfEnable(0), "_EF_ENABLE"},
                                            {kDioEfIndex(0), "_EF_INDEX"},
                                            {kDioEfClockSource(0), "_EF_CLOCK_SOURCE"},
                                            {kDioEfConfigA(0), "_EF_CONFIG_A"}};
  for (const auto& [first, suffix] : ef) {
    if (a >= first && a < first + 2 * kDioCount) return indexed("DIO", (a - first) / 2, suffix);
  }
  if (a >= kClockEnable(0) && a < kClockEnable(3)) {
    const int clock = (a - kClockEnable(0)) / 10;
    const char* what[] = {"_ENABLE",     "_DIVISOR", "_OPTIONS", "_OPTIONS", "_ROLL_VALUE",
                          "_ROLL_VALUE", "",         "",         "_COUNT",   "_COUNT"};
    return indexed("DIO_EF_CLOCK", clock, what[(a - kClockEnable(0)) % 10]);
  }
  const std::pair<int, const char*> named[] = {{kAinAllResolutionIndex, "AIN_ALL_RESOLUTION_INDEX"},
                                               {kDioState, "DIO_STATE"},
                                               {kDioDirection, "DIO_DIRECTION"},
                                               {kDioInhibit, "DIO_INHIBIT"},
                                               {kProductId, "PRODUCT_ID"},
                                               {kFirmwareVersion, "FIRMWARE_VERSION"},
                                               {kHardwareInstalled, "HARDWARE_INSTALLED"},
                                               {kSerialNumber, "SERIAL_NUMBER"},
                                               {kLastErrDetail, "LAST_ERR_DETAIL"},
                                               {kLastErrTransactionId, "LAST_ERR_TRANSACTION_ID"},
                                               {kWatchdogEnable, "WATCHDOG_ENABLE_DEFAULT"},
                                               {kWatchdogAdvanced, "WATCHDOG_ADVANCED_DEFAULT"},
                                               {kWatchdogTimeout_s, "WATCHDOG_TIMEOUT_S_DEFAULT"},
                                               {kWatchdogStartupDelay_s, "WATCHDOG_STARTUP_DELAY_S_DEFAULT"},
                                               {kWatchdogStrictEnable, "WATCHDOG_STRICT_ENABLE_DEFAULT"},
                                               {kWatchdogStrictKey, "WATCHDOG_STRICT_KEY_DEFAULT"},
                                               {kWatchdogStrictClear, "WATCHDOG_STRICT_CLEAR"},
                                               {kWatchdogResetEnable, "WATCHDOG_RESET_ENABLE_DEFAULT"},
                                               {kWatchdogDioEnable, "WATCHDOG_DIO_ENABLE_DEFAULT"},
                                               {kWatchdogDioState, "WATCHDOG_DIO_STATE_DEFAULT"},
                                               {kWatchdogDioDirection, "WATCHDOG_DIO_DIRECTION_DEFAULT"},
                                               {kWatchdogDioInhibit, "WATCHDOG_DIO_INHIBIT_DEFAULT"},
                                               {kStreamEnable, "STREAM_ENABLE"},
                                               {kIoConfigCheckForFactory, "IO_CONFIG_CHECK_FOR_FACTORY"},
                                               {kIoConfigSetBootupToCurrent, "IO_CONFIG_SET_BOOTUP_TO_CURRENT"},
                                               {kIoConfigSetBootupToFactory, "IO_CONFIG_SET_BOOTUP_TO_FACTORY"}};
  for (const auto& [address, name] : named) {
    if (a == address || a == address + 1) return name;
  }
  return "register " + std::to_string(a);
}

/// The PWM clock for a frequency: the smallest divisor whose roll value fits 32 bits.
struct PwmClock {
  std::uint32_t divisor = 1;
  std::uint32_t roll = 0;
  double frequency_hz() const { return kCoreClock_Hz / (divisor * static_cast<double>(roll)); }
  /// The largest CONFIG_A a T7 accepts: one below the roll value (LabJack error 2565,
  /// EF_VALUE_GREATER_THAN_PERIOD: "the value must be less than the selected ClockSource's roll value").
  std::uint32_t max_config_a() const { return roll == 0 ? 4294967295u : roll - 1; }
  /// CONFIG_A for a duty cycle in [0, 1]. 1 (fully open) is roll - 1: the line is low for one count
  /// of the clock per period (12.5 ns at divisor 1), which no valve can follow.
  std::uint32_t config_a(double duty) const {
    const double d = std::isfinite(duty) ? std::fmin(std::fmax(duty, 0.0), 1.0) : 0.0;
    const double r = roll == 0 ? 4294967296.0 : static_cast<double>(roll);
    return std::min(static_cast<std::uint32_t>(std::llround(d * r)), max_config_a());
  }
  /// The duty cycle a line outputs at CONFIG_A; roll - 1 and above is fully open (as config_a()).
  double duty(std::uint32_t config_a) const {
    const double r = roll == 0 ? 4294967296.0 : static_cast<double>(roll);
    if (config_a >= max_config_a()) return 1.0;
    return static_cast<double>(config_a) / r;
  }
};

inline PwmClock pwm_clock_for(double frequency_hz) {
  for (int divisor : kClockDivisors) {
    const double roll = kCoreClock_Hz / (divisor * frequency_hz);
    if (roll <= 4294967295.0)
      return {static_cast<std::uint32_t>(divisor), static_cast<std::uint32_t>(std::lround(roll))};
  }
  return {256, 4294967295u};
}

inline void put_u32(std::uint32_t value, std::uint16_t* registers) {
  registers[0] = static_cast<std::uint16_t>(value >> 16);
  registers[1] = static_cast<std::uint16_t>(value & 0xffff);
}
inline std::uint32_t get_u32(const std::uint16_t* registers) {
  return (static_cast<std::uint32_t>(registers[0]) << 16) | registers[1];
}
// FLOAT32 as the T7 sends it: IEEE 754 bits, high word first, each word big-endian on the wire
// (libmodbus 3.1.6's modbus_set_float_abcd byte-swaps with htonl and does not match its own
// modbus_get_float_abcd, so bellows does not use them).
inline void put_float(double value, std::uint16_t* registers) {
  const float f = static_cast<float>(value);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  put_u32(bits, registers);
}
inline double get_float(const std::uint16_t* registers) {
  const std::uint32_t bits = get_u32(registers);
  float f = 0.0f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

}  // namespace bellows::t7
