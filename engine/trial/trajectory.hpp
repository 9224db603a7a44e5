// Reference trajectories: the desired joint angles sampled at the ILC sample time.
// A trajectory of N learning samples holds N + 1 angles per joint, at t = 0, T, ..., N T; sample 0
// is where the arm waits before the trial (the lifted error is e(1..N)). J joints of equal rank:
// joint(j) is joint j + 1's angles (../shared/spec/multi-joint.md section 3).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "engine/model/multi_joint_model.hpp"  // kMaxJoints, JointVector

namespace bellows {

/// One set-point move with a trapezoidal velocity profile.
struct TrapezoidalMove {
  double start_s = 0.0;
  double from_deg = 0.0;
  double to_deg = 0.0;
  double duration_s = 0.2;
  double peak_acceleration_deg_per_s2 = 12000.0;
};

/// One joint's part of a trajectory built from moves: where it starts and its moves in time order.
struct JointMoves {
  double initial_deg = 0.0;
  std::vector<TrapezoidalMove> moves;
};

struct Trajectory {
  std::string name;
  double sample_time_s = 0.0;
  std::vector<Eigen::VectorXd> angles_rad = {};  // one per joint (J), N + 1 samples each

  int learning_samples() const { return angles_rad.empty() ? -1 : static_cast<int>(angles_rad.front().size()) - 1; }
  double duration_s() const { return learning_samples() * sample_time_s; }
  int joints() const { return static_cast<int>(angles_rad.size()); }
  /// Joint `joint`'s (0-based) angles over time; the joint must exist.
  const Eigen::VectorXd& joint(int joint) const { return angles_rad[static_cast<std::size_t>(joint)]; }
  Eigen::VectorXd& joint(int joint) { return angles_rad[static_cast<std::size_t>(joint)]; }
  /// Every joint's desired angle at `sample` (allocation-free: JointVector has a fixed capacity).
  JointVector setpoint_rad(Eigen::Index sample) const;
};

/// Limits every trajectory must respect before it may drive the arm (each joint the same range).
struct TrajectoryLimits {
  double max_abs_angle_deg = 90.0;
  int min_learning_samples = 2;
};

/// Angle (deg) at time t of a trapezoidal move; `from_deg` before it starts, `to_deg` after.
/// Throws InputError when the move cannot be done in its duration with its peak acceleration.
double trapezoidal_move_angle_deg(const TrapezoidalMove& move, double time_s);

/// Samples a sequence of moves from `initial_deg` over `duration_s` (one joint).
Trajectory trajectory_from_moves(const std::string& name, double initial_deg, const std::vector<TrapezoidalMove>& moves,
                                 double duration_s, double sample_time_s);
/// The same for 1..kMaxJoints joints, one JointMoves per joint; throws InputError for another count.
Trajectory trajectory_from_joint_moves(const std::string& name, const std::vector<JointMoves>& joints,
                                       double duration_s, double sample_time_s);

/// Builds a trajectory from (time, angle) samples, checking: finite values, time starting at 0 and
/// uniformly spaced by `sample_time_s` (to 1e-6 s), angles within the limits. Throws InputError.
Trajectory trajectory_from_samples(const std::string& name, const std::vector<double>& time_s,
                                   const std::vector<double>& angle_deg, double sample_time_s,
                                   const TrajectoryLimits& limits);
/// The same for 1..kMaxJoints joints: `joint_angle_deg[j]` is joint j + 1's column.
Trajectory trajectory_from_joint_samples(const std::string& name, const std::vector<double>& time_s,
                                         const std::vector<std::vector<double>>& joint_angle_deg, double sample_time_s,
                                         const TrajectoryLimits& limits);

/// Checks a built trajectory against the limits (every joint the same length, finite, in range);
/// throws InputError naming the first bad sample (and its joint when there are several).
void validate_trajectory(const Trajectory& trajectory, const TrajectoryLimits& limits);

/// Refuses a trajectory whose joint count is not the arm's, before anything moves:
/// "trajectory 'paper2' has 2 joints; the arm has 1 (<arm_source>)". Throws InputError.
void require_trajectory_joints(const Trajectory& trajectory, int arm_joints, const std::string& arm_source);

/// Names of the built-in library, in display order.
std::vector<std::string> trajectory_library_names();
/// A one-line description of a library entry (its joint count when more than one).
std::string trajectory_library_description(const std::string& name);
/// The joint count of a library entry; throws InputError if unknown.
int trajectory_library_joints(const std::string& name);
/// The library as a help text shows it: "paper, steps, sine, paper2 (2 joints), paper3 (3 joints)".
std::string trajectory_library_summary();
/// The library trajectory `name` ("paper", "steps", "sine", "paper2", ...); throws InputError if unknown.
Trajectory library_trajectory(const std::string& name, double sample_time_s);

}  // namespace bellows
