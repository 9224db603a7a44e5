// Everything one trial produced, preallocated before the trial so the loop only writes into it.
// Samples are at the ILC rate (index k = 0..N); ticks at the loop rate (index 0..N*ticks_per_sample-1).
#pragma once

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
  TrialSamples samples;
  TrialTicks ticks;
  int learning_samples = 0;  // N
  bool complete = false;

  void prepare(int learning_samples_count, int ticks_per_sample);
  /// Normalized lifted error e(1..N) = (yD - y) / pi, what the learning laws take.
  Eigen::VectorXd normalized_error() const;
  double rms_error_deg() const;
  double max_abs_error_deg() const;
};

}  // namespace bellows
