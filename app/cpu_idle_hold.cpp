#include "app/cpu_idle_hold.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <functional>

namespace bellows {
namespace {

/// One core's spinner: pinned to `cpu`, in SCHED_IDLE, until `stop`. Its first act is to leave the
/// normal class, so it never competes with a thread that has work; `refused` counts one the kernel
/// would not let (it then ends), `decided` every one that tried.
void spin(int cpu, const std::atomic<bool>& stop, std::atomic<int>& refused, std::atomic<int>& decided) {
  sched_param none{};
  const bool idle_class = pthread_setschedparam(pthread_self(), SCHED_IDLE, &none) == 0;
  if (!idle_class) refused.fetch_add(1, std::memory_order_relaxed);
  decided.fetch_add(1, std::memory_order_release);
  if (!idle_class) return;
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(cpu, &one);
  pthread_setaffinity_np(pthread_self(), sizeof one, &one);  // refused: it spins wherever it runs
  while (!stop.load(std::memory_order_relaxed)) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();  // the spin-wait hint: kinder to a sibling hyperthread
#endif
  }
}

}  // namespace

CpuIdleHold::CpuIdleHold(bool wanted, int max_wakeup_us, const std::string& driver_path, bool spin_without_driver)
    : max_wakeup_us_(max_wakeup_us) {
  if (!wanted) return;
  std::string driver;
  if (std::ifstream file(driver_path); !(file >> driver) || driver == "none") {
    why_not_ = "no cpuidle driver (" + driver_path + ": " + (driver.empty() ? "missing" : driver) +
               "): idle cores halt whatever is asked";
    if (spin_without_driver) start_spinners();
    return;
  }
  fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) {
    why_not_ = "/dev/cpu_dma_latency cannot be opened (no permission)";
    return;
  }
  const auto value = static_cast<std::int32_t>(max_wakeup_us);
  if (::write(fd_, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) {
    ::close(fd_);
    fd_ = -1;
    why_not_ = "/dev/cpu_dma_latency refused the limit";
  }
}

void CpuIdleHold::start_spinners() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) {
      spinners_.emplace_back(spin, cpu, std::cref(stop_), std::ref(refused_), std::ref(decided_));
    }
  }
  // Each spinner first asks for SCHED_IDLE (at once: a system call); one refused, none spins, as
  // a spinner in the normal class would take CPU from threads with work.
  while (decided_.load(std::memory_order_acquire) < static_cast<int>(spinners_.size())) std::this_thread::yield();
  if (refused_.load(std::memory_order_relaxed) != 0 || spinners_.empty()) {
    stop_spinners();
    why_not_ += "; SCHED_IDLE refused, no spinning either";
    return;
  }
  why_not_.clear();  // held, by spinning
}

void CpuIdleHold::stop_spinners() {
  stop_.store(true, std::memory_order_relaxed);
  // Back to the normal class first: on a busy core a SCHED_IDLE thread may wait seconds for the
  // slice in which it sees `stop_` (the end of a run beside two CPU-bound processes took 2 s more).
  sched_param none{};
  for (std::thread& t : spinners_) pthread_setschedparam(t.native_handle(), SCHED_OTHER, &none);
  for (std::thread& t : spinners_) t.join();
  spinners_.clear();
}

CpuIdleHold::~CpuIdleHold() {
  stop_spinners();
  if (fd_ >= 0) ::close(fd_);  // ends the request
}

std::optional<int> CpuIdleHold::held_us() const {
  if (fd_ < 0) return std::nullopt;
  return max_wakeup_us_;
}

}  // namespace bellows
