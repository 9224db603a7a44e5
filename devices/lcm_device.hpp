// A rig driven over LCM (`bellows run --device lcm`), the engine's side of docs/lcm-protocol.md.
//
// Two threads touch it, through lock-free latest-value buffers only:
// - the engine thread (Device methods): write_valves()/vent() leave the desired valve state in the
//   outbox, read_sensors() takes the latest state from the inbox. Neither calls LCM.
// - the I/O thread (LcmEndpoint methods, run by an LcmIoThread that owns the LCM handle): publishes
//   each new valve state as an io_command_t with the next sequence number, and checks every
//   io_state_t received before handing it to the engine.
//
// Joints: an arm of one joint speaks io_command_t / io_state_t, one of several io_joints_command_t /
// io_joints_state_t (devices/lcm_io_messages). A state of a rig of another joint count is counted
// (`other_joints`) and never bound to; diagnosis() says so in one line.
//
// Binding: commands are addressed to one rig (`rig_id`) and echo its binding offer. Until a free
// rig's offer is seen they are addressed to none (rig_id 0) and every rig ignores them; the engine
// vents until a rig serves it, so the command that binds is a vent. A new offer (the rig restarted,
// or dropped the session) is taken only while the engine is venting. With a key, states whose MAC
// does not match are counted and ignored, and every command is signed.
//
// The reading's time_s is the I/O thread's monotonic clock when the last valid state of this
// session arrived (not the rig's clock, which restarts with the rig). A tick without one is a tick
// without a reading: the engine holds the valves closed and rides through; [safety] stale_ticks of
// them end the trial, and explain_silence() names why: `link-lost` when the rig addressed has sent
// nothing at all for that long, `foreign-sender` when another sender is commanding the rig, else
// `sensor-stale` (states arrive but none is usable). A state of this session carrying the rig's own
// trip (its angle range, its pressure ceiling, its command timeout, a sensor or valve fault) is no
// reading but a fault with the rig's reason and joint (take_fault()): `rig-limit`, `rig-timeout`,
// `rig-fault`; a `rig-timeout` says from this host's own send times whether it sent nothing for the
// rig's timeout (it stalled) or sent and the network lost them. A rig that trips keeps naming the
// session it dropped in its states for a while (docs/lcm-protocol.md, "the tripped state"), so the
// reason reaches the engine it served (the faults' words: devices/lcm_device_faults.cpp). Only fresh
// valve states are published: if the engine thread stops, the commands stop and the rig vents on its
// own.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "devices/lcm_codec.hpp"
#include "devices/lcm_io_messages.hpp"
#include "devices/io_turn_watch.hpp"
#include "devices/lcm_io_thread.hpp"
#include "devices/round_trip_stats.hpp"
#include "devices/tick_phase_lock.hpp"
#include "engine/control/device.hpp"
#include "engine/rt/latest_value.hpp"

