// The engine thread on wall time: ticks on absolute deadlines (CLOCK_MONOTONIC, TIMER_ABSTIME),
// with SCHED_FIFO (priority 80 by default, above the rig links' I/O threads at 70) and locked memory
// when the system allows it (`--rt try`, the default, or `enforce`). Every signal is blocked on
// it, so that no handler runs inside a tick. On an overrun it counts the missed periods and skips
// ahead rather than bursting. It keeps a histogram of wake-up latency.
//
// `speed` warps time for a simulated device: each tick advances the device by tick_s but waits only
// tick_s / speed of wall time (speed 0 means as fast as possible).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "engine/rt/engine_driver.hpp"

namespace bellows {

enum class RealtimeMode { kEnforce, kTry, kOff };

struct LatencySummary {
  std::uint64_t ticks = 0;
  std::uint64_t missed = 0;
  double p50_us = 0.0, p99_us = 0.0, max_us = 0.0;
};

/// Wake-up latency histogram in 1 us bins, written by the loop thread and read by any other.
class LatencyHistogram {
 public:
  static constexpr std::size_t kBins = 20000;  // up to 20 ms; beyond counts in the last bin
  void add(double latency_us);
  LatencySummary summarize() const;
  void clear();

 private:
  std::array<std::atomic<std::uint32_t>, kBins> bins_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::uint64_t> max_ns_{0};
};

class RealtimeLoop final : public EngineDriver {
 public:
  RealtimeLoop(EngineCore& core, Device& device, double speed);
  ~RealtimeLoop() override;

  /// Starts the thread. With kEnforce, throws EnvironmentError if SCHED_FIFO or mlockall is refused;
  /// with kTry it takes what it gets (see rt_granted()). Blocks all signals in the loop thread.
  void start(RealtimeMode mode, int priority = 80);
  /// Stops the thread and vents the device.
  void stop();

  bool rt_granted() const { return rt_granted_; }
  std::string rt_description() const { return rt_description_; }
  LatencySummary latency() const;
  std::uint64_t missed_deadlines() const { return missed_.load(std::memory_order_relaxed); }

  EngineCore& core() override { return core_; }
  void await() override;
  bool simulated() const override { return false; }

 private:
  void run(int priority, RealtimeMode mode);

  EngineCore& core_;
  Device& device_;
  double speed_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> ready_{false};
  bool rt_granted_ = false;
  std::string rt_description_ = "other";
  std::string start_error_;
  LatencyHistogram histogram_;
  std::atomic<std::uint64_t> missed_{0};
};

}  // namespace bellows
