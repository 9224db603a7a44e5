#include "devices/lcm_io_thread.hpp"

#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"

namespace bellows {
namespace {

/// Opens an LCM handle with what LCM prints on stderr while doing so (it explains a failure in a
/// dozen lines of its own) captured instead of shown: bellows reports a failure in one line and
/// quotes LCM's reason. Opening happens before the run starts, when nothing else writes to stderr.
std::unique_ptr<lcm::LCM> open_lcm_quietly(const std::string& url, std::string& said) {
  const int capture = ::memfd_create("lcm-stderr", MFD_CLOEXEC);
  const int saved = capture >= 0 ? ::dup(STDERR_FILENO) : -1;
  if (saved >= 0) ::dup2(capture, STDERR_FILENO);
  auto bus = std::make_unique<lcm::LCM>(url);
  if (saved >= 0) {
    ::dup2(saved, STDERR_FILENO);
    ::close(saved);
    constexpr std::size_t kMostCaptured = 4096;
    std::string text(kMostCaptured, '\0');
    const ssize_t got = ::pread(capture, text.data(), text.size(), 0);
    text.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {  // the first line that says something
      if (!trim(line).empty()) {
        said = std::string(trim(line));
        break;
      }
    }
  }
  if (capture >= 0) ::close(capture);
  return bus;
}

// Upper bound on one wait, so that a stop request is seen promptly even on an idle bus.
constexpr double kMaxWait_s = 0.05;
// Messages already queued that one turn of the loop handles before it services its endpoints
// (bounded, so that a flood cannot keep it from servicing them).
constexpr int kMaxDrained = 64;

timespec to_timespec(double seconds) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(seconds);
  t.tv_nsec = static_cast<long>((seconds - static_cast<double>(t.tv_sec)) * 1e9);
  return t;
}

void deliver(const lcm_recv_buf_t* buffer, const char* channel, void* endpoint) {
  static_cast<LcmEndpoint*>(endpoint)->on_message(channel, buffer->data, buffer->data_size);
}

}  // namespace

void LcmEndpoint::subscribe(lcm::LCM& bus, const std::string& channel, int queue_capacity) {
  lcm_subscription_t* subscription = lcm_subscribe(bus.getUnderlyingLCM(), channel.c_str(), &deliver, this);
  if (subscription != nullptr && queue_capacity > 0) lcm_subscription_set_queue_capacity(subscription, queue_capacity);
}

double monotonic_s() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

LcmIoThread::LcmIoThread(std::string url, std::vector<LcmEndpoint*> endpoints)
    : url_(std::move(url)), endpoints_(std::move(endpoints)) {}

LcmIoThread::~LcmIoThread() { stop(); }

void LcmIoThread::start(RealtimeMode mode, int priority) {
  if (thread_.joinable()) return;
  stop_.store(false);
  ready_.store(false);
  thread_ = std::thread(
      [this, mode, priority] { serve([this] { return stop_.load(std::memory_order_acquire); }, mode, priority); });
  while (!ready_.load(std::memory_order_acquire)) std::this_thread::yield();
  if (!start_error_.empty()) {
    thread_.join();
    throw EnvironmentError(start_error_);  // the bus or the scheduler refused
  }
}

void LcmIoThread::run(const std::function<bool()>& should_stop, RealtimeMode mode, int priority) {
  serve(should_stop, mode, priority);
  if (!start_error_.empty()) throw EnvironmentError(start_error_);
}

void LcmIoThread::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true, std::memory_order_release);
  thread_.join();
}

void LcmIoThread::serve(const std::function<bool()>& should_stop, RealtimeMode mode, int priority) {
  pthread_setname_np(pthread_self(), "bellows-lcm-io");  // as htop -H, ps -L and gdb show it
  if (mode != RealtimeMode::kOff) {
    sched_param param{};
    param.sched_priority = priority;
    const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    rt_granted_ = error == 0;
    if (error != 0 && mode == RealtimeMode::kEnforce) {
      start_error_ =
          "--rt enforce: SCHED_FIFO refused for the LCM I/O thread (" + std::string(std::strerror(error)) + ")";
      ready_.store(true, std::memory_order_release);
      return;
    }
  }
  // The handle lives and dies on this thread: LCM 1.3.1 allows one thread per handle.
  std::unique_ptr<lcm::LCM> bus;
  if (!url_.empty()) {
    std::string lcm_said;
    bus = open_lcm_quietly(url_, lcm_said);
    if (!bus->good()) {
      start_error_ = "cannot open the LCM bus '" + printable(url_) + "'" +
                     (lcm_said.empty() ? std::string() : " (LCM: " + printable(lcm_said) + ")") +
                     (url_.rfind("udpm://", 0) == 0
                          ? "; for udpm:// the host needs a multicast route, e.g. `ip route add 224.0.0.0/4 dev lo`"
                          : "");
      ready_.store(true, std::memory_order_release);
      return;
    }
    for (LcmEndpoint* endpoint : endpoints_) endpoint->attach(*bus);
  }
  ready_.store(true, std::memory_order_release);
  if (on_open_) on_open_();

  const int fd = bus ? bus->getFileno() : -1;
  while (!should_stop()) {
    // What arrived while this thread was away first: a host that descheduled it (a loaded machine)
    // must not make a rig time out on commands, or a device miss states, already in the socket.
    for (int i = 0; fd >= 0 && i < kMaxDrained; ++i) {
      pollfd queued{fd, POLLIN, 0};
      if (poll(&queued, 1, 0) <= 0 || (queued.revents & POLLIN) == 0) break;
      bus->handle();
    }
    const double now = monotonic_s();
    double next = now + kMaxWait_s;
    for (LcmEndpoint* endpoint : endpoints_) next = std::min(next, endpoint->service(bus.get(), now));
    const double wait_s = std::clamp(next - monotonic_s(), 0.0, kMaxWait_s);
    const timespec timeout = to_timespec(wait_s);
    if (fd >= 0) {
      pollfd poll_fd{fd, POLLIN, 0};
      if (ppoll(&poll_fd, 1, &timeout, nullptr) > 0 && (poll_fd.revents & POLLIN) != 0) bus->handle();
    } else {
      nanosleep(&timeout, nullptr);
    }
  }
  const double now = monotonic_s();
  for (LcmEndpoint* endpoint : endpoints_) endpoint->finish(bus.get(), now);
}

}  // namespace bellows
