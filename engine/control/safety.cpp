#include "engine/control/safety.hpp"

#include <cmath>
#include <numbers>

namespace bellows {

GuardFault find_guard_fault(const SensorReading& r, const GuardInputs& in, const SafetyParameters& limits) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  if (in.stale_count >= limits.stale_ticks) return {FaultCode::kSensorStale, -1};
  // A reading for another number of joints than the engine drives cannot be checked joint by joint.
  if (r.joint_count != in.joint_count || !valid_joint_count(r.joint_count)) return {FaultCode::kSensorOutOfRange, -1};
  const int joints = r.joint_count;
  const auto joint = [&r](int j) -> const JointReading& { return r.joint[static_cast<std::size_t>(j)]; };
  // Each kind of fault is looked for on every joint before the next kind: the most basic one wins,
  // whichever joint shows it (with one joint, the order of the single-joint guards).
  for (int j = 0; j < joints; ++j) {
    if (!std::isfinite(joint(j).angle_rad)) return {FaultCode::kSensorNotANumber, j};
  }
  for (int j = 0; j < joints; ++j) {
    for (double p : joint(j).chamber_bar) {
      if (!std::isfinite(p)) return {FaultCode::kSensorNotANumber, j};
    }
  }
  if (!std::isfinite(r.supply_bar)) return {FaultCode::kSensorNotANumber, -1};
  for (int j = 0; j < joints; ++j) {
    if (std::abs(joint(j).angle_rad) > limits.sensor_max_angle_deg * kDeg) return {FaultCode::kSensorOutOfRange, j};
  }
  const auto implausible = [&](double p) { return p < limits.sensor_min_bar || p > limits.sensor_max_bar; };
  for (int j = 0; j < joints; ++j) {
    for (double p : joint(j).chamber_bar) {
      if (implausible(p)) return {FaultCode::kSensorOutOfRange, j};
    }
  }
  if (implausible(r.supply_bar)) return {FaultCode::kSensorOutOfRange, -1};
  for (int j = 0; j < joints; ++j) {
    if (std::abs(joint(j).angle_rad) > limits.angle_limit_deg_of(j) * kDeg) return {FaultCode::kAngleLimit, j};
  }
  for (int j = 0; j < joints; ++j) {
    for (double p : joint(j).chamber_bar) {
      if (p > in.p_max_bar + limits.pressure_margin_bar) return {FaultCode::kOverpressure, j};
    }
  }
  if (r.supply_bar < limits.supply_min_bar) return {FaultCode::kSupplyLow, -1};
  if (in.missed_streak >= limits.missed_deadline_streak) return {FaultCode::kMissedDeadlines, -1};
  if (limits.heartbeat_timeout_s > 0.0 && in.heartbeat_age_s > limits.heartbeat_timeout_s)
    return {FaultCode::kHeartbeatLost, -1};
  return {};
}

}  // namespace bellows
