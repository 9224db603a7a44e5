// The link figures a Device reports in health(): round trips (one exchange with the rig) kept in a
// fixed ring that the I/O thread writes and any thread may summarize. Lock-free and
// allocation-free on the writing side; the reader copies the ring (relaxed atomics: a summary may
// mix a few old and new entries, never a torn value).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "engine/control/device.hpp"

namespace bellows {

class RoundTripStats {
 public:
  static constexpr std::size_t kKept = 1024;  // the last ~5 s of exchanges at 200 Hz

  /// I/O thread: one completed exchange.
  void record(double round_trip_ms) {
    const std::uint64_t n = count_.load(std::memory_order_relaxed);
    ring_[n % kKept].store(static_cast<float>(round_trip_ms), std::memory_order_relaxed);
    count_.store(n + 1, std::memory_order_release);
  }

  /// Any thread: p50, p99 and max of the kept round trips, and how many there were in all.
  void summarize(DeviceHealth& health) const {
    const std::uint64_t n = count_.load(std::memory_order_acquire);
    health.exchanges = n;
    const std::size_t kept = static_cast<std::size_t>(std::min<std::uint64_t>(n, kKept));
    if (kept == 0) return;
    std::vector<float> values(kept);
    for (std::size_t i = 0; i < kept; ++i) values[i] = ring_[i].load(std::memory_order_relaxed);
    std::sort(values.begin(), values.end());
    const auto at = [&](double q) {
      return static_cast<double>(values[static_cast<std::size_t>(q * static_cast<double>(kept - 1))]);
    };
    health.round_trip_p50_ms = at(0.5);
    health.round_trip_p99_ms = at(0.99);
    health.round_trip_max_ms = values.back();
  }

 private:
  std::array<std::atomic<float>, kKept> ring_{};
  std::atomic<std::uint64_t> count_{0};
};

}  // namespace bellows
