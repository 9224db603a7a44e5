// What a T7 refuses, for t7-sim (docs/labjack-t7.md has each rule's source). A request that breaks
// one is answered with a Modbus exception and changes nothing; LabJack's error number goes to
// LAST_ERR_DETAIL, as on the device:
// - an unknown address, a write to a read-only one: exception 2 (LJM 1202);
// - a value a register cannot take (a resolution index beyond the product's, a settling beyond
//   50 ms): exception 3 (LJM 1203);
// - the extended features' own errors, exception 4 with: 2554 disabling a clock that is not
//   running; 2558 enabling clock 0 while clock 1 or 2 runs; 2559 a divisor other than 1, 2, 4, 8,
//   16, 32, 64, 256; 2563 enabling PWM on a line that is not an output driven low; 2565 a PWM
//   CONFIG_A not below clock 0's roll value; 2566 changing an enabled EF's index.
#pragma once

#include <cstdint>
#include <string>

#include "devices/t7_sim_registers.hpp"
#include "devices/t7_timing.hpp"

namespace bellows {

struct T7Refusal {
  int exception = 0;  // Modbus exception code; 0: the request is served
  int error = 0;      // LabJack's error number
  int address = 0;    // the register that broke the rule
  std::string why;    // e.g. "CONFIG_A 400000 >= roll value 400000"
};

/// The refusal for a request (function 3, 4, 6 or 16; `values`: what a write carries), or one with
/// exception 0 to serve it.
T7Refusal check_t7_request(const T7SimRegisters& registers, t7::Product product, int function, int address, int count,
                           const std::uint16_t* values);

}  // namespace bellows
