// A rig profile: how one real rig is wired to its DAQ (docs/rig-bring-up.md). Which analog input
// carries which sensor and its linear calibration (volts to bar, rad or K) with the voltage range
// the sensor can really produce; which digital line drives which valve; the PWM frequency; the
// angle's zero; the model identified on this rig. Reading it from a file is app/'s job
// (app/rig_profile_file.*); the T7 device and t7-sim use it.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "engine/base/parameters.hpp"

namespace bellows {

/// The sensors bellows reads, in SensorReading's terms.
enum class SensorRole { kChamberA, kChamberB, kSupply, kAngle, kTemperature };
inline constexpr int kSensorRoleCount = 5;
inline constexpr std::array<SensorRole, kSensorRoleCount> kSensorRoles = {
    SensorRole::kChamberA, SensorRole::kChamberB, SensorRole::kSupply, SensorRole::kAngle, SensorRole::kTemperature};

/// The four PWM outputs: one per valve group (both inlets of a bellows share a duty cycle, so do
/// both outlets).
enum class ValveRole { kInletA, kInletB, kOutletA, kOutletB };
inline constexpr int kValveRoleCount = 4;
inline constexpr std::array<ValveRole, kValveRoleCount> kValveRoles = {ValveRole::kInletA, ValveRole::kInletB,
                                                                       ValveRole::kOutletA, ValveRole::kOutletB};

/// "chamber_a", "chamber_b", "supply", "angle", "temperature" (static storage).
const char* to_string(SensorRole role);
/// "inlet_a", "inlet_b", "outlet_a", "outlet_b" (static storage).
const char* to_string(ValveRole role);
/// The unit of a role's calibrated value: "bar" (absolute), "rad", "K".
const char* calibrated_unit(SensorRole role);

/// One analog input: value = offset + gain_per_V * volts, in the role's unit.
struct SensorCalibration {
  int ain = -1;               // T7 analog input number (AIN#)
  std::string part;           // what is wired there, e.g. "Buerkert 8230"
  double range_V = 10.0;      // the T7's input range for it: 10, 1, 0.1 or 0.01 (+-V)
  double gain_per_V = 1.0;    // role unit per volt
  double offset = 0.0;        // role unit at 0 V
  double volts_min_V = 0.0;   // the voltages the sensor can really produce; outside: a broken
  double volts_max_V = 10.0;  // wire or sensor (sensor-range fault)
  // How the T7 samples it (AIN#_RESOLUTION_INDEX, AIN#_SETTLING_US; devices/t7_timing.hpp): index
  // 1..8 (12 on a T7-Pro), 0 the product's default (8, or 9 on a Pro: too slow for a 5 ms tick);
  // settling 0 = automatic. Index 4 samples in 0.1 ms: five inputs and the link fit a tick.
  int resolution_index = 4;
  double settling_us = 0.0;

  double value(double volts) const { return offset + gain_per_V * volts; }
  double volts(double value) const { return (value - offset) / gain_per_V; }
  bool valid(double volts) const { return volts >= volts_min_V && volts <= volts_max_V; }
};

struct RigProfile {
  std::string name;                                          // e.g. "paper-rig"
  std::string source;                                        // the file it came from (for messages)
  std::array<SensorCalibration, kSensorRoleCount> inputs{};  // by SensorRole
  std::array<int, kValveRoleCount> valve_dio{};              // DIO number by ValveRole
  double pwm_frequency_hz = 200.0;
  double angle_zero_rad = 0.0;           // subtracted from the calibrated angle
  std::optional<ModelParameters> model;  // identified on this rig, if it was

  const SensorCalibration& input(SensorRole role) const { return inputs[static_cast<int>(role)]; }
  SensorCalibration& input(SensorRole role) { return inputs[static_cast<int>(role)]; }
  int dio(ValveRole role) const { return valve_dio[static_cast<int>(role)]; }
};

/// What a reading becomes when its voltage is outside the sensor's valid range: values the engine's
/// sensor-range guard rejects (a pressure below any plausible one, an angle beyond any plausible one).
inline constexpr double kOutOfRangePressure_bar = -1.0;
inline constexpr double kOutOfRangeAngle_rad = 1000.0;

/// Checks everything a file cannot be trusted with: input numbers, a line used twice or unable to
/// carry PWM, a calibration mapping the valid voltage range to impossible values. Throws InputError
/// "rig profile SOURCE: [inputs.chamber_a] gain_per_V: ..." naming the key.
void validate_rig_profile(const RigProfile& profile);

}  // namespace bellows
