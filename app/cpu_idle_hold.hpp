#pragma once
// Keeps the CPUs out of deep idle states while the engine runs on wall time.
//
// Waking a core from a deep idle state (or, in a VM, a halted vCPU) costs tens of microseconds on
// every tick. The kernel's PM QoS interface lets a process ask for a maximum wake-up latency by
// holding /dev/cpu_dma_latency open with the value written to it; the request ends when the file is
// closed. cyclictest does the same by default, so the engine's latency is measured on equal terms.
// Best effort: without the permission the engine runs anyway and the report says so.

#include <optional>

namespace bellows {

class CpuIdleHold {
 public:
  /// Asks for `max_wakeup_us` (0: no idle state deeper than polling) when `wanted`.
  explicit CpuIdleHold(bool wanted, int max_wakeup_us = 0);
  ~CpuIdleHold();
  CpuIdleHold(const CpuIdleHold&) = delete;
  CpuIdleHold& operator=(const CpuIdleHold&) = delete;

  /// The wake-up latency held, or nothing when not asked for or refused.
  std::optional<int> held_us() const;

 private:
  int fd_ = -1;
  int max_wakeup_us_ = 0;
};

}  // namespace bellows
