// The simulated arm served as a rig over LCM (`bellows io-sim`): the reference for anyone writing a
// driver for real hardware (docs/lcm-protocol.md).
//
// On its own clock, every `period_s`, it publishes an io_state_t (a stepped simulator instead
// answers each command at once: RigServerParameters::stepped). While free it holds the safe
// state (inlets closed, outlets open) and offers a random binding in its states; a session binds
// with a vent command addressed to this rig that echoes the offer, and from then on the rig applies
// that session's commands only, as soon as they arrive (the arm's physics integrated up to that
// moment first), provided each sequence number is above the last by at most `seq_window`. A vent
// addressed to this rig is obeyed whatever its session or sequence number. When the session's
// commands stop for `command_timeout_s`, or the arm leaves the rig's angle range, it vents and drops
// the session: tripped, it goes on naming that session and its last command in its states (with
// FAULT_NO_SESSION and the reason's bit, and already its new offer) for `command_timeout_s`, so
// that the engine it served reads why; then its states name no session. A chamber above the rig's ceiling is vented
// whatever the command. With a key, a command whose MAC does not match is counted and ignored, and every state is
// signed. Everything refused is counted, in the states and in the log.
//
// Joints: it serves any Device of J joints (the single-joint SimulatedArm, or the J-joint
// SimulatedArmChain for `[arm] preset`). With one joint it speaks io_command_t / io_state_t exactly
// as before joints existed; with several, io_joints_command_t / io_joints_state_t. A valid command
// for an arm of another joint count (either message type) is counted as `other_joints`, logged
// once per binding, and never binds or drives the arm (a vent addressed to this rig is obeyed, as
// every vent is).
//
// Limits: at its start and then every kIoLimitsPeriod_s it publishes an io_rig_limits_t on
// BELLOWS_IO_LIMITS (its period, command timeout, ceiling and angle range), which `bellows rig check
// --device lcm` compares with the engine's configuration.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "devices/lcm_auth.hpp"
#include "devices/lcm_codec.hpp"
#include "devices/lcm_io_messages.hpp"
#include "devices/lcm_io_thread.hpp"
#include "devices/lcm_rig_limits.hpp"
#include "devices/simulated_arm.hpp"

namespace bellows {

struct RigServerParameters {
  double period_s = 1.0 / 200.0;    // state publication period, [timing] tick_s
  double command_timeout_s = 0.05;  // [lcm] rig_timeout_s
  std::int64_t seq_window = 100;    // [lcm] seq_window
  RigLimits limits;                 // RigLimits::from(configuration)
  LcmKey key;                       // [lcm] key_file; none: nothing checked or signed
  /// false: a drill (`io-sim --no-command-timeout`): the rig announces its timeout but never vents
  /// when the commands stop, as a driver that forgot to (`rig check --device lcm` must catch it).
  bool command_timeout_enforced = true;
  /// A simulator's lockstep (`io-sim --stepped`, for `run --clock lockstep`): the arm's physics
  /// advances by one `period_s` under each command of the session served, and the state answering
  /// it goes out at once; between commands the rig's time stands still, and while serving it
  /// publishes only those answers. The command timeout counts on the wall clock as ever (set it to
  /// the engine's [lcm] lockstep_timeout_s). No real rig can wait for its commands.
  bool stepped = false;
  /// Called on the I/O thread with one line per notable event (a session bound or dropped, the
  /// first refusal of each kind per binding, a limit acted on). May be empty.
  std::function<void(const std::string&)> log;
};

struct RigServerStats {
  std::int64_t rig_id = 0;
  ReceiveCounts commands;           // io_command_t received, by outcome
  std::uint64_t not_addressed = 0;  // valid commands addressed to another rig or to none (not in `commands`)
  std::uint64_t vents_obeyed_out_of_sequence = 0;  // vents applied whose session or seq did not fit
  std::uint64_t states_published = 0;
  std::uint64_t sessions_served = 0;       // sessions bound, one after another
  std::uint64_t timeouts = 0;              // times the rig vented because commands stopped
  std::uint64_t pressure_limit_trips = 0;  // times a chamber crossed the ceiling and was vented
  std::uint64_t angle_limit_trips = 0;     // times the arm left the range: vented, session dropped
  std::uint64_t missed_periods = 0;        // periods skipped because the thread woke too late
  std::int64_t serving = 0;                // the session bound now, 0: none
  std::int64_t binding = 0;                // offered now (free) or in force (serving): public, in every state
};

class RigServer final : public LcmEndpoint {
 public:
  /// `rig_id`: nonzero, unique per start (random_nonzero_id()). The single-joint simulated arm.
  RigServer(SimulatedArm& arm, RigServerParameters params, std::int64_t rig_id);
  /// Any in-process arm of `joints` joints (1..kMaxJoints, InputError otherwise) whose physics is
  /// advanced in steps of at most `integration_step_s` (the limits are checked after each).
  RigServer(Device& arm, int joints, double integration_step_s, RigServerParameters params, std::int64_t rig_id);

