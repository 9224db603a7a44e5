// Safety guards: each a named fault with a human message, every limit from `[safety]`.
// check_guards() looks at one tick's reading and loop health and names the first fault it finds.
#pragma once

#include <cstdint>

#include "engine/control/device.hpp"

namespace bellows {

struct SafetyParameters {
  double angle_limit_deg = 95.0;          // beyond it the arm is where no trajectory may take it
  double pressure_margin_bar = 0.25;      // fault when a chamber exceeds p_max + margin
  double supply_min_bar = 2.0;            // absolute; below it the valves cannot do their job
  double sensor_min_bar = 0.5;            // plausible range of any pressure reading
  double sensor_max_bar = 10.0;
  double sensor_max_angle_deg = 180.0;    // plausible range of the encoder
  int stale_ticks = 3;                    // readings whose time did not advance
  int missed_deadline_streak = 5;         // consecutive ticks that missed their deadline
  double heartbeat_timeout_s = 1.0;       // console silent for longer: fault
  double black_box_s = 2.0;               // ticks kept for the fault record
};

enum class FaultCode : std::uint8_t {
  kNone,
  kEmergencyStop,
  kAngleLimit,
  kOverpressure,
  kSupplyLow,
  kSensorNotANumber,
  kSensorOutOfRange,
  kSensorStale,
  kMissedDeadlines,
  kHeartbeatLost,
};

/// A short stable name ("overpressure") and a sentence for the operator.
const char* fault_name(FaultCode code);
const char* fault_message(FaultCode code);

/// What the guards need to know besides the reading.
struct GuardInputs {
  double p_max_bar = 1.4;
  int joint_count = 1;        // the joints the engine drives: a reading for another count is implausible
  int stale_count = 0;        // consecutive ticks without a fresh reading
  int missed_streak = 0;      // consecutive missed deadlines
  double heartbeat_age_s = 0; // time since the console's last heartbeat (0 when not monitored)
};

FaultCode check_guards(const SensorReading& reading, const GuardInputs& inputs, const SafetyParameters& limits);

}  // namespace bellows
