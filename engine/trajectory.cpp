#include "engine/trajectory.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "engine/errors.hpp"

namespace bellows {
namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
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
  const int samples = static_cast<int>(std::lround(duration_s / sample_time_s));
  Trajectory trajectory{name, sample_time_s, Eigen::VectorXd(samples + 1)};
  for (int k = 0; k <= samples; ++k) {
    const double t = k * sample_time_s;
    double angle = initial_deg;
    for (const TrapezoidalMove& move : moves) {
      if (t >= move.start_s) angle = trapezoidal_move_angle_deg(move, t);
    }
    trajectory.angle_rad(k) = angle * kRadPerDeg;
  }
  return trajectory;
}

void validate_trajectory(const Trajectory& trajectory, const TrajectoryLimits& limits) {
  if (trajectory.learning_samples() < limits.min_learning_samples) {
    throw InputError("trajectory '" + trajectory.name + "' is too short: " +
                     std::to_string(trajectory.angle_rad.size()) + " samples, at least " +
                     std::to_string(limits.min_learning_samples + 1) + " needed");
  }
  for (Eigen::Index k = 0; k < trajectory.angle_rad.size(); ++k) {
    const double angle_deg = trajectory.angle_rad(k) / kRadPerDeg;
    if (!std::isfinite(angle_deg)) {
      throw InputError("trajectory '" + trajectory.name + "': angle at sample " + std::to_string(k) + " is not a number");
    }
    if (std::abs(angle_deg) > limits.max_abs_angle_deg) {
      throw InputError("trajectory '" + trajectory.name + "': angle " + format_number(angle_deg) + " deg at t = " +
                       format_number(static_cast<double>(k) * trajectory.sample_time_s) + " s is outside the joint range of +-" +
                       format_number(limits.max_abs_angle_deg) + " deg");
    }
  }
}

Trajectory trajectory_from_samples(const std::string& name, const std::vector<double>& time_s,
                                   const std::vector<double>& angle_deg, double sample_time_s,
                                   const TrajectoryLimits& limits) {
  constexpr double kTimeTolerance_s = 1e-6;
  if (time_s.size() != angle_deg.size()) throw InputError("trajectory '" + name + "': time and angle counts differ");
  Trajectory trajectory{name, sample_time_s, Eigen::VectorXd(static_cast<Eigen::Index>(angle_deg.size()))};
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    if (!std::isfinite(time_s[k])) {
      throw InputError("trajectory '" + name + "': time at sample " + std::to_string(k) + " is not a number");
    }
    const double expected = static_cast<double>(k) * sample_time_s;
    if (std::abs(time_s[k] - expected) > kTimeTolerance_s) {
      throw InputError("trajectory '" + name + "': sampling is not uniform at the ILC sample time " +
                       format_number(sample_time_s) + " s: sample " + std::to_string(k) + " is at t = " +
                       format_number(time_s[k]) + " s, expected " + format_number(expected) + " s");
    }
    trajectory.angle_rad(static_cast<Eigen::Index>(k)) = angle_deg[k] * kRadPerDeg;
  }
  validate_trajectory(trajectory, limits);
  return trajectory;
}

std::vector<std::string> trajectory_library_names() { return {"paper", "steps", "sine"}; }

std::string trajectory_library_description(const std::string& name) {
  if (name == "paper") return "8 s, six 0.2 s moves between +-30 deg (the paper's reference)";
  if (name == "steps") return "10 s, staircase 0 -> 20 -> 40 -> -20 -> -40 -> 0 deg, 0.3 s moves";
  if (name == "sine") return "8 s, 30 deg amplitude at 0.5 Hz with a 1 s raised-cosine fade in and out";
  throw InputError("unknown trajectory '" + name + "' (library: paper, steps, sine)");
}

Trajectory library_trajectory(const std::string& name, double sample_time_s) {
  constexpr double kDuration = 0.2, kAccel = 12000.0;  // spec section 6
  if (name == "paper") {
    const std::vector<TrapezoidalMove> moves = {
        {0.6, 0, 30, kDuration, kAccel},   {1.6, 30, -30, kDuration, kAccel}, {2.6, -30, 30, kDuration, kAccel},
        {3.6, 30, -30, kDuration, kAccel}, {4.6, -30, 30, kDuration, kAccel}, {5.6, 30, 0, kDuration, kAccel}};
    return trajectory_from_moves("paper", 0.0, moves, 8.0, sample_time_s);
  }
  if (name == "steps") {
    constexpr double kSlow = 0.3, kSlowAccel = 4000.0;
    const std::vector<TrapezoidalMove> moves = {
        {0.5, 0, 20, kSlow, kSlowAccel},    {2.0, 20, 40, kSlow, kSlowAccel},  {3.5, 40, -20, kSlow, kSlowAccel},
        {5.0, -20, -40, kSlow, kSlowAccel}, {6.5, -40, 0, kSlow, kSlowAccel}};
    return trajectory_from_moves("steps", 0.0, moves, 10.0, sample_time_s);
  }
  if (name == "sine") {
    constexpr double kDuration_s = 8.0, kAmplitude_deg = 30.0, kFrequency_Hz = 0.5, kFade_s = 1.0;
    const int samples = static_cast<int>(std::lround(kDuration_s / sample_time_s));
    Trajectory trajectory{"sine", sample_time_s, Eigen::VectorXd(samples + 1)};
    for (int k = 0; k <= samples; ++k) {
      const double t = k * sample_time_s;
      const double edge = std::min(t, kDuration_s - t);
      const double fade = edge >= kFade_s ? 1.0 : 0.5 * (1.0 - std::cos(std::numbers::pi * edge / kFade_s));
      trajectory.angle_rad(k) =
          fade * kAmplitude_deg * kRadPerDeg * std::sin(2.0 * std::numbers::pi * kFrequency_Hz * t);
    }
    return trajectory;
  }
  trajectory_library_description(name);  // throws the "unknown trajectory" error
  return {};
}

}  // namespace bellows
