// When a device's I/O thread last made a turn of its loop. The engine's stale limit found a silence;
// if the thread made no turn for half of it, and for longer than a healthy turn can block, this host
// held the thread off its core: the silence is the machine's, not the link's (LcmDevice and T7Device
// name it so, each in its own words).
#pragma once

#include <atomic>
#include <cmath>

namespace bellows {

class IoTurnWatch {
 public:
  /// The I/O thread, at each turn, on the clock explain() is given.
  void turn(double now_s) { last_turn_s_.store(now_s, std::memory_order_release); }
  /// Any thread: how long the I/O thread has made no turn, when that explains a silence of `silent_s`
  /// (at least half of it, and longer than `longest_turn_s`, the longest a healthy turn blocks); NAN
  /// when it does not, or before the first turn.
  double held_off_s(double now_s, double silent_s, double longest_turn_s) const {
    const double idle_s = now_s - last_turn_s_.load(std::memory_order_acquire);
    return std::isfinite(idle_s) && idle_s >= 0.5 * silent_s && idle_s > longest_turn_s ? idle_s : NAN;
  }

 private:
  std::atomic<double> last_turn_s_{INFINITY};
};

}  // namespace bellows
