#include "devices/t7_sim_rules.hpp"

#include <algorithm>
#include <cstdio>

#include <modbus/modbus.h>

#include "devices/t7_errors.hpp"
#include "devices/t7_registers.hpp"

namespace bellows {
namespace {

using namespace t7;

// The registers as they would be after the write: the request's values over the current ones.
class Proposed {
 public:
  Proposed(const T7SimRegisters& registers, int address, int count, const std::uint16_t* values)
      : registers_(registers), address_(address), count_(count), values_(values) {}
  bool written(int a) const { return values_ != nullptr && a >= address_ && a < address_ + count_; }
  std::uint16_t u16(int a) const { return written(a) ? values_[a - address_] : registers_.u16(a); }
  std::uint32_t u32(int a) const { return (static_cast<std::uint32_t>(u16(a)) << 16) | u16(a + 1); }
  double f32(int a) const {
    std::uint16_t r[2] = {u16(a), u16(a + 1)};
    return get_float(r);
  }

 private:
  const T7SimRegisters& registers_;
  int address_, count_;
  const std::uint16_t* values_;
};

T7Refusal refuse(int exception, int error, int address, const char* format, double a = 0.0, double b = 0.0) {
  char why[160];
  std::snprintf(why, sizeof why, format, a, b);
  return {exception, error, address, why};
}

bool in_block(int a, int first, int registers_each, int count, int& index) {
  if (a < first || a >= first + registers_each * count || (a - first) % registers_each != 0) return false;
  index = (a - first) / registers_each;
  return true;
}

double roll_of_clock0(const Proposed& p) {
  const std::uint32_t roll = p.u32(kClock0RollValue);
  return roll == 0 ? 4294967296.0 : static_cast<double>(roll);
}

// The rules of one written register `a` (the first of a UINT32 or FLOAT32).
T7Refusal check_written(const T7SimRegisters& now, const Proposed& p, Product product, int a) {
  int n = 0;
  for (int clock = 0; clock < 3; ++clock) {
    if (a == kClockEnable(clock)) {
      const std::uint16_t value = p.u16(a), current = now.u16(a);
      if (value == 0 && current == 0)
        return refuse(kExceptionDeviceFailure, kErrorClockNotEnabled, a, "disabling a clock that is not running");
      if (clock == 0 && value != 0 && (p.u16(kClockEnable(1)) != 0 || p.u16(kClockEnable(2)) != 0)) {
        return refuse(kExceptionDeviceFailure, kErrorClock0NeedsClocks12Off, a,
                      "enabling clock 0 while clock 1 or 2 runs");
      }
    }
    if (a == kClockDivisor(clock)) {
      const int d = p.u16(a);
      if (std::find(kClockDivisors.begin(), kClockDivisors.end(), d) == kClockDivisors.end()) {
        return refuse(kExceptionDeviceFailure, kErrorDivisorInvalid, a, "divisor %g", d);
      }
    }
  }
  if (in_block(a, kDioEfIndex(0), 2, kDioCount, n) && now.u32(kDioEfEnable(n)) != 0 && p.u32(a) != now.u32(a)) {
    return refuse(kExceptionDeviceFailure, kErrorIndexChangeWhileEnabled, a, "index %g while the EF is enabled",
                  p.u32(a));
  }
  const auto pwm_on_clock0 = [&](int dio) {
    return p.u32(kDioEfIndex(dio)) == kEfIndexPwmOut && p.u32(kDioEfClockSource(dio)) == 0;
  };
  if (in_block(a, kDioEfConfigA(0), 2, kDioCount, n) && pwm_on_clock0(n) && p.u32(a) >= roll_of_clock0(p)) {
    return refuse(kExceptionDeviceFailure, kErrorValueGreaterThanPeriod, a,
                  "CONFIG_A %.0f, not below the roll value %.0f", p.u32(a), roll_of_clock0(p));
  }
  if (in_block(a, kDioEfEnable(0), 2, kDioCount, n) && p.u32(a) != 0 && now.u32(a) == 0 && pwm_on_clock0(n)) {
    const std::uint32_t bit = 1u << n;
    if ((now.u32(kDioDirection) & bit) == 0 || (now.u32(kDioState) & bit) != 0) {
      return refuse(kExceptionDeviceFailure, kErrorLineMustBeLow, a, "PWM on a line that is not an output driven low");
    }
    if (p.u32(kDioEfConfigA(n)) >= roll_of_clock0(p)) {
      return refuse(kExceptionDeviceFailure, kErrorValueGreaterThanPeriod, a,
                    "CONFIG_A %.0f, not below the roll value %.0f", p.u32(kDioEfConfigA(n)), roll_of_clock0(p));
    }
  }
  if ((in_block(a, kAinResolutionIndex(0), 1, kAinCount, n) || a == kAinAllResolutionIndex) &&
      p.u16(a) > max_resolution_index(product)) {
    return refuse(kExceptionIllegalDataValue, kErrorAinResolutionInvalid, a,
                  "resolution index %g (this product: 0..%g)", p.u16(a), max_resolution_index(product));
  }
  if (in_block(a, kAinSettling_us(0), 2, kAinCount, n) && !(p.f32(a) >= 0.0 && p.f32(a) <= kMaxSettling_us)) {
    return refuse(kExceptionIllegalDataValue, kErrorAinSettlingInvalid, a, "settling %g us (0..50000)", p.f32(a));
  }
  return {};
}

}  // namespace

T7Refusal check_t7_request(const T7SimRegisters& registers, Product product, int function, int address, int count,
                           const std::uint16_t* values) {
  const int exception = registers.check(function, address, count);
  if (exception != 0) {
    const bool write = function == MODBUS_FC_WRITE_SINGLE_REGISTER || function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS;
    return refuse(
        exception, exception == kExceptionIllegalDataAddress ? kErrorIllegalDataAddress : 1201, address,
        write ? "a write to an address that does not exist or is read only" : "an address that does not exist");
  }
  // While a stream runs the analog inputs are not read command-response (the error number a T7 answers
  // is not documented: STREAM_IS_ACTIVE, "can not be performed while stream is running").
  if (values == nullptr && registers.u32(kStreamEnable) != 0 && address < kAin(kAinCount)) {
    return refuse(kExceptionDeviceFailure, kErrorStreamIsActive, address,
                  "a read of analog inputs while a stream runs");
  }
  if (values == nullptr) return {};
  const Proposed proposed(registers, address, count, values);
  for (int a = address; a < address + count; ++a) {
    T7Refusal r = check_written(registers, proposed, product, a);
    if (r.exception != 0) return r;
  }
  return {};
}

}  // namespace bellows
