// Building blocks of learning transfer: linear regressors built from a signal sampled at the ILC
// rate, and ridge least squares over rows accumulated from several trials. All signals are in the
// learning laws' normalized units (angle / pi) or bar.
#pragma once

#include <vector>

#include <Eigen/Dense>

namespace bellows {

/// How a signal s(0..N) becomes regressors for one row centred at sample c.
struct RegressorShape {
  int taps_behind = 0;  // s(c - k), k = 1..taps_behind (clamped to s(0))
  int taps_ahead = 0;   // s(c + k), k = 0..taps_ahead (clamped to s(N)); non-causal when > 0
  int derivatives = 0;  // central differences of order 1..derivatives at c (basis of the reference)
  std::vector<double> lowpass_time_constants_s;  // first-order low-passes of s (rational basis, slow modes)
  // |s'| s' and |s| s' at c + lead for each lead: the valves' flow limit near ambient and the bellows'
  // volume effect grow with speed and pressure, which a linear map cannot follow.
  std::vector<int> nonlinear_leads;
  bool constant = true;
  int count() const;
};

/// Regressor matrix: row i is centred at sample first_center + i, rows = count. `signal` has the
/// samples 0..N; samples outside are held at the ends (the arm rests before and after a trial).
Eigen::MatrixXd build_regressors(const Eigen::VectorXd& signal, const RegressorShape& shape, int first_center, int rows,
                                 double sample_time_s);

/// Causal FIR of an input u(0..N-1) to outputs at samples 1..N: row t-1 holds u(t-1-k), k = 0..taps-1,
/// and first-order low-passes of u (the closed loop's slow tails). No constant.
Eigen::MatrixXd build_causal_regressors(const Eigen::VectorXd& input, int taps,
                                        const std::vector<double>& lowpass_time_constants_s, double sample_time_s);

/// Normal equations Phi'Phi, Phi'y accumulated group by group (a group is one source session), so
/// that a fit leaving one group out costs one solve.
class RidgeAccumulator {
 public:
  explicit RidgeAccumulator(int parameters, int groups);
  void add(int group, const Eigen::MatrixXd& regressors, const Eigen::VectorXd& target);
  /// theta = argmin sum ||Phi theta - y||^2 + lambda tr(Phi'Phi)/p ||theta||^2 over all groups but
  /// `left_out` (-1: all). Empty when the remaining rows carry no data.
  Eigen::VectorXd solve(double relative_ridge, int left_out = -1) const;
  long rows(int left_out = -1) const;

 private:
  std::vector<Eigen::MatrixXd> gram_;
  std::vector<Eigen::VectorXd> moment_;
  std::vector<long> rows_;
};

}  // namespace bellows
