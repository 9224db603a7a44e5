#include "devices/request_arrival.hpp"

#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

namespace bellows {
namespace {

// A stamp older than this is taken for none (a request never waits that long to be read).
constexpr double kMaxAge_s = 60.0;

double realtime_now_s() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

timespec to_timespec(double s) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(std::floor(s));
  t.tv_nsec = static_cast<long>((s - static_cast<double>(t.tv_sec)) * 1e9);
  if (t.tv_nsec >= 1000000000L) {
    ++t.tv_sec;
    t.tv_nsec -= 1000000000L;
  }
  return t;
}

}  // namespace

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool enable_arrival_stamps(int fd) {
  const int one = 1;
  return setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one) == 0;
}

double request_arrival_s(int fd, double fallback_s) {
  char byte = 0;
  iovec io{&byte, 1};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
  msghdr message{};
  message.msg_iov = &io;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  if (recvmsg(fd, &message, MSG_PEEK | MSG_DONTWAIT) <= 0) return fallback_s;
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
    timespec stamp{};
    std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
    // The stamp is on the realtime clock: its age, from the two clocks read together (again when
    // this thread was preempted between the reads, which would age it by the preemption).
    double steady = 0.0, realtime = 0.0;
    for (int attempt = 0; attempt < 3; ++attempt) {
      const double before = realtime_now_s();
      steady = steady_now_s();
      const double after = realtime_now_s();
      realtime = 0.5 * (before + after);
      if (after - before < 50e-6) break;
    }
    const double age_s = realtime - (static_cast<double>(stamp.tv_sec) + static_cast<double>(stamp.tv_nsec) * 1e-9);
    if (!(age_s < kMaxAge_s)) return fallback_s;  // no stamp the kernel took for this data
    return steady - std::max(0.0, age_s);
  }
  return fallback_s;
}

void wait_until_s(double due_s, double spin_s) {
  // steady_clock is CLOCK_MONOTONIC on Linux (libstdc++).
  const timespec sleep_to = to_timespec(due_s - std::max(0.0, spin_s));
  while (steady_now_s() < due_s - spin_s &&
         clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &sleep_to, nullptr) == EINTR) {
  }
  while (steady_now_s() < due_s) {
  }
}

}  // namespace bellows
