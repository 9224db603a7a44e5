// The limits a rig enforces by itself, whatever it is sent: the last line of defence when the
// engine is wrong, gone, or not the one sending (docs/lcm-protocol.md). Every rig back-end (io-sim,
// t7-sim) applies
// them to the valve state it is about to drive, with the sensor values it has just read.
#pragma once

#include <cstdint>

#include "engine/config/configuration.hpp"
#include "engine/control/device.hpp"

namespace bellows {

struct RigLimits {
  double pressure_ceiling_bar = 1.75;  // [controller] p_max_bar + [lcm] rig_pressure_margin_bar
  double angle_limit_rad = 1.745;      // [lcm] rig_angle_limit_deg

  static RigLimits from(const Configuration& config);
};

// The bits of LimitedValves::fault_bits: io_state_t's FAULT_PRESSURE_LIMIT and FAULT_ANGLE_LIMIT
// (checked where the LCM rig uses them), so that rigs off LCM (t7-sim) apply the same limits.
inline constexpr std::int32_t kRigPressureLimitBit = 16;
inline constexpr std::int32_t kRigAngleLimitBit = 32;

struct LimitedValves {
  ValveCommand valves;          // what to drive
  std::int32_t fault_bits = 0;  // kRigPressureLimitBit / kRigAngleLimitBit
  bool angle_exceeded = false;  // the rig must vent and drop its session
};

/// `commanded` with every chamber above the ceiling vented (inlet closed, outlet open), and
/// everything vented when the angle is beyond the range. A NaN reading counts as beyond its limit.
LimitedValves enforce_rig_limits(const ValveCommand& commanded, const SensorReading& reading, const RigLimits& limits);

}  // namespace bellows
