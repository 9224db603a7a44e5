// The CPU idle hold: a PM QoS request that lives exactly as long as the object.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <optional>

#include "app/cpu_idle_hold.hpp"

namespace bellows {
namespace {

// Reading /dev/cpu_dma_latency gives the system's current wake-up limit in microseconds.
std::optional<std::int32_t> current_limit_us() {
  std::ifstream file("/dev/cpu_dma_latency", std::ios::binary);
  std::int32_t value = 0;
  if (!file.read(reinterpret_cast<char*>(&value), sizeof value)) return std::nullopt;
  return value;
}

TEST(CpuIdleHold, NotWantedHoldsNothing) {
  const CpuIdleHold hold(false);
  EXPECT_FALSE(hold.held_us().has_value());
}

TEST(CpuIdleHold, HoldsTheLimitWhileAliveAndReleasesIt) {
  const std::optional<std::int32_t> before = current_limit_us();
  if (!before) GTEST_SKIP() << "/dev/cpu_dma_latency is not readable here";
  if (*before <= 7) GTEST_SKIP() << "another process already holds a limit of " << *before << " us";
  {
    const CpuIdleHold hold(true, 7);
    if (!hold.held_us()) GTEST_SKIP() << "no permission to write /dev/cpu_dma_latency";
    EXPECT_EQ(*hold.held_us(), 7);
    EXPECT_EQ(current_limit_us(), 7);
  }
  EXPECT_EQ(current_limit_us(), before);
}

}  // namespace
}  // namespace bellows
