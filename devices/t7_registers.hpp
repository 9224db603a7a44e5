// The subset of the LabJack T7's Modbus map bellows uses (LabJack's public register map,
// labjack/ljm_constants LabJack/LJM/ljm_constants.json; docs/labjack-t7.md). Registers are 16-bit
// and big-endian; FLOAT32 and UINT32 values take two registers, high word first.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace bellows::t7 {

inline constexpr int kAinCount = 14;                  // AIN0..AIN13 on the T7's screw terminals and DB37
inline constexpr int kAin(int n) { return 2 * n; }    // AIN# FLOAT32 volts, read only
inline constexpr int kAinRange(int n) { return 40000 + 2 * n; }  // AIN#_RANGE FLOAT32 (+-V)

inline constexpr int kDioCount = 23;                  // DIO0..DIO22
inline constexpr int kDioEfEnable(int dio) { return 44000 + 2 * dio; }       // UINT32
inline constexpr int kDioEfIndex(int dio) { return 44100 + 2 * dio; }        // UINT32, 0 = PWM out
inline constexpr int kDioEfClockSource(int dio) { return 44200 + 2 * dio; }  // UINT32, 0 = clock 0
inline constexpr int kDioEfConfigA(int dio) { return 44300 + 2 * dio; }      // UINT32, PWM: count where the line goes low
inline constexpr std::uint32_t kEfIndexPwmOut = 0;
/// The T7 lines that can carry PWM out: FIO0 and FIO2..FIO5 (T-Series datasheet 13.2.2).
inline constexpr std::array<int, 5> kPwmCapableDio = {0, 2, 3, 4, 5};
inline constexpr bool pwm_capable(int dio) {
  for (int d : kPwmCapableDio) {
    if (d == dio) return true;
  }
  return false;
}

inline constexpr int kClock0Enable = 44900;    // UINT16
inline constexpr int kClock0Divisor = 44901;   // UINT16: 1, 2, 4, 8, 16, 32, 64 or 256
inline constexpr int kClock0Options = 44902;   // UINT32
inline constexpr int kClock0RollValue = 44904; // UINT32, 0 = 2^32
inline constexpr double kCoreClock_Hz = 80e6;
inline constexpr std::array<int, 8> kClockDivisors = {1, 2, 4, 8, 16, 32, 64, 256};

inline constexpr int kDioState = 2800;         // UINT32 bit mask
inline constexpr int kDioDirection = 2850;     // UINT32 bit mask, 1 = output

inline constexpr int kProductId = 60000;       // FLOAT32, 7 for a T7 / T7-Pro
inline constexpr int kFirmwareVersion = 60004; // FLOAT32
inline constexpr int kSerialNumber = 60028;    // UINT32
inline constexpr double kT7ProductId = 7.0;

inline constexpr int kWatchdogEnable = 61600;        // UINT32; disable before writing the others
inline constexpr int kWatchdogAdvanced = 61602;      // UINT32: 1 IO config to factory, 2 to power-up defaults
inline constexpr int kWatchdogTimeout_s = 61604;     // UINT32 whole seconds
inline constexpr int kWatchdogStartupDelay_s = 61606;
inline constexpr int kWatchdogStrictEnable = 61610;
inline constexpr int kWatchdogStrictKey = 61612;
inline constexpr int kWatchdogStrictClear = 61614;
inline constexpr int kWatchdogResetEnable = 61620;   // UINT32: 1 restarts the device on timeout
inline constexpr int kWatchdogDioEnable = 61630;     // UINT32: 1 sets DIO on timeout
inline constexpr int kWatchdogDioState = 61632;      // UINT32 mask: high/low after timeout
inline constexpr int kWatchdogDioDirection = 61634;  // UINT32 mask: output/input after timeout
inline constexpr int kWatchdogDioInhibit = 61636;
inline constexpr std::uint32_t kWatchdogAdvancedIoConfigToDefault = 2;

/// Modbus exception a T7 answers for an address it does not have (or a write to a read-only one):
/// 2, ILLEGAL DATA ADDRESS (LJM error 1202, LJME_MBE2_ILLEGAL_DATA_ADDRESS).
inline constexpr int kExceptionIllegalDataAddress = 2;

/// The PWM clock for a frequency: the smallest divisor whose roll value fits 32 bits.
struct PwmClock {
  std::uint32_t divisor = 1;
  std::uint32_t roll = 0;
  double frequency_hz() const { return kCoreClock_Hz / (divisor * static_cast<double>(roll)); }
  /// CONFIG_A for a duty cycle in [0, 1] (1: the line never goes low).
  std::uint32_t config_a(double duty) const {
    const double d = std::isfinite(duty) ? std::fmin(std::fmax(duty, 0.0), 1.0) : 0.0;
    return static_cast<std::uint32_t>(std::lround(d * roll));
  }
  double duty(std::uint32_t config_a) const {
    const double r = roll == 0 ? 4294967296.0 : static_cast<double>(roll);
    return std::fmin(static_cast<double>(config_a), r) / r;
  }
};

inline PwmClock pwm_clock_for(double frequency_hz) {
  for (int divisor : kClockDivisors) {
    const double roll = kCoreClock_Hz / (divisor * frequency_hz);
    if (roll <= 4294967295.0) return {static_cast<std::uint32_t>(divisor), static_cast<std::uint32_t>(std::lround(roll))};
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
