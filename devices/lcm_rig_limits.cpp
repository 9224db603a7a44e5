#include "devices/lcm_rig_limits.hpp"

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
  if (!(std::abs(reading.angle_rad) <= limits.angle_limit_rad)) {  // NaN too
    out.valves = ValveCommand::vented();
    out.fault_bits |= kRigAngleLimitBit;
    out.angle_exceeded = true;
  }
  for (int i = 0; i < kActuatorCount; ++i) {
    if (!(reading.chamber_bar[i] <= limits.pressure_ceiling_bar)) {
      out.valves.inlet_duty[i] = 0.0;
      out.valves.outlet_duty[i] = 1.0;
      out.fault_bits |= kRigPressureLimitBit;
    }
  }
  return out;
}

}  // namespace bellows
