// The CPU idle hold: a PM QoS request that lives exactly as long as the object.
#include <gtest/gtest.h>
#include <sched.h>

#include <filesystem>

#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

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

// Writes `driver` as a cpuidle current_driver file and returns its path.
std::string driver_file(const std::string& driver) {
  const std::string path = testing::TempDir() + "cpuidle_current_driver";
  std::ofstream(path) << driver << "\n";
  return path;
}

TEST(CpuIdleHold, WithoutACpuidleDriverNothingIsClaimed) {
  // No driver to act on a PM QoS limit (a VM's idle cores halt): the hold says so, and holds nothing.
  const CpuIdleHold none(true, 0, driver_file("none"));
  EXPECT_FALSE(none.held_us().has_value());
  EXPECT_NE(none.why_not().find("no cpuidle driver"), std::string::npos) << none.why_not();
  const CpuIdleHold missing(true, 0, testing::TempDir() + "no-such-cpuidle-file");
  EXPECT_FALSE(missing.held_us().has_value());
  EXPECT_NE(missing.why_not().find("missing"), std::string::npos) << missing.why_not();
}

TEST(CpuIdleHold, ForARigWithoutACpuidleDriverEveryCoreSpinsInTheIdleClassWhileItLives) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ASSERT_EQ(sched_getaffinity(0, sizeof allowed, &allowed), 0);
  const int cores = CPU_COUNT(&allowed);
  {
    const CpuIdleHold hold(true, 0, driver_file("none"), true);
    if (hold.spinning_cores() == 0) GTEST_SKIP() << "SCHED_IDLE refused here: " << hold.why_not();
    EXPECT_EQ(hold.spinning_cores(), cores);
    EXPECT_EQ(hold.why_not(), "") << "held, by spinning";
    EXPECT_FALSE(hold.held_us().has_value()) << "no PM QoS limit was asked for";
    // The spinners are in the idle class (a thread with work takes their core at once): this
    // process's threads in SCHED_IDLE, one per core.
    int idle_class = 0;
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
      const int policy = sched_getscheduler(static_cast<pid_t>(std::stoi(task.path().filename().string())));
      if (policy == SCHED_IDLE) ++idle_class;
    }
    EXPECT_EQ(idle_class, cores);
  }
  // Not for the simulated arm (no spinners), and with a driver that acts, never.
  EXPECT_EQ(CpuIdleHold(true, 0, driver_file("none"), false).spinning_cores(), 0);
  EXPECT_EQ(CpuIdleHold(false, 0, driver_file("none"), true).spinning_cores(), 0);
}

TEST(CpuIdleHold, HoldsTheLimitWhileAliveAndReleasesIt) {
  const std::optional<std::int32_t> before = current_limit_us();
  if (!before) GTEST_SKIP() << "/dev/cpu_dma_latency is not readable here";
  if (*before <= 7) GTEST_SKIP() << "another process already holds a limit of " << *before << " us";
  {
    const CpuIdleHold hold(true, 7, driver_file("intel_idle"));  // a driver that acts on it
    if (!hold.held_us()) GTEST_SKIP() << "no permission to write /dev/cpu_dma_latency";
    EXPECT_EQ(*hold.held_us(), 7);
    EXPECT_EQ(current_limit_us(), 7);
  }
  EXPECT_EQ(current_limit_us(), before);
}

}  // namespace
}  // namespace bellows
