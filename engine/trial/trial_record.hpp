// Everything one trial produced, preallocated before the trial so the loop only writes into it.
// Samples are at the ILC rate (index k = 0..N); ticks at the loop rate (index 0..N*ticks_per_sample-1).
// J joints, each of equal rank: joints[j] holds joint j + 1's columns (a single-joint trial has
// joints[0] only). What every joint shares, the clock and the supply pressure, is kept once.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

namespace bellows {

/// One joint's columns at the ILC rate, k = 0..N.
struct TrialSamples {
  Eigen::VectorXd setpoint_rad, angle_rad, error_rad;  // error(0) is 0 by definition
  Eigen::VectorXd u_pid_bar, u_ilc_bar, u_total_bar;   // inputs u(k); index N is the hold after the trial
  Eigen::VectorXd pressure_a_bar, pressure_b_bar;      // measured at sample k
  Eigen::VectorXd setpoint_a_bar, setpoint_b_bar;      // commanded from sample k on
  void resize(Eigen::Index count);
};

/// One joint's columns at the loop rate.
struct TrialTicks {
  Eigen::VectorXd angle_rad, pressure_a_bar, pressure_b_bar;
  Eigen::VectorXd setpoint_a_bar, setpoint_b_bar, inlet_a, outlet_a, inlet_b, outlet_b;
  void resize(Eigen::Index count);
};

/// One joint's part of a trial.
struct TrialJoint {
  TrialSamples samples;
  TrialTicks ticks;
};

struct TrialRecord {
  Eigen::VectorXd sample_time_s;        // k T, k = 0..N: every joint's samples
  Eigen::VectorXd tick_time_s;          // i tick_s: every joint's ticks
  Eigen::VectorXd supply_bar;           // measured at each tick (one supply for every joint)
  std::vector<TrialJoint> joints = {};  // J of them; joints[0] is joint 1
  int learning_samples = 0;             // N
  bool complete = false;
  // Samples k = 0..N taken on a tick without a fresh reading (1: held; ControlCore::tick_held):
  // their error is 0 and nothing is learned from them. Shared by every joint (one reading for all).
  // Sessions keep them as an event, not a column: a file without held samples is as it always was.
  std::vector<unsigned char> held = {};
  int held_samples = 0;  // how many of `held` are 1

  /// Sizes every joint's columns and the shared ones (zeroed). Preparing again to the same sizes
  /// allocates nothing.
  void prepare(int learning_samples_count, int ticks_per_sample, int joint_count = 1);
  int joint_count() const { return static_cast<int>(joints.size()); }
  /// Joint `joint`'s (0-based) columns; the joint must exist.
  TrialSamples& joint_samples(int joint) { return joints[static_cast<std::size_t>(joint)].samples; }
  const TrialSamples& joint_samples(int joint) const { return joints[static_cast<std::size_t>(joint)].samples; }
  TrialTicks& joint_ticks(int joint) { return joints[static_cast<std::size_t>(joint)].ticks; }
  const TrialTicks& joint_ticks(int joint) const { return joints[static_cast<std::size_t>(joint)].ticks; }

  /// Normalized lifted error e(1..N) = (yD - y) / pi of joint `joint`, what the learning laws take.
  Eigen::VectorXd normalized_error(int joint = 0) const;
  /// Every joint's normalized lifted error, N x J (one column per joint): what MultiJointNoilc takes.
  Eigen::MatrixXd normalized_joint_errors() const;
  /// RMS and largest error of joint 1 (deg).
  double rms_error_deg() const;
  double max_abs_error_deg() const;
  /// RMS error of joint `joint` (deg), over samples 1..N.
  double joint_rms_error_deg(int joint) const;
};

}  // namespace bellows
