// How bellows asks glibc's allocator to give memory back. A console left running for a lab day
// allocates and frees trial records of hundreds of kB on several threads; glibc's defaults keep
// such blocks in per-thread heaps (its mmap threshold rises after the first free, and a free heap
// is returned to the system only from its top), so resident memory grows with the iterations run
// although the live heap stays bounded (docs/benchmarks.md, "Console soak").
#pragma once

namespace bellows {

/// Before any thread starts: blocks from kMmapThreshold_bytes up get pages of their own, returned
/// at once when freed; at most kArenas heaps.
void bound_allocator_retention();

/// Hands the free pages inside the heaps back to the system (malloc_trim). Not on the real-time
/// thread: it takes the allocator's locks. The console calls it after each autosave.
void return_free_memory();

}  // namespace bellows
