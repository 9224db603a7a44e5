// The one thread that uses an LCM handle. LCM 1.3.1 supports one thread per `lcm::LCM`: this thread
// opens the bus, subscribes its endpoints, waits on the bus's file descriptor until a message
// arrives or an endpoint's next deadline comes, dispatches, and gives every endpoint its periodic
// turn (`service`). Endpoints talk to the rest of the program through lock-free buffers only.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "engine/rt/realtime_loop.hpp"

namespace bellows {

/// Monotonic time in seconds (CLOCK_MONOTONIC), the clock of every endpoint.
double monotonic_s();

/// Something served by an LcmIoThread. Every method runs on that thread.
class LcmEndpoint {
 public:
  virtual ~LcmEndpoint() = default;
  /// Subscribe (with subscribe()) to what it receives. Called once, before the first service().
  virtual void attach(lcm::LCM& bus) { (void)bus; }
  /// A message on a channel it subscribed to: raw bytes, trusted for nothing.
  virtual void on_message(const char* channel, const void* data, std::size_t size) {
    (void)channel;
    (void)data;
    (void)size;
  }
  /// Periodic work: hand over what arrived, publish what is due. `bus` is null when the thread
  /// runs without a bus (a publisher that only writes a log). Returns the monotonic time by which
  /// it wants its next turn; it may get one earlier (after every message received).
  virtual double service(lcm::LCM* bus, double now_s) = 0;
  /// The last turn, before the thread exits: flush, publish a final vent, close files.
  virtual void finish(lcm::LCM* bus, double now_s) {
    (void)bus;
    (void)now_s;
  }

 protected:
  /// Delivers the messages on `channel` (an LCM channel regex) to on_message(). Through LCM's C
  /// API: the C++ member-function subscribe of LCM 1.3.1 crashes when built with GCC 12's
  /// -fsanitize=vptr (its pointer-to-member call goes wrong), so the sanitizer builds could not run
  /// it. `queue_capacity` 0 keeps LCM's default (30 messages; a full queue drops the newest).
  void subscribe(lcm::LCM& bus, const std::string& channel, int queue_capacity = 0);
};

class LcmIoThread {
 public:
  /// `url` empty: no bus. The endpoints must outlive the thread.
  LcmIoThread(std::string url, std::vector<LcmEndpoint*> endpoints);
  ~LcmIoThread();
  LcmIoThread(const LcmIoThread&) = delete;
  LcmIoThread& operator=(const LcmIoThread&) = delete;

  /// Starts the thread and returns once the bus is open. With kEnforce / kTry the thread asks for
  /// SCHED_FIFO `priority` before opening the bus, so LCM's own receive thread inherits it.
  /// Throws InputError if the bus cannot be opened, or real-time scheduling is refused under kEnforce.
  void start(RealtimeMode mode, int priority);
  /// Serves on the calling thread until `should_stop()` returns true (checked at least every 50 ms).
  void run(const std::function<bool()>& should_stop, RealtimeMode mode, int priority);
  /// Called on the I/O thread once the bus is open, before serving (e.g. to announce it: only a bus
  /// that opened is announced).
  void on_open(std::function<void()> callback) { on_open_ = std::move(callback); }
  /// Gives every endpoint its last turn and joins the thread.
  void stop();

  bool rt_granted() const { return rt_granted_; }
  const std::string& url() const { return url_; }

 private:
  void serve(const std::function<bool()>& should_stop, RealtimeMode mode, int priority);

  std::string url_;
  std::vector<LcmEndpoint*> endpoints_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> ready_{false};
  std::string start_error_;  // written by the thread before ready_, read after
  bool rt_granted_ = false;
  std::function<void()> on_open_;
};

}  // namespace bellows
