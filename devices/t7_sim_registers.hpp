// The register side of `bellows t7-sim`: the subset of a T7's Modbus map bellows uses, what the
// lines output, and the T7's watchdog, as docs/labjack-t7.md describes the real one.
// - Known addresses only: any other one, or a write to a read-only one, is answered with Modbus
//   exception 2 (ILLEGAL DATA ADDRESS), as a T7 does; a function other than 3, 4, 6, 16 with 1.
//   What a T7 refuses beyond addresses: devices/t7_sim_rules.hpp.
// - A line's output: PWM (EF enabled, index 0, clock 0 enabled) at CONFIG_A / roll; else an output
//   at its DIO_STATE bit; else an input, which the valve driver's pull-down reads as closed.
// - The IO configuration (AIN, DIO, DIO_EF and its clocks) has the factory's values and the power-up
//   defaults, which IO_CONFIG_SET_BOOTUP_TO_CURRENT saves from the current values (as Kipling's "save
//   as power-up defaults" does, PWM and all) and IO_CONFIG_SET_BOOTUP_TO_FACTORY resets.
// - The watchdog counts from the last answered request; on timeout it resets the IO configuration
//   as WATCHDOG_ADVANCED_DEFAULT asks (1 the factory's: every EF off, every line an input; 2, or
//   the reset action, the power-up defaults), then sets the lines WATCHDOG_DIO_DIRECTION/STATE_DEFAULT
//   name, and starts over. Whether a T7's Set DIO overrides a line an EF drives is not documented
//   (docs/labjack-t7.md): here it does not, the unsafe answer, so a safe configuration cannot rely on it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bellows {

class T7SimRegisters {
 public:
  /// `high_resolution_adc`: a T7-Pro (HARDWARE_INSTALLED bit 0).
  explicit T7SimRegisters(bool high_resolution_adc = true);

  /// The whole 16-bit register space; the server's Modbus mapping points into it.
  std::uint16_t* data() { return registers_.data(); }
  static constexpr int kSize = 65536;

  /// The Modbus exception for a request's addresses (function, first address, register count), or
  /// 0 (devices/t7_sim_rules.hpp checks the values).
  int check(int function, int address, int count) const;
  /// What a served write does beside storing its values: a FIO# write makes the line an output at
  /// that level; AIN_ALL_RESOLUTION_INDEX sets every input's.
  void wrote(int address, int count);

  /// The duty cycle line `dio` outputs now, in [0, 1].
  double line_duty(int dio) const;

  /// Writes volts into AIN#.
  void set_ain(int ain, double volts);

  /// A request was answered at `now_s`: the watchdog starts over.
  void answered(double now_s) { last_answer_s_ = now_s; }
  /// Runs the watchdog; true when it acted at this call.
  bool run_watchdog(double now_s);
  bool watchdog_enabled() const;
  std::uint32_t watchdog_timeout_s() const;
  double last_answer_s() const { return last_answer_s_; }

  std::uint16_t u16(int address) const { return registers_[static_cast<std::size_t>(address)]; }
  std::uint32_t u32(int address) const;
  void set_u32(int address, std::uint32_t value);

 private:
  void allow(int first, int count, bool writable);
  /// The registers of the IO configuration, in order (what IO_CONFIG_* saves and restores).
  std::vector<std::uint16_t> io_config() const;
  void set_io_config(const std::vector<std::uint16_t>& values);
  void set_bootup(const std::vector<std::uint16_t>& values);

  std::vector<std::uint16_t> registers_;
  std::vector<std::uint16_t> factory_io_config_, bootup_io_config_;
  std::vector<std::uint8_t> access_;  // 0 unknown, 1 read only, 2 read-write
  double last_answer_s_ = 0.0;
};

}  // namespace bellows