namespace bellows {

struct LcmDeviceStats {
  std::int64_t session_id = 0;
  std::int64_t rig_id = 0;                // the rig served by, 0: none yet
  ReceiveCounts states;                   // io_state_t received, by outcome
  std::uint64_t rig_fault_states = 0;     // states of this session carrying rig fault bits
  std::int32_t last_fault_bits = 0;       // of the last state of this session (0 again once a new binding serves it)
  std::int32_t last_trip_bits = 0;        // of the last state that reported a trip of the rig (its reasons)
  std::int64_t last_foreign_session = 0;  // the session a rig served when it was not this one
  int joints = 1;                         // this arm's
  int last_other_joints = 0;              // a rig's joint count when it was not this arm's, 0: none heard
  std::uint64_t commands_sent = 0;
  std::uint64_t vent_commands_sent = 0;  // of which armed = false
  std::uint64_t publish_errors = 0;
  double longest_command_gap_s = 0.0;   // between two of the engine's commands sent (a rig times out past its timeout)
  std::uint64_t commands_not_ours = 0;  // states of this session echoing a command it never sent
  std::int64_t rig_foreign_commands = 0;  // what the rig says it refused (its last state)
  std::int64_t rig_unauthenticated_commands = 0;
  bool keyed = false;  // [lcm] key_file set
};

/// What the rig addressed says it enforces by itself (its io_rig_limits_t), for `bellows rig check`.
struct RigAnnouncedLimits {
  double received_s = -1.0;  // the I/O thread's clock (monotonic_s()); < 0: none received
  std::int64_t rig_id = 0;
  int joints = 0;
  double period_s = 0.0, command_timeout_s = 0.0, pressure_ceiling_bar = 0.0, angle_limit_rad = 0.0;
};

/// A state of the rig addressed as it arrived, whatever its session (`bellows rig check` watches
/// the rig's trips with it).
struct RigStateSeen {
  double received_s = -1.0;  // the I/O thread's clock; < 0: none
  std::int64_t session_id = 0, binding = 0, command_seq = 0;
  std::int32_t fault_bits = 0;
  SensorReading reading{};  // its sensor values (time_s the rig's)
};

class LcmDevice final : public Device, public LcmEndpoint {
 public:
  /// `session_id`: nonzero, unique per run (random_session_id()).
  /// `rig_silence_s`: a rig silent this long is gone ([lcm] rig_timeout_s): another may be bound.
  /// `joints`: the arm's joint count, 1..kMaxJoints (InputError otherwise), the rig's must match.
  explicit LcmDevice(std::int64_t session_id, LcmKey key = {}, double rig_silence_s = 0.05, int joints = 1);

  /// A random nonzero session id.
  static std::int64_t random_session_id() { return random_nonzero_id(); }

  // ---- Device: engine thread only (one writer of the outbox at a time: the engine thread while
  // the loop runs, the thread that stopped it afterwards) ----
  SensorReading read_sensors() override;
  void write_valves(const ValveCommand& command) override;
  void vent() override;
  /// A real rig's time passes on its own: nothing to do. In lockstep, waits for the rig's answer.
  void advance(double dt_s) override;
  /// In lockstep the rig's time waits for the engine's commands: a late tick harms nothing physical.
  bool time_follows_ticks() const override { return lockstep_; }
  const char* name() const override { return "lcm"; }
  bool take_fault(DeviceFault& fault) override;
  void explain_silence(double silent_s, DeviceFault& fault) const override;

  /// Lockstep (`run --clock lockstep`, against a stepped simulator, `io-sim --stepped`): the engine's
  /// ticks follow the rig's answers, so a stall of either process delays the trial but changes none
  /// of its numbers. advance() returns once a state echoing this tick's command has reached the
  /// inbox, or after `answer_timeout_s` (the next tick then has no fresh reading: the stale guard
  /// counts it as any other); while no rig serves this engine, it waits one tick, the rig's pace of
  /// offers. No real rig waits for its commands: a real rig runs on the wall clock.
  /// Before the engine is made (it reads time_follows_ticks() once); engine thread.
  void set_lockstep(double answer_timeout_s);
  /// On the wall clock, the engine's ticks lock to the phase of the rig's states (devices/
  /// tick_phase_lock; not in lockstep, where the answers pace the ticks). Before the engine ticks.
  void set_tick_phase_lock(const TickPhaseLock::Parameters& parameters) { phase_lock_ = TickPhaseLock(parameters); }
  double tick_shift_s() override;

  // ---- LcmEndpoint: I/O thread only ----
  void attach(lcm::LCM& bus) override;
  void on_message(const char* channel, const void* data, std::size_t size) override;
  double service(lcm::LCM* bus, double now_s) override;
  void finish(lcm::LCM* bus, double now_s) override;

