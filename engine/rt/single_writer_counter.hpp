// A counter written by one thread and read by any: a relaxed load and store, no read-modify-write
// (no lock prefix on the writer's hot path); readers may see a value one step old.
#pragma once

#include <atomic>
#include <cstdint>

namespace bellows {

/// Adds `by` to a counter that only the calling thread writes.
inline void bump(std::atomic<std::uint64_t>& counter, std::uint64_t by = 1) {
  counter.store(counter.load(std::memory_order_relaxed) + by, std::memory_order_relaxed);
}

}  // namespace bellows
