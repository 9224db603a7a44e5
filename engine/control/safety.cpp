#include "engine/control/safety.hpp"

#include <cmath>
#include <numbers>
#include <span>

namespace bellows {

const char* fault_name(FaultCode code) {
  switch (code) {
    case FaultCode::kNone: return "none";
    case FaultCode::kEmergencyStop: return "emergency-stop";
    case FaultCode::kAngleLimit: return "angle-limit";
    case FaultCode::kOverpressure: return "overpressure";
    case FaultCode::kSupplyLow: return "supply-low";
    case FaultCode::kSensorNotANumber: return "sensor-nan";
    case FaultCode::kSensorOutOfRange: return "sensor-range";
    case FaultCode::kSensorStale: return "sensor-stale";
    case FaultCode::kMissedDeadlines: return "missed-deadlines";
    case FaultCode::kHeartbeatLost: return "heartbeat-lost";
  }
  return "unknown";
}

const char* fault_message(FaultCode code) {
  switch (code) {
    case FaultCode::kNone: return "no fault";
    case FaultCode::kEmergencyStop: return "emergency stop requested by the operator";
    case FaultCode::kAngleLimit: return "the arm went beyond its angle limit";
    case FaultCode::kOverpressure: return "a chamber pressure exceeded p_max plus the safety margin";
    case FaultCode::kSupplyLow: return "the supply pressure is too low to control the arm";
    case FaultCode::kSensorNotANumber: return "a sensor reading is not a number";
    case FaultCode::kSensorOutOfRange: return "a sensor reading is outside its plausible range";
    case FaultCode::kSensorStale: return "the sensors stopped updating";
    case FaultCode::kMissedDeadlines:
      return "the control loop missed [safety] missed_deadline_streak deadlines in a row: lighten the machine's "
             "load, run with --rt enforce (real-time scheduling), or raise [safety] missed_deadline_streak";
    case FaultCode::kHeartbeatLost: return "the console stopped responding";
  }
  return "unknown fault";
}

FaultCode check_guards(const SensorReading& r, const GuardInputs& in, const SafetyParameters& limits) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  if (in.stale_count >= limits.stale_ticks) return FaultCode::kSensorStale;
  // A reading for another number of joints than the engine drives cannot be checked joint by joint.
  if (r.joint_count != in.joint_count || !valid_joint_count(r.joint_count)) return FaultCode::kSensorOutOfRange;
  const std::span<const JointReading> joints(r.joint.data(), static_cast<std::size_t>(r.joint_count));
  // Each kind of fault is looked for on every joint before the next kind: the most basic one wins,
  // whichever joint shows it (with one joint, the order of the single-joint guards).
  for (const JointReading& j : joints) {
    if (!std::isfinite(j.angle_rad)) return FaultCode::kSensorNotANumber;
  }
  for (const JointReading& j : joints) {
    for (double p : j.chamber_bar) {
      if (!std::isfinite(p)) return FaultCode::kSensorNotANumber;
    }
  }
  if (!std::isfinite(r.supply_bar)) return FaultCode::kSensorNotANumber;
  for (const JointReading& j : joints) {
    if (std::abs(j.angle_rad) > limits.sensor_max_angle_deg * kDeg) return FaultCode::kSensorOutOfRange;
  }
  const auto implausible = [&](double p) { return p < limits.sensor_min_bar || p > limits.sensor_max_bar; };
  for (const JointReading& j : joints) {
    for (double p : j.chamber_bar) {
      if (implausible(p)) return FaultCode::kSensorOutOfRange;
    }
  }
  if (implausible(r.supply_bar)) return FaultCode::kSensorOutOfRange;
  for (const JointReading& j : joints) {
    if (std::abs(j.angle_rad) > limits.angle_limit_deg * kDeg) return FaultCode::kAngleLimit;
  }
  for (const JointReading& j : joints) {
    for (double p : j.chamber_bar) {
      if (p > in.p_max_bar + limits.pressure_margin_bar) return FaultCode::kOverpressure;
    }
  }
  if (r.supply_bar < limits.supply_min_bar) return FaultCode::kSupplyLow;
  if (in.missed_streak >= limits.missed_deadline_streak) return FaultCode::kMissedDeadlines;
  if (limits.heartbeat_timeout_s > 0.0 && in.heartbeat_age_s > limits.heartbeat_timeout_s) return FaultCode::kHeartbeatLost;
  return FaultCode::kNone;
}

}  // namespace bellows