  // ---- any thread ----
  std::int64_t session_id() const { return session_id_; }
  int joints() const { return joints_; }
  /// Whether a valid state of this session has arrived: a rig has served this engine.
  bool connected() const { return connected_.load(std::memory_order_acquire); }
  /// When (the I/O thread's clock, monotonic_s()) the last valid state was handed to the engine.
  double last_state_s() const { return last_state_s_.load(std::memory_order_relaxed); }
  LcmDeviceStats stats() const;
  /// The phase lock's average lead (ms from a state's handover to the engine's read; -1: none yet)
  /// and the sum of its shifts (ms); any thread.
  double tick_phase_lead_ms() const { return phase_lead_ms_.load(std::memory_order_relaxed); }
  double tick_phase_shifted_ms() const { return phase_shifted_ms_.load(std::memory_order_relaxed); }
  /// The link: round trip from a command to the first state echoing it, rejected messages and
  /// rig fault states as errors, engine reads without a new state as stale; connected while a
  /// valid state arrived within the last kLinkAlive_s.
  DeviceHealth health() const override;
  /// Evidence that someone else is on this rig's bus, for people: "another sender is commanding
  /// this rig: ..." or "" when there is none.
  std::string diagnosis() const;

  // ---- `bellows rig check` (one thread, not the engine's) ----
  /// The limits the rig addressed announced last; false while none arrived.
  bool read_announced_limits(RigAnnouncedLimits& out) { return limits_seen_.read(out) || out.received_s >= 0.0; }
  /// Holds back every command while `hold` (the engine keeps ticking): the rig hears nothing, as
  /// when an engine stalls, so that its own command timeout can be seen to act. While held, the
  /// first state of the rig addressed carrying a trip bit (command timeout, angle range) is kept.
  void hold_commands(bool hold) { hold_commands_.store(hold, std::memory_order_release); }
  /// Whether the I/O thread holds them now (it acts on hold_commands() at its next turn).
  bool commands_held() const { return commands_held_.load(std::memory_order_acquire); }
  /// When the last command went out (the I/O thread's clock, -1: none yet) and its seq.
  double last_command_sent_s() const { return last_sent_s_.load(std::memory_order_acquire); }
  std::int64_t last_command_seq() const { return last_sent_seq_.load(std::memory_order_acquire); }
  /// The first trip state seen since the commands were held (false: none yet).
  bool read_trip_seen(RigStateSeen& out) { return trip_seen_.read(out) || out.received_s >= 0.0; }
  /// The latest state of the rig addressed, whatever its session.
  bool read_rig_state(RigStateSeen& out) { return rig_seen_.read(out) || out.received_s >= 0.0; }
  /// Announcements of limits ignored: undecodable, unauthenticated, invalid, or of another rig.
  std::uint64_t limits_ignored() const { return limits_ignored_.load(std::memory_order_relaxed); }

 private:
  struct Outgoing {
    ValveCommand valves{};
    bool armed = false;
    std::uint64_t generation = 0;  // the engine's count of valve states written, this one included
  };

  void publish(lcm::LCM& bus, const Outgoing& outgoing, double now_s);
  void on_limits(const void* data, std::size_t size);
  /// A state of this session with trip bits: the rig's reason, for the engine (once per trip).
  /// `offered`: the rig's new offer (session 0) that dropped this session, its reasons in its bits.
  void report_trip(const io_joints_state_t& state, bool offered);
  /// A command timeout the rig reported (report_trip()), named at the next service() turn, when this
  /// thread's clock is fresh: whether this host stopped sending (it stalled) or its commands were lost.
  void name_command_timeout(double now_s);
  /// The longest this host went without publishing, from the command the rig last applied until `now_s`
  /// (NAN: that command is no longer in sent_s_).
  double longest_send_gap_s(std::int64_t applied_seq, double now_s) const;

  const std::int64_t session_id_;
  const LcmKey key_;
  const double rig_silence_s_;
  const int joints_;
  LatestValue<Outgoing> outbox_;  // engine -> I/O
  struct Handover {
    SensorReading reading{};
    double handed_over_s = 0.0;  // monotonic_s() when the I/O thread put it in the inbox
  };
  LatestValue<Handover> inbox_;     // I/O -> engine
  LatestValue<DeviceFault> trips_;  // I/O -> engine: the rig's own trips
  Handover reading_{};              // engine thread's copy
  TickPhaseLock phase_lock_;        // engine thread; step 0 (no lock) until set_tick_phase_lock()
  std::uint64_t written_ = 0;       // engine thread: valve states written to the outbox
  bool lockstep_ = false;           // set_lockstep(), before the engine ticks
  double answer_timeout_s_ = 0.0;

