// Counts global allocations while counting is on: for tests that prove a call allocates nothing.
// Replaces the global operator new/delete: include it in exactly one file of a test executable.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace bellows::testing_allocations {
inline std::atomic<bool> counting{false};
inline std::atomic<long> count{0};

/// Counts the allocations of its lifetime.
class Counter {
 public:
  Counter() {
    count.store(0);
    counting.store(true);
  }
  ~Counter() { counting.store(false); }
  long allocations() const { return count.load(); }
};

/// The allocations a Counter sees for one `new`: 1 when the instrument works.
inline long probe_allocations() {
  Counter counter;
  int* volatile probe = new int(1);  // volatile: else the compiler may elide the new/delete pair (C++14 allows it)
  const long seen = counter.allocations();
  delete probe;
  return seen;
}
}  // namespace bellows::testing_allocations

void* operator new(std::size_t size) {
  if (bellows::testing_allocations::counting.load(std::memory_order_relaxed)) {
    bellows::testing_allocations::count.fetch_add(1, std::memory_order_relaxed);
  }
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
