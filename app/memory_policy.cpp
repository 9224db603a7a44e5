#include "app/memory_policy.hpp"

#include <malloc.h>

namespace bellows {
namespace {

// A trial record (tick-rate telemetry of a 9 s trial) is ~300 kB; an ILC-rate vector ~4 kB.
constexpr int kMmapThreshold_bytes = 64 * 1024;
// The UI, the saver and the workers share two heaps; the engine thread allocates nothing.
constexpr int kArenas = 2;

}  // namespace

void bound_allocator_retention() {
  ::mallopt(M_MMAP_THRESHOLD, kMmapThreshold_bytes);  // also stops the threshold from rising
  ::mallopt(M_ARENA_MAX, kArenas);
}

void return_free_memory() { ::malloc_trim(0); }

}  // namespace bellows
