#include "devices/lcm_rig_limits.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bellows {

RigLimits RigLimits::from(const Configuration& config) {
  RigLimits limits;
  limits.pressure_ceiling_bar = config.controller.p_max_bar + config.lcm.rig_pressure_margin_bar;
  limits.angle_limit_rad = config.lcm.rig_angle_limit_deg * std::numbers::pi / 180.0;
  return limits;
}

LimitedValves enforce_rig_limits(const ValveCommand& commanded, const SensorReading& reading, const RigLimits& limits) {
  LimitedValves out{commanded, 0, false};
  const int joints = std::clamp(reading.joint_count, 1, kMaxJoints);
  for (int j = 0; j < joints; ++j) {
    if (!(std::abs(reading.joint[static_cast<std::size_t>(j)].angle_rad) <= limits.angle_limit_rad)) {  // NaN too
      out.valves = ValveCommand::vented(commanded.joint_count);  // any joint out of range vents the whole arm
      out.fault_bits |= kRigAngleLimitBit;
      out.angle_exceeded = true;
      if (out.angle_joint < 0) out.angle_joint = j;
    }
  }
  for (int j = 0; j < joints; ++j) {
    const JointReading& joint = reading.joint[static_cast<std::size_t>(j)];
    JointValves& valves = out.valves.joint[static_cast<std::size_t>(j)];
    for (int i = 0; i < kActuatorCount; ++i) {
      if (!(joint.chamber_bar[i] <= limits.pressure_ceiling_bar)) {
        valves.inlet_duty[i] = 0.0;
        valves.outlet_duty[i] = 1.0;
        out.fault_bits |= kRigPressureLimitBit;
      }
    }
  }
  return out;
}

}  // namespace bellows