  int joints() const { return joints_; }

  void attach(lcm::LCM& bus) override;
  void on_message(const char* channel, const void* data, std::size_t size) override;
  double service(lcm::LCM* bus, double now_s) override;
  void finish(lcm::LCM* bus, double now_s) override;

  /// Any thread.
  RigServerStats stats() const;

 private:
  // What the log reports once per binding (the refusals first).
  enum class Notice : std::uint8_t {
    kOldVersion,
    kUnauthenticated,
    kOtherJoints,
    kForeign,
    kJump,
    kPressureLimit,
    kAngleLimit,
    kCount
  };

  void obey_vent(const io_joints_command_t& vent);  // a vent addressed to this rig, outside its session's sequence
  void advance_to(double now_s);                    // free-running: the physics catches up with the wall clock
  void advance_by(double dt_s);                     // in integration steps, the limits checked after each
  void apply_limits(bool write);
  void release(std::int32_t fault_bits);  // vent, drop the session, offer a new binding
  void notice(Notice kind, const std::string& line);
  void say(const std::string& line) const;
  void publish_state(lcm::LCM& bus, double now_s);
  void publish_limits(lcm::LCM& bus, double now_s);

  Device& arm_;
  const int joints_;
  const double integration_step_s_;
  const RigServerParameters params_;
  const std::int64_t rig_id_;

  // I/O thread state.
  io_joints_command_t received_{};
  io_joints_command_t pending_{};
  bool pending_fresh_ = false;
  bool pending_in_sequence_ = false;                 // the session's own command (else a vent obeyed out of sequence)
  ValveCommand commanded_ = ValveCommand::vented();  // the session's latest, before the limits
  std::int32_t limit_bits_ = 0;                      // the limits acting now
  std::int32_t limit_bits_since_state_ = 0;          // and those that acted since the last state
  std::int64_t binding_ = 0;                         // offered while free, in force while serving
  std::int64_t session_ = 0;                         // bound now
  std::int64_t last_seq_ = 0;
  std::int64_t applied_seq_ = 0;
  std::int32_t fault_bits_ = io_state_t::FAULT_NO_SESSION;
  // Tripped: the session dropped for a reason, named in the next states (docs/lcm-protocol.md).
  std::int64_t tripped_session_ = 0, tripped_command_seq_ = 0;
  int tripped_states_left_ = 0;
  bool reported_[static_cast<int>(Notice::kCount)] = {};  // one log line per kind per binding
  double origin_s_ = -1.0;
  double device_time_s_ = 0.0;
  double last_command_s_ = 0.0;
  double next_publish_s_ = 0.0;
  std::int64_t state_seq_ = 0;
  io_joints_state_t state_{};
  SensorReading last_reading_{};  // the last state's
  bool reading_taken_ = false;
  double next_limits_s_ = 0.0;
  io_rig_limits_t limits_{};
  std::vector<std::uint8_t> buffer_;

  ReceiveCounters counters_;
  std::atomic<std::uint64_t> states_published_{0}, sessions_served_{0}, timeouts_{0}, missed_periods_{0};
  std::atomic<std::uint64_t> not_addressed_{0}, vents_out_of_sequence_{0}, pressure_trips_{0}, angle_trips_{0};
  std::atomic<std::int64_t> serving_{0}, binding_shown_{0};
};

}  // namespace bellows
