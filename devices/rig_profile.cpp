#include "devices/rig_profile.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "devices/t7_registers.hpp"
#include "devices/t7_timing.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// What a calibrated value can physically be, whatever the rig: a calibration that maps a sensor's
// valid voltage range outside these bounds is a typo (a gain in mbar, an offset in degrees).
struct PhysicalBounds {
  double low, high;
};
PhysicalBounds physical_bounds(SensorRole role) {
  switch (role) {
    case SensorRole::kChamberA:
    case SensorRole::kChamberB:
    case SensorRole::kSupply:
      return {0.0, 50.0};  // bar, absolute
    case SensorRole::kAngle:
      return {-2.0 * std::numbers::pi, 2.0 * std::numbers::pi};  // rad
    case SensorRole::kTemperature:
      return {173.15, 473.15};  // K: -100..200 C
  }
  return {0.0, 0.0};
}

bool is_t7_range(double range_V) {
  for (double r : {10.0, 1.0, 0.1, 0.01}) {
    if (range_V == r) return true;
  }
  return false;
}

}  // namespace

const char* to_string(SensorRole role) {
  switch (role) {
    case SensorRole::kChamberA:
      return "chamber_a";
    case SensorRole::kChamberB:
      return "chamber_b";
    case SensorRole::kSupply:
      return "supply";
    case SensorRole::kAngle:
      return "angle";
    case SensorRole::kTemperature:
      return "temperature";
  }
  return "?";
}

const char* to_string(ValveRole role) {
  switch (role) {
    case ValveRole::kInletA:
      return "inlet_a";
    case ValveRole::kInletB:
      return "inlet_b";
    case ValveRole::kOutletA:
      return "outlet_a";
    case ValveRole::kOutletB:
      return "outlet_b";
  }
  return "?";
}

const char* calibrated_unit(SensorRole role) {
  switch (role) {
    case SensorRole::kAngle:
      return "rad";
    case SensorRole::kTemperature:
      return "K";
    default:
      return "bar";
  }
}

void validate_rig_profile(const RigProfile& p) {
  const std::string where = "rig profile " + p.source + ": ";
  const auto fail = [&](const std::string& key, const std::string& what) {
    throw InputError(where + key + ": " + what);
  };
  if (p.name.empty()) fail("name", "must not be empty");
  if (!(p.pwm_frequency_hz >= 1.0 && p.pwm_frequency_hz <= 10000.0)) {
    fail("pwm_frequency_hz", "must be between 1 and 10000 Hz, not " + std::to_string(p.pwm_frequency_hz));
  }
  if (!std::isfinite(p.angle_zero_rad) || std::abs(p.angle_zero_rad) > std::numbers::pi) {
    fail("angle_zero_rad", "must be within +-pi");
  }
  for (SensorRole role : kSensorRoles) {
    const SensorCalibration& c = p.input(role);
    const std::string section = std::string("[inputs.") + to_string(role) + "] ";
    if (c.ain < 0)
      fail(section + "ain", "missing: every input (chamber_a, chamber_b, supply, angle, temperature) needs one");
    if (c.ain >= t7::kAinCount) fail(section + "ain", "a T7 has AIN0..AIN13, not AIN" + std::to_string(c.ain));
    for (SensorRole other : kSensorRoles) {
      if (other < role && p.input(other).ain == c.ain) {
        fail(section + "ain", "AIN" + std::to_string(c.ain) + " is already " + to_string(other) + "'s input");
      }
    }
    if (!is_t7_range(c.range_V)) fail(section + "range_V", "a T7 input range is 10, 1, 0.1 or 0.01 V");
    if (!std::isfinite(c.gain_per_V) || c.gain_per_V == 0.0) fail(section + "gain_per_V", "must be a nonzero number");
    if (!std::isfinite(c.offset)) fail(section + "offset", "must be a number");
    if (!(c.volts_min_V < c.volts_max_V)) fail(section + "volts_min_V", "must be below volts_max_V");
    if (c.volts_min_V < -c.range_V || c.volts_max_V > c.range_V) {
      fail(section + "volts_max_V",
           "the valid voltages must lie inside the input range +-" + std::to_string(c.range_V) + " V");
    }
    if (c.resolution_index < 0 || c.resolution_index > t7::kMaxResolutionIndexT7Pro) {
      fail(section + "resolution_index",
           "a T7 samples at index 0..8 (0..12 on a T7-Pro), not " + std::to_string(c.resolution_index));
    }
    if (!(c.settling_us >= 0.0 && c.settling_us <= t7::kMaxSettling_us)) {
      fail(section + "settling_us", "must be 0 (automatic) up to 50000 us");
    }
    const PhysicalBounds bounds = physical_bounds(role);
    for (double volts : {c.volts_min_V, c.volts_max_V}) {
      const double value = c.value(volts);
      if (!(value >= bounds.low && value <= bounds.high)) {
        char what[200];
        std::snprintf(what, sizeof what, "maps %.3g V to %.4g %s, outside anything a %s sensor can read (%g..%g %s)",
                      volts, value, calibrated_unit(role), to_string(role), bounds.low, bounds.high,
                      calibrated_unit(role));
        fail(section + "gain_per_V", what);
      }
    }
  }
  for (ValveRole role : kValveRoles) {
    const int dio = p.dio(role);
    const std::string key = std::string("[valves] ") + to_string(role);
    if (!t7::pwm_capable(dio)) {
      fail(key, "DIO" + std::to_string(dio) + " cannot carry PWM on a T7 (DIO0 and DIO2..DIO5 can)");
    }
    for (ValveRole other : kValveRoles) {
      if (other < role && p.dio(other) == dio) {
        fail(key, "DIO" + std::to_string(dio) + " is already " + to_string(other) + "'s line");
      }
    }
  }
  if (p.model) {
    if (!(p.model->kappa_rad_per_bar > 0.0)) fail("[model] kappa_rad_per_bar", "must be positive");
    if (!(p.model->omega0_rad_per_s > 0.0)) fail("[model] omega0_rad_per_s", "must be positive");
    if (!(p.model->damping > 0.0)) fail("[model] damping", "must be positive");
  }
}

}  // namespace bellows
