// Everything one trial produced, preallocated before the trial so the loop only writes into it.
// Samples are at the ILC rate (index k = 0..N); ticks at the loop rate (index 0..N*ticks_per_sample-1).
// One joint is the default: `samples` and `ticks` are joint 1 (the only joint of a single-joint
// trial, recorded exactly as before joints were counted); `more_joint_samples` / `more_joint_ticks`
// hold joints 2..J in the same layout (each with its own copy of the time and supply columns), as
// Trajectory's `more_joints_rad` does.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

namespace bellows {

struct TrialSamples {
  Eigen::VectorXd time_s, setpoint_rad, angle_rad, error_rad;  // error(0) is 0 by definition
  Eigen::VectorXd u_pid_bar, u_ilc_bar, u_total_bar;           // inputs u(k); index N is the hold after the trial
  Eigen::VectorXd pressure_a_bar, pressure_b_bar;              // measured at sample k
  Eigen::VectorXd setpoint_a_bar, setpoint_b_bar;              // commanded from sample k on
  void resize(Eigen::Index count);
};

struct TrialTicks {
  Eigen::VectorXd time_s, angle_rad, pressure_a_bar, pressure_b_bar, supply_bar;
  Eigen::VectorXd setpoint_a_bar, setpoint_b_bar, inlet_a, outlet_a, inlet_b, outlet_b;
  void resize(Eigen::Index count);
};

struct TrialRecord {
  TrialSamples samples;                               // joint 1
  TrialTicks ticks;                                   // joint 1
  std::vector<TrialSamples> more_joint_samples = {};  // joints 2..J; empty: one joint
  std::vector<TrialTicks> more_joint_ticks = {};      // joints 2..J, like more_joint_samples
  int learning_samples = 0;                           // N
  bool complete = false;
  // Samples k = 0..N taken on a tick without a fresh reading (1: held; ControlCore::tick_held):
  // their error is 0 and nothing is learned from them. Shared by every joint (one reading for all).
  // Sessions keep them as an event, not a column: a file without held samples is as it always was.
  std::vector<unsigned char> held = {};
  int held_samples = 0;  // how many of `held` are 1

  /// Sizes every joint's columns (zeroed). Preparing again to the same sizes allocates nothing.
  void prepare(int learning_samples_count, int ticks_per_sample, int joints = 1);
  int joints() const { return 1 + static_cast<int>(more_joint_samples.size()); }
  /// Joint `joint`'s columns (0 = joint 1 = samples / ticks); the joint must exist.
  TrialSamples& joint_samples(int joint) {
    return joint == 0 ? samples : more_joint_samples[static_cast<std::size_t>(joint - 1)];
  }
  const TrialSamples& joint_samples(int joint) const {
    return joint == 0 ? samples : more_joint_samples[static_cast<std::size_t>(joint - 1)];
  }
  TrialTicks& joint_ticks(int joint) {
    return joint == 0 ? ticks : more_joint_ticks[static_cast<std::size_t>(joint - 1)];
  }
  const TrialTicks& joint_ticks(int joint) const {
    return joint == 0 ? ticks : more_joint_ticks[static_cast<std::size_t>(joint - 1)];
  }

  /// Normalized lifted error e(1..N) = (yD - y) / pi of joint 1, what the learning laws take.
  Eigen::VectorXd normalized_error() const;
  /// Every joint's normalized lifted error, N x J (one column per joint): what MultiJointNoilc takes.
  Eigen::MatrixXd normalized_joint_errors() const;
  /// RMS and largest error of joint 1 (deg).
  double rms_error_deg() const;
  double max_abs_error_deg() const;
  /// RMS error of joint `joint` (deg), over samples 1..N.
  double joint_rms_error_deg(int joint) const;
};

}  // namespace bellows
