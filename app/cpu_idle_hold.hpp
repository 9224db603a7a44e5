#pragma once
// Keeps the CPUs out of deep idle states while the engine runs on wall time.
//
// Waking a core from a deep idle state (or, in a VM, a halted vCPU) costs tens of microseconds on
// every tick. The kernel's PM QoS interface lets a process ask for a maximum wake-up latency by
// holding /dev/cpu_dma_latency open with the value written to it; the request ends when the file is
// closed. cyclictest does the same by default, so the engine's latency is measured on equal terms.
// Only a cpuidle driver acts on the request (its governor picks no state slower than the limit):
// without one (/sys/devices/system/cpu/cpuidle/current_driver "none", as in many VMs, e.g. this
// project's 2-core test VM) an idle core halts whatever is asked, so the hold is not claimed.
// Best effort: without the permission or the driver the engine runs anyway and the report says so.

#include <optional>
#include <string>

namespace bellows {

class CpuIdleHold {
 public:
  static constexpr const char* kCpuidleDriverPath = "/sys/devices/system/cpu/cpuidle/current_driver";

  /// Asks for `max_wakeup_us` (0: no idle state deeper than polling) when `wanted` and the cpuidle
  /// driver named in `driver_path` would act on it.
  explicit CpuIdleHold(bool wanted, int max_wakeup_us = 0, const std::string& driver_path = kCpuidleDriverPath);
  ~CpuIdleHold();
  CpuIdleHold(const CpuIdleHold&) = delete;
  CpuIdleHold& operator=(const CpuIdleHold&) = delete;

  /// The wake-up latency held, or nothing when not asked for, refused or without effect.
  std::optional<int> held_us() const;
  /// Why a wanted hold is not held ("" when held or not wanted).
  const std::string& why_not() const { return why_not_; }

 private:
  int fd_ = -1;
  int max_wakeup_us_ = 0;
  std::string why_not_;
};

}  // namespace bellows
