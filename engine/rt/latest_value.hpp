// A latest-value buffer between exactly one writer and one reader (a lock-free triple buffer):
// the writer never blocks and never waits for the reader; the reader always gets the most recent
// complete value. The idea of ros2_control's RealtimeBuffer, without its mutex.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace bellows {

template <typename T>
class LatestValue {
 public:
  /// Writer side: publish a complete value.
  void write(const T& value) {
    buffers_[back_] = value;
    const std::uint8_t previous =
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = previous & kIndexMask;
  }

  /// Reader side: copy the latest value into `out`. Returns false if nothing new since the last read
  /// (`out` then holds the previous value again).
  bool read(T& out) {
    bool fresh = false;
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const std::uint8_t previous = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = previous & kIndexMask;
      fresh = true;
    }
    out = buffers_[front_];
    return fresh;
  }

 private:
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;
  std::array<T, 3> buffers_{};
  std::uint8_t back_ = 0;                // writer's buffer
  std::atomic<std::uint8_t> middle_{1};  // the hand-over buffer, with the fresh flag
  std::uint8_t front_ = 2;               // reader's buffer
};

}  // namespace bellows
