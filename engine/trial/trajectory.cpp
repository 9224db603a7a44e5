#include "engine/trial/trajectory.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void check_joint_count(const std::string& name, std::size_t joints) {
  if (joints < 1 || joints > static_cast<std::size_t>(kMaxJoints)) {
    throw InputError("trajectory '" + name + "' has " + std::to_string(joints) + " joints: 1 to " +
                     std::to_string(kMaxJoints) + " are possible");
  }
}

// "" for a single-joint trajectory (its messages stay as they always were), "joint 2: " otherwise.
std::string joint_label(int joints, int joint) {
  return joints == 1 ? "" : "joint " + std::to_string(joint + 1) + ": ";
}
}  // namespace

double trapezoidal_move_angle_deg(const TrapezoidalMove& move, double time_s) {
  const double distance = std::abs(move.to_deg - move.from_deg);
  const double direction = move.to_deg >= move.from_deg ? 1.0 : -1.0;
  const double duration = move.duration_s;
  const double accel = move.peak_acceleration_deg_per_s2;
  if (!(duration > 0.0) || !(accel > 0.0)) throw InputError("a move needs a positive duration and acceleration");
  // a t_a (T - t_a) = distance gives the length t_a of the acceleration phase.
  const double discriminant = duration * duration - 4.0 * distance / accel;
  if (discriminant < 0.0) {
    throw InputError("a move of " + format_number(distance) + " deg cannot be done in " + format_number(duration) +
                     " s with peak acceleration " + format_number(accel) + " deg/s^2");
  }
  const double t_accel = 0.5 * (duration - std::sqrt(discriminant));
  const double cruise_speed = accel * t_accel;
  const double t = time_s - move.start_s;
  double travelled;
  if (t <= 0.0) {
    travelled = 0.0;
  } else if (t < t_accel) {
    travelled = 0.5 * accel * t * t;
  } else if (t < duration - t_accel) {
    travelled = 0.5 * accel * t_accel * t_accel + cruise_speed * (t - t_accel);
  } else if (t < duration) {
    const double remaining = duration - t;
    travelled = distance - 0.5 * accel * remaining * remaining;
  } else {
    travelled = distance;
  }
  return move.from_deg + direction * travelled;
}

Trajectory trajectory_from_moves(const std::string& name, double initial_deg, const std::vector<TrapezoidalMove>& moves,
                                 double duration_s, double sample_time_s) {
  return trajectory_from_joint_moves(name, {JointMoves{initial_deg, moves}}, duration_s, sample_time_s);
}

Trajectory trajectory_from_joint_moves(const std::string& name, const std::vector<JointMoves>& joints,
                                       double duration_s, double sample_time_s) {
  check_joint_count(name, joints.size());
  const int samples = static_cast<int>(std::lround(duration_s / sample_time_s));
  Trajectory trajectory{name, sample_time_s, std::vector<Eigen::VectorXd>(joints.size())};
  for (std::size_t j = 0; j < joints.size(); ++j) {
    Eigen::VectorXd& angle_rad = trajectory.angles_rad[j];
    angle_rad.resize(samples + 1);
    for (int k = 0; k <= samples; ++k) {
      const double t = k * sample_time_s;
      double angle = joints[j].initial_deg;
      for (const TrapezoidalMove& move : joints[j].moves) {
        if (t >= move.start_s) angle = trapezoidal_move_angle_deg(move, t);
      }
      angle_rad(k) = angle * kRadPerDeg;
    }
  }
  return trajectory;
}

JointVector Trajectory::setpoint_rad(Eigen::Index sample) const {
  JointVector setpoint(joints());
  for (int j = 0; j < joints(); ++j) setpoint(j) = joint(j)(sample);
  return setpoint;
}

