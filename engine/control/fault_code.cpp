#include "engine/control/fault_code.hpp"

#include <cstdarg>
#include <cstdio>

namespace bellows {

const char* fault_name(FaultCode code) {
  switch (code) {
    case FaultCode::kNone:
      return "none";
    case FaultCode::kEmergencyStop:
      return "emergency-stop";
    case FaultCode::kAngleLimit:
      return "angle-limit";
    case FaultCode::kOverpressure:
      return "overpressure";
    case FaultCode::kSupplyLow:
      return "supply-low";
    case FaultCode::kSensorNotANumber:
      return "sensor-nan";
    case FaultCode::kSensorOutOfRange:
      return "sensor-range";
    case FaultCode::kSensorStale:
      return "sensor-stale";
    case FaultCode::kMissedDeadlines:
      return "missed-deadlines";
    case FaultCode::kHeartbeatLost:
      return "heartbeat-lost";
    case FaultCode::kLinkLost:
      return "link-lost";
    case FaultCode::kRigLimit:
      return "rig-limit";
    case FaultCode::kRigTimeout:
      return "rig-timeout";
    case FaultCode::kRigFault:
      return "rig-fault";
    case FaultCode::kDeviceError:
      return "device-error";
    case FaultCode::kForeignSender:
      return "foreign-sender";
    case FaultCode::kRigUnavailable:
      return "rig-unavailable";
  }
  return "unknown";
}

const char* fault_message(FaultCode code) {
  switch (code) {
    case FaultCode::kNone:
      return "no fault";
    case FaultCode::kEmergencyStop:
      return "emergency stop requested by the operator";
    case FaultCode::kAngleLimit:
      return "the arm went beyond its angle limit";
    case FaultCode::kOverpressure:
      return "a chamber pressure exceeded p_max plus the safety margin";
    case FaultCode::kSupplyLow:
      return "the supply pressure is too low to control the arm";
    case FaultCode::kSensorNotANumber:
      return "a sensor reading is not a number";
    case FaultCode::kSensorOutOfRange:
      return "a sensor reading is outside its plausible range";
    case FaultCode::kSensorStale:
      return "the sensors stopped updating";
    case FaultCode::kMissedDeadlines:
      return "the control loop missed [safety] missed_deadline_streak deadlines in a row: lighten the machine's "
             "load, run with --rt enforce (real-time scheduling), or raise [safety] missed_deadline_streak";
    case FaultCode::kHeartbeatLost:
      return "the console stopped responding";
    case FaultCode::kLinkLost:
      return "the link to the rig stopped answering: check the rig's process, cable and network";
    case FaultCode::kRigLimit:
      return "the rig's own limit tripped (its angle range or pressure ceiling) and vented it";
    case FaultCode::kRigTimeout:
      return "the rig vented by itself: the engine's commands stopped reaching it";
    case FaultCode::kRigFault:
      return "the rig cannot read its sensors or drive its valves";
    case FaultCode::kDeviceError:
      return "the device refused a request";
    case FaultCode::kForeignSender:
      return "another sender is commanding this rig or publishing its states";
    case FaultCode::kRigUnavailable:
      return "no rig served this run";
  }
  return "unknown fault";
}

void DeviceFault::set(FaultCode fault, int fault_joint, const char* format, ...) {
  code = fault;
  joint = fault_joint;
  va_list args;
  va_start(args, format);
  std::vsnprintf(text.data(), text.size(), format, args);
  va_end(args);
}

}  // namespace bellows
