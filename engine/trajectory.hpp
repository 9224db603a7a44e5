// Reference trajectories: the desired joint angle sampled at the ILC sample time.
// A trajectory of N learning samples holds N + 1 angles, at t = 0, T, ..., N T; sample 0 is where
// the arm waits before the trial (the lifted error is e(1..N)).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

namespace bellows {

/// One set-point move with a trapezoidal velocity profile.
struct TrapezoidalMove {
  double start_s = 0.0;
  double from_deg = 0.0;
  double to_deg = 0.0;
  double duration_s = 0.2;
  double peak_acceleration_deg_per_s2 = 12000.0;
};

struct Trajectory {
  std::string name;
  double sample_time_s = 0.0;
  Eigen::VectorXd angle_rad;  // N + 1 samples

  int learning_samples() const { return static_cast<int>(angle_rad.size()) - 1; }
  double duration_s() const { return learning_samples() * sample_time_s; }
};

/// Limits every trajectory must respect before it may drive the arm.
struct TrajectoryLimits {
  double max_abs_angle_deg = 90.0;
  int min_learning_samples = 2;
};

/// Angle (deg) at time t of a trapezoidal move; `from_deg` before it starts, `to_deg` after.
/// Throws InputError when the move cannot be done in its duration with its peak acceleration.
double trapezoidal_move_angle_deg(const TrapezoidalMove& move, double time_s);

/// Samples a sequence of moves from `initial_deg` over `duration_s`.
Trajectory trajectory_from_moves(const std::string& name, double initial_deg, const std::vector<TrapezoidalMove>& moves,
                                 double duration_s, double sample_time_s);

/// Builds a trajectory from (time, angle) samples, checking: finite values, time starting at 0 and
/// uniformly spaced by `sample_time_s` (to 1e-6 s), angles within the limits. Throws InputError.
Trajectory trajectory_from_samples(const std::string& name, const std::vector<double>& time_s,
                                   const std::vector<double>& angle_deg, double sample_time_s,
                                   const TrajectoryLimits& limits);

/// Checks a built trajectory against the limits; throws InputError naming the first bad sample.
void validate_trajectory(const Trajectory& trajectory, const TrajectoryLimits& limits);

/// Names of the built-in library, in display order.
std::vector<std::string> trajectory_library_names();
/// A one-line description of a library entry.
std::string trajectory_library_description(const std::string& name);
/// The library trajectory `name` ("paper", "steps", "sine", ...); throws InputError if unknown.
Trajectory library_trajectory(const std::string& name, double sample_time_s);

}  // namespace bellows
