#include "engine/rt/realtime_loop.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

constexpr long kNsPerS = 1'000'000'000L;

timespec add_ns(timespec t, long long ns) {
  long long total = t.tv_nsec + ns;
  t.tv_sec += static_cast<time_t>(total / kNsPerS);
  t.tv_nsec = static_cast<long>(total % kNsPerS);
  return t;
}

long long diff_ns(const timespec& a, const timespec& b) {  // a - b
  return (static_cast<long long>(a.tv_sec) - b.tv_sec) * kNsPerS + (a.tv_nsec - b.tv_nsec);
}

// Touch the stack the loop may use, so no page fault happens inside a tick (with mlockall).
void prefault_stack() {
  constexpr std::size_t kStackBytes = 256 * 1024;
  unsigned char stack[kStackBytes];
  std::memset(stack, 0, kStackBytes);
  asm volatile("" : : "r"(stack) : "memory");  // keep the writes
}

}  // namespace

void LatencyHistogram::add(double latency_us) {
  const double clamped = latency_us < 0.0 ? 0.0 : latency_us;
  const auto bin = static_cast<std::size_t>(clamped);
  bins_[bin < kBins ? bin : kBins - 1].fetch_add(1, std::memory_order_relaxed);
  count_.fetch_add(1, std::memory_order_relaxed);
  const auto ns = static_cast<std::uint64_t>(clamped * 1000.0);
  std::uint64_t previous = max_ns_.load(std::memory_order_relaxed);
  while (ns > previous && !max_ns_.compare_exchange_weak(previous, ns, std::memory_order_relaxed)) {
  }
}

LatencySummary LatencyHistogram::summarize() const {
  LatencySummary s;
  s.ticks = count_.load(std::memory_order_relaxed);
  s.max_us = static_cast<double>(max_ns_.load(std::memory_order_relaxed)) / 1000.0;
  if (s.ticks == 0) return s;
  const auto quantile = [&](double q) {
    const auto target = static_cast<std::uint64_t>(q * static_cast<double>(s.ticks));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      seen += bins_[i].load(std::memory_order_relaxed);
      if (seen > target) return static_cast<double>(i) + 0.5;
    }
    return static_cast<double>(kBins);
  };
  s.p50_us = quantile(0.50);
  s.p99_us = quantile(0.99);
  return s;
}

void LatencyHistogram::clear() {
  for (auto& b : bins_) b.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_relaxed);
  max_ns_.store(0, std::memory_order_relaxed);
}

RealtimeLoop::RealtimeLoop(EngineCore& core, Device& device, double speed)
    : core_(core), device_(device), speed_(speed) {}

RealtimeLoop::~RealtimeLoop() { stop(); }

void RealtimeLoop::start(RealtimeMode mode, int priority) {
  if (running_.load()) return;
  running_.store(true);
  ready_.store(false);
  thread_ = std::thread([this, priority, mode] { run(priority, mode); });
  while (!ready_.load(std::memory_order_acquire)) std::this_thread::yield();
  if (!start_error_.empty()) {
    thread_.join();
    running_.store(false);
    throw EnvironmentError(start_error_);
  }
}

void RealtimeLoop::stop() {
  if (!thread_.joinable()) return;
  running_.store(false, std::memory_order_release);
  thread_.join();
  device_.vent();
}

LatencySummary RealtimeLoop::latency() const {
  LatencySummary s = histogram_.summarize();
  s.missed = missed_.load(std::memory_order_relaxed);
  return s;
}

void RealtimeLoop::await() {
  timespec pause{0, 1'000'000};  // 1 ms: the loop runs on its own; the operator just polls
  nanosleep(&pause, nullptr);
}

void RealtimeLoop::run(int priority, RealtimeMode mode) {
  // Signals go to the other threads (SIGINT, SIGTERM, SIGWINCH): never interrupt the loop.
  sigset_t all;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, nullptr);
  pthread_setname_np(pthread_self(), "bellows-engine");  // as htop -H, ps -L and gdb show it

  // Unpaced (speed max) the loop never sleeps: under SCHED_FIFO it would starve its core.
  if (speed_ <= 0.0 && mode == RealtimeMode::kTry) mode = RealtimeMode::kOff;
  if (mode != RealtimeMode::kOff) {
    const bool locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
    sched_param param{};
    param.sched_priority = priority;
    const int fifo_error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    rt_granted_ = locked && fifo_error == 0;
    if (fifo_error == 0) rt_description_ = "fifo";
    if (!rt_granted_ && mode == RealtimeMode::kEnforce) {
      start_error_ = std::string("--rt enforce: real-time scheduling refused (") +
                     (fifo_error != 0 ? "SCHED_FIFO: " + std::string(std::strerror(fifo_error))
                                      : "mlockall: " + std::string(std::strerror(errno))) +
                     "); run as root or grant CAP_SYS_NICE and a memlock limit, or use --rt try";
      ready_.store(true, std::memory_order_release);
      return;
    }
    prefault_stack();
  }
  ready_.store(true, std::memory_order_release);

  const double tick_s = core_.timing().tick_s;
  const auto period_ns = static_cast<long long>(speed_ > 0.0 ? tick_s / speed_ * 1e9 : 0.0);
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  timespec deadline = start;
  std::uint64_t tick = 0;
  int missed_since_last = 0;
  const bool follows_ticks = device_.time_follows_ticks();
  while (running_.load(std::memory_order_acquire)) {
    if (period_ns > 0) {
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr);
      timespec woke{};
      clock_gettime(CLOCK_MONOTONIC, &woke);
      const long long late_ns = diff_ns(woke, deadline);
      histogram_.add(static_cast<double>(late_ns) / 1000.0);
      // Overrun: count whole periods missed and skip ahead to the next future deadline.
      if (late_ns >= period_ns) {
        const long long skipped = late_ns / period_ns;
        missed_since_last += static_cast<int>(skipped);
        missed_.fetch_add(static_cast<std::uint64_t>(skipped), std::memory_order_relaxed);
        deadline = add_ns(deadline, skipped * period_ns);
      }
    }
    // Engine time is simulated time for a warped simulator: tick count times the tick.
    timespec wall{};
    clock_gettime(CLOCK_MONOTONIC, &wall);
    // The engine decides what a missed deadline means for its device (Device::time_follows_ticks()).
    // A rig whose time is its own lived through the missed periods: engine time keeps its pace.
    if (!follows_ticks) tick += static_cast<std::uint64_t>(missed_since_last);
    core_.tick(static_cast<double>(tick) * tick_s, static_cast<double>(diff_ns(wall, start)) * 1e-9, missed_since_last);
    device_.advance(tick_s);
    missed_since_last = 0;
    ++tick;
    if (period_ns > 0) {
      // The device may move the phase of the ticks (never their pace) by a little at a time.
      const double shift_ns = std::clamp(device_.tick_shift_s() * 1e9 / speed_, -0.1 * static_cast<double>(period_ns),
                                         0.1 * static_cast<double>(period_ns));
      deadline = add_ns(deadline, period_ns + std::llround(shift_ns));
    }
  }
}

}  // namespace bellows