  // I/O thread state.
  io_joints_state_t received_{};
  SensorReading pending_{};
  bool pending_fresh_ = false;
  std::int64_t rig_id_ = 0;              // the rig addressed, 0: none yet
  std::int64_t binding_ = 0;             // its offer this session answers
  bool bound_ = false;                   // its last state served this session
  double now_s_ = 0.0;                   // of the last service()
  double last_rig_state_s_ = 0.0;        // when the rig addressed last sent anything valid
  std::int32_t reported_trip_bits_ = 0;  // trip bits of this binding already reported
  std::int64_t last_state_seq_ = 0;
  std::int64_t last_echoed_seq_ = 0;
  double last_rig_time_s_ = 0.0;
  double last_reading_time_s_ = 0.0;
  double origin_s_ = -1.0;
  std::int64_t seq_ = 0;
  bool last_armed_ = false;
  io_joints_command_t command_{};
  std::vector<std::uint8_t> buffer_;
  // Lockstep: the generation of the valve state the last command carried, its seq, and the
  // generation a state echoing it answers (handed over with that state's reading).
  std::uint64_t awaited_generation_ = 0, answer_generation_ = 0;
  std::int64_t awaited_seq_ = 0;
  io_rig_limits_t limits_received_{};
  double announced_timeout_s_ = 0.0;             // the rig addressed's command timeout (0: not announced)
  std::int64_t timeout_applied_seq_ = -1;        // a reported command timeout to name: the last command applied
  bool hold_seen_ = false;                       // the I/O thread has acted on hold_commands(true)
  bool trip_kept_ = false;                       // the first trip since then is in trip_seen_
  LatestValue<RigAnnouncedLimits> limits_seen_;  // I/O -> rig check
  LatestValue<RigStateSeen> trip_seen_, rig_seen_;
  std::atomic<bool> hold_commands_{false}, commands_held_{false};
  std::atomic<double> last_sent_s_{-1.0};
  std::atomic<std::int64_t> last_sent_seq_{0};
  std::atomic<std::uint64_t> limits_ignored_{0};

  ReceiveCounters counters_;
  std::atomic<bool> connected_{false};
  std::atomic<bool> serving_us_{false};     // the rig addressed serves this session (bound_, shown)
  std::atomic<std::uint64_t> answered_{0};  // generation whose answer reached the inbox
  std::atomic<double> last_state_s_{-1.0};
  IoTurnWatch io_turns_;                        // the I/O thread's service() turns, on monotonic_s()
  std::atomic<double> rig_silent_s_{INFINITY};  // since the addressed rig's last valid state of any kind (I/O clock)
  std::atomic<std::int64_t> stats_rig_id_{0};
  std::atomic<std::uint64_t> rig_fault_states_{0};
  std::atomic<std::int32_t> last_fault_bits_{0};
  std::atomic<std::int32_t> last_trip_bits_{0};
  std::atomic<std::int64_t> last_foreign_session_{0};
  std::atomic<int> last_other_joints_{0};
  std::atomic<std::uint64_t> commands_sent_{0};
  std::atomic<std::uint64_t> vent_commands_sent_{0};
  std::atomic<std::uint64_t> publish_errors_{0};
  double last_engine_command_s_ = NAN;              // I/O thread: the last engine command sent (NAN: none, or held)
  std::atomic<double> longest_command_gap_s_{0.0};  // between two of them (stats())
  // health(): when each recent command went out (I/O thread), round trips, stale engine reads.
  std::array<double, 64> sent_s_{};
  RoundTripStats round_trips_;
  std::atomic<std::uint64_t> stale_reads_{0};
  std::atomic<double> phase_lead_ms_{-1.0}, phase_shifted_ms_{0.0};
  std::atomic<std::uint64_t> commands_not_ours_{0};
  std::atomic<std::int64_t> rig_foreign_commands_{0}, rig_unauthenticated_commands_{0};
};

}  // namespace bellows
