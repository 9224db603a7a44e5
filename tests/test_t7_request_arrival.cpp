// t7-sim times a T7's answer from the request's arrival (the kernel's receive stamp), not from the
// moment its own thread woke for it (devices/request_arrival.hpp), and never answers early.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "devices/request_arrival.hpp"
#include "tests/loopback_listener.hpp"

namespace bellows {
namespace {

/// A connected pair of TCP sockets on 127.0.0.1: [0] the client's end, [1] the server's.
struct LoopbackPair {
  int fd[2] = {-1, -1};
  LoopbackPair() {
    sockaddr_in address{};
    const int listener = testing::loopback_listener(address);
    fd[0] = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    ::connect(fd[0], reinterpret_cast<sockaddr*>(&address), sizeof address);
    fd[1] = ::accept(listener, nullptr, nullptr);
    ::close(listener);
  }
  ~LoopbackPair() {
    for (int f : fd)
      if (f >= 0) ::close(f);
  }
};

TEST(T7SimRequestArrival, IsWhenTheRequestArrivedNotWhenItIsLookedAt) {
  LoopbackPair pair;
  ASSERT_GE(pair.fd[1], 0);
  ASSERT_TRUE(enable_arrival_stamps(pair.fd[1]));
  // The kernel turns receive stamps on for the whole stack a little after the first socket asks
  // (a deferred static key): until then data arrive unstamped and the fallback is used. Wait for
  // the first stamped byte (consumed), as t7-sim's first requests may go unstamped.
  bool stamped = false;
  for (int attempt = 0; attempt < 200 && !stamped; ++attempt) {
    const std::uint8_t probe = 0;
    ASSERT_EQ(::send(pair.fd[0], &probe, 1, 0), 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    stamped = request_arrival_s(pair.fd[1], -1.0) != -1.0;
    std::uint8_t drained = 0;
    ASSERT_EQ(::recv(pair.fd[1], &drained, 1, 0), 1);
  }
  ASSERT_TRUE(stamped) << "no receive stamp within a second";
  const std::uint8_t request[12] = {0, 1, 0, 0, 0, 6, 0xff, 3, 0, 0, 0, 2};
  const double sent_s = steady_now_s();
  ASSERT_EQ(::send(pair.fd[0], request, sizeof request, 0), static_cast<ssize_t>(sizeof request));
  std::this_thread::sleep_for(std::chrono::milliseconds(30));  // the server's thread wakes late
  const double looked_s = steady_now_s();
  const double arrived_s = request_arrival_s(pair.fd[1], looked_s);
  // The stamp is the kernel's, taken when the bytes came in: at least the 30 ms sleep before the look.
  EXPECT_LE(arrived_s, looked_s - 0.029);
  EXPECT_GE(arrived_s, sent_s - 0.001);  // the clocks' conversion: within a millisecond
  // Peeking consumed nothing: the whole request is still there for the Modbus server to read.
  std::uint8_t got[12] = {};
  EXPECT_EQ(::recv(pair.fd[1], got, sizeof got, MSG_DONTWAIT), static_cast<ssize_t>(sizeof got));
  EXPECT_EQ(got[7], 3);
}

TEST(T7SimRequestArrival, WithoutStampsOrDataItIsTheFallback) {
  LoopbackPair pair;
  ASSERT_GE(pair.fd[1], 0);
  EXPECT_EQ(request_arrival_s(pair.fd[1], 12.5), 12.5);  // nothing queued
  const std::uint8_t byte = 7;
  ASSERT_EQ(::send(pair.fd[0], &byte, 1, 0), 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(request_arrival_s(pair.fd[1], 12.5), 12.5);  // queued, but stamps were never asked for
}

TEST(T7SimRequestArrival, AnAnswerIsNeverEarlierThanItsDueTime) {
  for (const double spin_s : {0.0, 0.0002, 0.01}) {
    const double due_s = steady_now_s() + 0.003;
    wait_until_s(due_s, spin_s);
    EXPECT_GE(steady_now_s(), due_s) << "spin " << spin_s;
  }
  const double past_s = steady_now_s() - 1.0;  // already due (a stalled request): at once
  wait_until_s(past_s, 0.0002);
  EXPECT_GE(steady_now_s(), past_s);
}

}  // namespace
}  // namespace bellows
