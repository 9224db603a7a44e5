#include "ui/joint_view.hpp"

#include <cmath>
#include <numbers>

#include "ui/canvas.hpp"

namespace bellows::ui {

std::string joint_name(int joints, int joint) {
  static const char* const kNames[] = {"shoulder", "elbow", "wrist"};
  if (joints < 2 || joints > 3 || joint < 0 || joint >= joints) return {};
  return kNames[joint];
}

std::string joint_label(int joints, int joint) {
  if (joints < 2) return {};
  const std::string name = joint_name(joints, joint);
  return format("joint %d/%d", joint + 1, joints) + (name.empty() ? "" : " " + name);
}

double tick_desired_rad(const TickRecord& tick, int joint) {
  return tick.joint(joint >= 0 && joint < kMaxJoints ? joint : 0).desired_rad;
}

std::string fault_location(FaultCode code, int joint, const TickRecord& tick, const Configuration& config) {
  const int joints = tick.reading.joint_count;
  if (joints < 2 || joints > kMaxJoints || joint < 0 || joint >= joints) return {};
  const SafetyParameters& limits = config.safety;
  const double p_limit_bar = config.controller.p_max_bar + limits.pressure_margin_bar;
  const std::string name = joint_name(joints, joint);
  std::string where = format("joint %d", joint + 1) + (name.empty() ? "" : " (" + name + ")");
  const JointReading& r = tick.reading.joint[static_cast<std::size_t>(joint)];
  constexpr double kDegPerRad = 180.0 / std::numbers::pi;
  const double angle_deg = r.angle_rad * kDegPerRad;
  const auto chamber = [](int c) { return c == 0 ? 'A' : 'B'; };
  switch (code) {
    case FaultCode::kAngleLimit:
      return format("%s: angle %.1f deg beyond its limit of %g deg", where.c_str(), angle_deg,
                    limits.angle_limit_deg_of(joint));
    case FaultCode::kOverpressure:
      for (int c = 0; c < kActuatorCount; ++c) {
        if (r.chamber_bar[static_cast<std::size_t>(c)] > p_limit_bar) {
          return format("%s chamber %c: %.3f bar above p_max plus the margin (%.3f bar)", where.c_str(), chamber(c),
                        r.chamber_bar[static_cast<std::size_t>(c)], p_limit_bar);
        }
      }
      break;
    case FaultCode::kSensorNotANumber:
      if (!std::isfinite(r.angle_rad)) return where + ": the angle is not a number";
      for (int c = 0; c < kActuatorCount; ++c) {
        if (!std::isfinite(r.chamber_bar[static_cast<std::size_t>(c)])) {
          return format("%s chamber %c: the pressure is not a number", where.c_str(), chamber(c));
        }
      }
      break;
    case FaultCode::kSensorOutOfRange:
      if (std::abs(angle_deg) > limits.sensor_max_angle_deg) {
        return format("%s: angle %.1f deg outside the encoder's range", where.c_str(), angle_deg);
      }
      for (int c = 0; c < kActuatorCount; ++c) {
        const double p = r.chamber_bar[static_cast<std::size_t>(c)];
        if (p < limits.sensor_min_bar || p > limits.sensor_max_bar) {
          return format("%s chamber %c: %.3f bar outside the sensor's range", where.c_str(), chamber(c), p);
        }
      }
      break;
    default:
      return {};
  }
  return where;  // the engine named the joint; the tick recorded no value beyond a limit
}

}  // namespace bellows::ui
