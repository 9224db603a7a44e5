#pragma once
// Keeps the CPUs out of deep idle states while the engine runs on wall time.
//
// Waking a core from a deep idle state (or, in a VM, a halted vCPU) costs tens of microseconds on
// every tick. The kernel's PM QoS interface lets a process ask for a maximum wake-up latency by
// holding /dev/cpu_dma_latency open with the value written to it; the request ends when the file is
// closed. cyclictest does the same by default, so the engine's latency is measured on equal terms.
// Only a cpuidle driver acts on the request (its governor picks no state slower than the limit):
// without one (/sys/devices/system/cpu/cpuidle/current_driver "none", as in many VMs, e.g. this
// project's 2-core test VM) an idle core halts whatever is asked, and a halted vCPU waits for its
// host to run it again: on that VM the T7 link missed 16-63 answers per 3-iteration run and the
// loop woke up to 17 ms late when nothing else ran, against 0-1 and 2 ms beside two CPU-bound
// processes (docs/benchmarks.md, "Rig links under load"). So, for a rig (`spin_without_driver`),
// the hold there keeps every core busy with a spinning thread of the lowest class the kernel has
// (SCHED_IDLE): it runs only when a core would otherwise halt, and any other thread that wakes
// takes the core from it at once: user space's `idle=poll`, for as long as the object lives.
// Best effort: without the permission or the driver the engine runs anyway and the report says so.

#include <atomic>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace bellows {

class CpuIdleHold {
 public:
  static constexpr const char* kCpuidleDriverPath = "/sys/devices/system/cpu/cpuidle/current_driver";

  /// Asks for `max_wakeup_us` (0: no idle state deeper than polling) when `wanted` and the cpuidle
  /// driver named in `driver_path` would act on it; without such a driver, and `spin_without_driver`,
  /// one SCHED_IDLE spinner per CPU this process may run on.
  explicit CpuIdleHold(bool wanted, int max_wakeup_us = 0, const std::string& driver_path = kCpuidleDriverPath,
                       bool spin_without_driver = false);
  ~CpuIdleHold();
  CpuIdleHold(const CpuIdleHold&) = delete;
  CpuIdleHold& operator=(const CpuIdleHold&) = delete;

  /// The wake-up latency held, or nothing when not asked for, refused or without effect.
  std::optional<int> held_us() const;
  /// How many cores spinners keep out of halt (0: none; then held_us() or why_not() tells).
  int spinning_cores() const { return static_cast<int>(spinners_.size()); }
  /// Why a wanted hold is not held ("" when held or not wanted).
  const std::string& why_not() const { return why_not_; }

 private:
  void start_spinners();
  void stop_spinners();  // every spinner ended and joined (none left)

  int fd_ = -1;
  int max_wakeup_us_ = 0;
  std::string why_not_;
  std::atomic<bool> stop_{false};
  std::atomic<int> refused_{0}, decided_{0};  // the spinners' SCHED_IDLE requests
  std::vector<std::thread> spinners_;
};

}  // namespace bellows