void validate_trajectory(const Trajectory& trajectory, const TrajectoryLimits& limits) {
  check_joint_count(trajectory.name, static_cast<std::size_t>(trajectory.joints()));
  if (trajectory.learning_samples() < limits.min_learning_samples) {
    throw InputError("trajectory '" + trajectory.name +
                     "' is too short: " + std::to_string(trajectory.learning_samples() + 1) + " samples, at least " +
                     std::to_string(limits.min_learning_samples + 1) + " needed");
  }
  for (int j = 0; j < trajectory.joints(); ++j) {
    const Eigen::VectorXd& angle_rad = trajectory.joint(j);
    // One joint keeps today's messages; with several, each names its joint.
    const std::string where = "trajectory '" + trajectory.name + "': " + joint_label(trajectory.joints(), j);
    if (angle_rad.size() != trajectory.joint(0).size()) {
      throw InputError(where + "has " + std::to_string(angle_rad.size()) + " samples, joint 1 has " +
                       std::to_string(trajectory.joint(0).size()));
    }
    for (Eigen::Index k = 0; k < angle_rad.size(); ++k) {
      const double angle_deg = angle_rad(k) / kRadPerDeg;
      if (!std::isfinite(angle_deg)) {
        throw InputError(where + "angle at sample " + std::to_string(k) + " is not a number");
      }
      if (std::abs(angle_deg) > limits.max_abs_angle_deg) {
        throw InputError(where + "angle " + format_number(angle_deg) +
                         " deg at t = " + format_number(static_cast<double>(k) * trajectory.sample_time_s) +
                         " s is outside the joint range of +-" + format_number(limits.max_abs_angle_deg) + " deg");
      }
    }
  }
}

Trajectory trajectory_from_samples(const std::string& name, const std::vector<double>& time_s,
                                   const std::vector<double>& angle_deg, double sample_time_s,
                                   const TrajectoryLimits& limits) {
  return trajectory_from_joint_samples(name, time_s, {angle_deg}, sample_time_s, limits);
}

Trajectory trajectory_from_joint_samples(const std::string& name, const std::vector<double>& time_s,
                                         const std::vector<std::vector<double>>& joint_angle_deg, double sample_time_s,
                                         const TrajectoryLimits& limits) {
  constexpr double kTimeTolerance_s = 1e-6;
  check_joint_count(name, joint_angle_deg.size());
  for (const std::vector<double>& angle_deg : joint_angle_deg) {
    if (time_s.size() != angle_deg.size()) throw InputError("trajectory '" + name + "': time and angle counts differ");
  }
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    if (!std::isfinite(time_s[k])) {
      throw InputError("trajectory '" + name + "': time at sample " + std::to_string(k) + " is not a number");
    }
    const double expected = static_cast<double>(k) * sample_time_s;
    if (std::abs(time_s[k] - expected) > kTimeTolerance_s) {
      throw InputError("trajectory '" + name + "': sampling is not uniform at the ILC sample time " +
                       format_number(sample_time_s) + " s: sample " + std::to_string(k) +
                       " is at t = " + format_number(time_s[k]) + " s, expected " + format_number(expected) + " s");
    }
  }
  Trajectory trajectory{name, sample_time_s, std::vector<Eigen::VectorXd>(joint_angle_deg.size())};
  for (std::size_t j = 0; j < joint_angle_deg.size(); ++j) {
    const auto count = static_cast<Eigen::Index>(time_s.size());
    trajectory.angles_rad[j] = Eigen::Map<const Eigen::VectorXd>(joint_angle_deg[j].data(), count) * kRadPerDeg;
  }
  validate_trajectory(trajectory, limits);
  return trajectory;
}

void require_trajectory_joints(const Trajectory& trajectory, int arm_joints, const std::string& arm_source) {
  if (trajectory.joints() == arm_joints) return;
  throw InputError("trajectory '" + trajectory.name + "' has " + std::to_string(trajectory.joints()) + " joint" +
                   (trajectory.joints() == 1 ? "" : "s") + "; the arm has " + std::to_string(arm_joints) + " (" +
                   arm_source + ")");
}

}  // namespace bellows
