// The last seconds of ticks before a fault (libfranka's idea): the loop writes every tick into a
// preallocated ring; on a fault it freezes, and stays frozen until the fault is reset, so a reader
// on another thread can copy it while the engine no longer touches it.
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

#include "engine/rt/engine_messages.hpp"

namespace bellows {

class BlackBox {
 public:
  explicit BlackBox(std::size_t capacity) : ring_(capacity > 0 ? capacity : 1) {}

  /// Loop side: record one tick (ignored while frozen).
  void record(const TickRecord& tick) {
    if (frozen_.load(std::memory_order_relaxed)) return;
    ring_[next_] = tick;
    next_ = (next_ + 1) % ring_.size();
    if (count_ < ring_.size()) ++count_;
  }
  /// Loop side: keep what is there (after the fault tick was recorded).
  void freeze() { frozen_.store(true, std::memory_order_release); }
  /// Loop side, on reset: start recording afresh.
  void clear() {
    count_ = 0;
    next_ = 0;
    frozen_.store(false, std::memory_order_release);
  }

  /// Reader side: whether a frozen record is available to copy.
  bool frozen() const { return frozen_.load(std::memory_order_acquire); }
  /// Reader side: the frozen ticks, oldest first. Empty unless frozen.
  std::vector<TickRecord> copy_frozen() const {
    std::vector<TickRecord> out;
    if (!frozen()) return out;
    out.reserve(count_);
    const std::size_t start = (next_ + ring_.size() - count_) % ring_.size();
    for (std::size_t i = 0; i < count_; ++i) out.push_back(ring_[(start + i) % ring_.size()]);
    return out;
  }
  std::size_t capacity() const { return ring_.size(); }

 private:
  std::vector<TickRecord> ring_;
  std::size_t next_ = 0;
  std::size_t count_ = 0;
  std::atomic<bool> frozen_{false};
};

}  // namespace bellows
