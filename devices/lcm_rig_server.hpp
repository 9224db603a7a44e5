// The simulated arm served as a rig over LCM (`bellows io-sim`): the reference for anyone writing a
// driver for real hardware (docs/lcm-protocol.md).
//
// On its own clock, every `period_s`, it publishes an io_state_t. It applies the latest valid
// io_command_t of the session it serves as soon as it arrives (integrating the arm's physics up to
// that moment first). Until the first valid command it holds the safe state (inlets closed, outlets
// open) and serves nobody; it then serves that command's session only. When that session's commands
// stop for `command_timeout_s` it vents by itself and serves nobody again. Anything malformed, out
// of order or from another session is counted and ignored.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "devices/lcm_codec.hpp"
#include "devices/lcm_io_thread.hpp"
#include "devices/simulated_arm.hpp"

namespace bellows {

struct RigServerParameters {
  double period_s = 1.0 / 200.0;     // state publication period, [timing] tick_s
  double command_timeout_s = 0.05;   // [lcm] rig_timeout_s
};

struct RigServerStats {
  std::int64_t rig_id = 0;
  ReceiveCounts commands;            // io_command_t received, by outcome
  std::uint64_t states_published = 0;
  std::uint64_t sessions_served = 0; // sessions accepted, one after another
  std::uint64_t timeouts = 0;        // times the rig vented because commands stopped
  std::uint64_t missed_periods = 0;  // periods skipped because the thread woke too late
  std::int64_t serving = 0;          // the session served now, 0: none
};

class RigServer final : public LcmEndpoint {
 public:
  /// `rig_id`: nonzero, unique per start (LcmDevice::random_session_id() will do).
  RigServer(SimulatedArm& arm, const RigServerParameters& params, std::int64_t rig_id);

  void attach(lcm::LCM& bus) override;
  void on_message(const char* channel, const void* data, std::size_t size) override;
  double service(lcm::LCM* bus, double now_s) override;
  void finish(lcm::LCM* bus, double now_s) override;

  /// Any thread.
  RigServerStats stats() const;

 private:
  void advance_to(double now_s);
  void publish_state(lcm::LCM& bus, double now_s);

  SimulatedArm& arm_;
  const RigServerParameters params_;
  const std::int64_t rig_id_;

  // I/O thread state.
  io_command_t received_{};
  io_command_t pending_{};
  bool pending_fresh_ = false;
  std::int64_t session_ = 0;        // served now
  std::int64_t last_session_ = 0;   // served last (its sequence numbers still count after a timeout)
  std::int64_t last_seq_ = 0;
  std::int64_t applied_seq_ = 0;
  std::int32_t fault_bits_ = io_state_t::FAULT_NO_SESSION;
  double origin_s_ = -1.0;
  double device_time_s_ = 0.0;
  double last_command_s_ = 0.0;
  double next_publish_s_ = 0.0;
  std::int64_t state_seq_ = 0;
  io_state_t state_{};
  std::vector<std::uint8_t> buffer_;

  ReceiveCounters counters_;
  std::atomic<std::uint64_t> states_published_{0}, sessions_served_{0}, timeouts_{0}, missed_periods_{0};
  std::atomic<std::int64_t> serving_{0};
};

}  // namespace bellows
