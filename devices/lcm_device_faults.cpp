// LcmDevice's faults, named for what happened (docs/lcm-protocol.md, the fault table): the rig's own
// trips as its states report them (report_trip(), on the I/O thread), a command timeout judged by this
// host's own send times (name_command_timeout(): this host silent, or the network), and a silence the
// engine's stale limit found (explain_silence(), on the engine thread). The rest of the device is in
// devices/lcm_device.cpp.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "devices/lcm_device.hpp"

namespace bellows {

void LcmDevice::report_trip(const io_joints_state_t& s, bool offered) {
  constexpr std::int32_t kAngle = io_state_t::FAULT_ANGLE_LIMIT, kPressure = io_state_t::FAULT_PRESSURE_LIMIT,
                         kTimeout = io_state_t::FAULT_COMMAND_TIMEOUT, kSensor = io_state_t::FAULT_SENSOR,
                         kValve = io_state_t::FAULT_VALVE, kNoSession = io_state_t::FAULT_NO_SESSION;
  // An offer always carries NO_SESSION: only its reasons count there.
  const std::int32_t trip =
      s.fault_bits & (kAngle | kPressure | kTimeout | kSensor | kValve | (offered ? 0 : kNoSession));
  if ((trip & ~reported_trip_bits_) == 0) return;  // nothing new since this binding's last report
  reported_trip_bits_ |= trip;
  const int joints = std::clamp<int>(s.joint_count, 1, kMaxJoints);
  const auto at = [](int j) { return static_cast<std::size_t>(j); };
  DeviceFault fault;
  const unsigned long long rig = static_cast<unsigned long long>(s.rig_id);
  if ((trip & kAngle) != 0) {  // the joint furthest out is the one the rig stopped
    int joint = 0;
    for (int j = 1; j < joints; ++j) {
      if (!(std::abs(s.angle_rad[at(j)]) <= std::abs(s.angle_rad[at(joint)]))) joint = j;
    }
    fault.set(
        FaultCode::kRigLimit, joint,
        "the rig stopped joint %d at %.1f deg beyond its angle range ([lcm] rig_angle_limit_deg): check the chamber "
        "wiring (bellows rig check --device lcm pulses each chamber)",
        joint + 1, s.angle_rad[at(joint)] * 180.0 / std::numbers::pi);
  } else if ((trip & kPressure) != 0) {
    int joint = 0, chamber = 0;
    for (int j = 0; j < joints; ++j) {
      for (int c = 0; c < kActuatorCount; ++c) {
        if (s.chamber_bar[at(j)][c] > s.chamber_bar[at(joint)][chamber]) joint = j, chamber = c;
      }
    }
    fault.set(
        FaultCode::kRigLimit, joint,
        "the rig vented chamber %c of joint %d at %.3f bar above its pressure ceiling ([controller] p_max_bar + [lcm] "
        "rig_pressure_margin_bar): check that valve and the rig's ceiling",
        chamber == 0 ? 'A' : 'B', joint + 1, s.chamber_bar[at(joint)][chamber]);
  } else if ((trip & kTimeout) != 0) {
    // Named at the next turn (name_command_timeout()): after a stall this state is handled before the
    // clock is read again.
    last_trip_bits_.store(s.fault_bits, std::memory_order_relaxed);
    timeout_applied_seq_ = s.command_seq > 0 ? s.command_seq : last_echoed_seq_;  // an offer carries 0
    return;
  } else if ((trip & (kSensor | kValve)) != 0) {
    fault.set(FaultCode::kRigFault, -1, "the LCM rig %llx reports %s (fault_bits %d): check its driver's log", rig,
              (trip & kSensor) != 0 ? "it cannot read its sensors" : "it cannot drive its valves", s.fault_bits);
  } else {  // NO_SESSION alone, naming this session: the rig ended it without a reason (shut down, restarted)
    fault.set(FaultCode::kRigFault, -1,
              "the LCM rig %llx ended this session without a reason (it shut down or restarted?)", rig);
  }
  last_trip_bits_.store(s.fault_bits, std::memory_order_relaxed);
  trips_.write(fault);
}

double LcmDevice::longest_send_gap_s(std::int64_t applied_seq, double now_s) const {
  const auto sent_at = [this](std::int64_t seq) { return sent_s_[static_cast<std::size_t>(seq) % sent_s_.size()]; };
  if (applied_seq <= 0 || applied_seq > seq_ || seq_ - applied_seq >= static_cast<std::int64_t>(sent_s_.size())) {
    return NAN;
  }
  double longest_s = now_s - sent_at(seq_);
  for (std::int64_t seq = applied_seq; seq < seq_; ++seq) {
    longest_s = std::max(longest_s, sent_at(seq + 1) - sent_at(seq));
  }
  return longest_s;
}

void LcmDevice::name_command_timeout(double now_s) {
  const unsigned long long rig = static_cast<unsigned long long>(rig_id_);
  const double timeout_s = announced_timeout_s_ > 0.0 ? announced_timeout_s_ : rig_silence_s_;
  const double gap_s = longest_send_gap_s(timeout_applied_seq_, now_s);
  timeout_applied_seq_ = -1;
  DeviceFault fault;
  if (hold_seen_) {  // the rig check's provoked timeout (hold_commands())
    fault.set(FaultCode::kRigTimeout, -1,
              "the LCM rig %llx vented, as provoked: this host held its commands back for %.0f ms, longer than its "
              "%.0f ms timeout",
              rig, gap_s * 1e3, timeout_s * 1e3);
  } else if (gap_s >= timeout_s) {  // nothing left this host for the rig's whole timeout: not the network
    fault.set(FaultCode::kRigTimeout, -1,
              "the LCM rig %llx vented: this host sent it no command for %.0f ms, longer than its %.0f ms timeout "
              "(its engine or LCM I/O thread did not run: lighten the load, --rt enforce)",
              rig, gap_s * 1e3, timeout_s * 1e3);
  } else if (std::isfinite(gap_s)) {
    fault.set(FaultCode::kRigTimeout, -1,
              "the LCM rig %llx heard no command for its %.0f ms timeout and vented, though this host sent one at "
              "least every %.0f ms: check the network from this host to the rig",
              rig, timeout_s * 1e3, gap_s * 1e3);
  } else {
    fault.set(FaultCode::kRigTimeout, -1,
              "the LCM rig %llx heard no command of this session for its %.0f ms timeout and vented itself: check the "
              "network from this host to the rig",
              rig, timeout_s * 1e3);
  }
  trips_.write(fault);
}

bool LcmDevice::take_fault(DeviceFault& fault) { return trips_.read(fault); }

void LcmDevice::explain_silence(double silent_s, DeviceFault& fault) const {
  constexpr auto relaxed = std::memory_order_relaxed;
  const unsigned long long rig = static_cast<unsigned long long>(stats_rig_id_.load(relaxed));
  const std::uint64_t not_ours = commands_not_ours_.load(relaxed);
  if (not_ours > 0) {
    fault.set(FaultCode::kForeignSender, -1,
              "another sender is commanding this rig: it applied commands this session never sent (%llu states)",
              static_cast<unsigned long long>(not_ours));
    return;
  }
  if (const std::uint64_t forged = counters_.snapshot().unauthenticated; forged > 0) {
    fault.set(FaultCode::kForeignSender, -1,
              "another sender publishes rig states on this bus: %llu failed authentication (or the rig has another "
              "[lcm] key_file)",
              static_cast<unsigned long long>(forged));
    return;
  }
  // The I/O thread's last turn: if it did not run, this host stalled, not the link. A turn waits at most
  // for the next outbox poll, well under half a stale limit.
  if (const double io_idle_s = io_turns_.held_off_s(monotonic_s(), silent_s, 0.0); !std::isnan(io_idle_s)) {
    fault.set(FaultCode::kLinkLost, -1,
              "no state of the LCM rig %llx reached the engine for %.0f ms: this host's LCM I/O thread did not run for "
              "%.0f ms (the machine stalled: lighten its load, --rt enforce)",
              rig, silent_s * 1e3, io_idle_s * 1e3);
    return;
  }
  const double silence_s = rig_silent_s_.load(relaxed);
  if (silence_s >= 0.5 * silent_s) {  // nothing at all arrived in the window (give or take the I/O thread's turn)
    if (std::isfinite(silence_s)) {
      fault.set(FaultCode::kLinkLost, -1,
                "the LCM rig %llx has been silent for %.0f ms (no state on "
                "BELLOWS_IO_STATE): check that the rig runs and the network to it",
                rig, silence_s * 1e3);
    } else {
      fault.set(FaultCode::kLinkLost, -1,
                "no LCM rig has been heard on BELLOWS_IO_STATE: check that the rig runs and the network to it");
    }
    return;
  }
  fault.set(
      FaultCode::kSensorStale, -1,
      "the LCM rig %llx answers, but none of its states for %.0f ms was a usable reading (frozen time or rejected: "
      "see lcm.rig.states)",
      rig, silent_s * 1e3);
}

}  // namespace bellows
