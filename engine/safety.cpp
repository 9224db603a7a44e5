#include "engine/safety.hpp"

#include <cmath>
#include <numbers>

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
  const double pressures[] = {r.chamber_bar[0], r.chamber_bar[1], r.supply_bar};
  if (!std::isfinite(r.angle_rad)) return FaultCode::kSensorNotANumber;
  for (double p : pressures) {
    if (!std::isfinite(p)) return FaultCode::kSensorNotANumber;
  }
  if (std::abs(r.angle_rad) > limits.sensor_max_angle_deg * kDeg) return FaultCode::kSensorOutOfRange;
  for (double p : pressures) {
    if (p < limits.sensor_min_bar || p > limits.sensor_max_bar) return FaultCode::kSensorOutOfRange;
  }
  if (std::abs(r.angle_rad) > limits.angle_limit_deg * kDeg) return FaultCode::kAngleLimit;
  for (int i = 0; i < kActuatorCount; ++i) {
    if (r.chamber_bar[i] > in.p_max_bar + limits.pressure_margin_bar) return FaultCode::kOverpressure;
  }
  if (r.supply_bar < limits.supply_min_bar) return FaultCode::kSupplyLow;
  if (in.missed_streak >= limits.missed_deadline_streak) return FaultCode::kMissedDeadlines;
  if (limits.heartbeat_timeout_s > 0.0 && in.heartbeat_age_s > limits.heartbeat_timeout_s) return FaultCode::kHeartbeatLost;
  return FaultCode::kNone;
}

}  // namespace bellows
