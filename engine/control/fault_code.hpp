// The one fault vocabulary of bellows: every fault the engine latches, whichever device or guard
// found it, and the two a run reports before the engine drives anything. The console's fault
// screen, the session's events, the JSON report and the LCM telemetry and events carry these
// names and numbers (docs/lcm-protocol.md, "Faults", lists them).
//
// A fault found by a device (the rig's own trip, a link that stopped answering, a request the
// device refused) comes with its own sentence naming the cause and the part to look at: a
// FaultDetail, fixed size, so that the tick that reports it allocates nothing.
#pragma once

#include <array>
#include <cstdint>

namespace bellows {

/// Numbers are part of the LCM protocol (telemetry_t.fault, engine_event_t.fault) and of the
/// session's black box: append, never renumber.
enum class FaultCode : std::uint8_t {
  kNone,
  kEmergencyStop,
  kAngleLimit,
  kOverpressure,
  kSupplyLow,
  kSensorNotANumber,
  kSensorOutOfRange,
  kSensorStale,  // readings arrive but their values are frozen (a sensor's time did not advance)
  kMissedDeadlines,
  kHeartbeatLost,
  kLinkLost,        // the link to the rig stopped answering: nothing at all arrived for the stale limit
  kRigLimit,        // the rig's own limit tripped (its angle range, its pressure ceiling)
  kRigTimeout,      // the rig vented by itself: the engine's commands stopped reaching it
  kRigFault,        // the rig says it cannot read its sensors or drive its valves
  kDeviceError,     // the device refused a request (e.g. a Modbus exception of a T7)
  kForeignSender,   // another sender is commanding the rig, or publishes states as it
  kRigUnavailable,  // no rig served this run (before arming: a run's failure, never latched by a tick)
};
inline constexpr FaultCode kLastFaultCode = FaultCode::kRigUnavailable;

/// A short stable name ("overpressure") and a sentence for the operator.
const char* fault_name(FaultCode code);
const char* fault_message(FaultCode code);

/// One sentence, at most kFaultDetailChars - 1 characters, naming the cause and what to check.
inline constexpr std::size_t kFaultDetailChars = 192;
using FaultDetail = std::array<char, kFaultDetailChars>;

/// A fault a device reports to the engine, with its words.
struct DeviceFault {
  FaultCode code = FaultCode::kNone;
  int joint = -1;      // the joint (0-based) it concerns, -1: no joint's
  FaultDetail text{};  // e.g. "the rig stopped joint 1 at -100 deg beyond its range 100 deg: check the chamber wiring"

  /// Sets code, joint and the text from a printf format (truncated to fit; no allocation).
  void set(FaultCode fault, int fault_joint, const char* format, ...) __attribute__((format(printf, 4, 5)));
};

}  // namespace bellows
