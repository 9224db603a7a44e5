// The map the correction u_ilc acts through, as one linear state-space model per arm: the arm's model
// behind the pressure controllers' designed first-order response (tau_p, with the bellows'
// bounce-back the pressure loop leaves uncompensated), inside the PID of the reference system's
// section 3 (the same closed loop z G / (1 + G C_pid) that engine/config/convergence writes down per
// frequency), plus a learned correction in parallel: per input, an FIR of its last `taps` values and
// first-order low-passes of it (the slow modes the nominal model lacks: creep, the valves' flow
// limits), read by each joint's output either from its own input only (diagonal) or from every
// joint's (cross-joint: the coupling the prior's model has wrong).
// States: [arm 2J | pressure J | PID integral J | previous output J | correction (taps + low-passes) J].
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "engine/base/parameters.hpp"
#include "engine/learning/noilc_state_space.hpp"

namespace bellows {

/// The known part: the arm's continuous model in the normalized coordinates of
/// engine/model/coupled_joint_dynamics (joint i owns states 2i, 2i+1), the pressure lag and the PID.
struct ClosedLoopPrior {
  Eigen::MatrixXd arm_A, arm_B;  // continuous, 2J x 2J and 2J x J
  Eigen::VectorXd bounce_back;   // per joint: d(dp)/dt per unit of x2 = alpha_dot / (10 pi)
  double tau_p_s = 0.02;
  ControllerParameters pid;  // k_p, k_i_per_s, k_d_s are used
  double sample_time_s = 0.02;
  int joints() const { return static_cast<int>(arm_B.cols()); }
};

/// The prior of an arm whose model is the zero-order-hold discretization (A: 2J x 2J, B: 2J x J, at
/// `sample_time_s`) of a continuous one, recovered with the matrix logarithm, every joint with the
/// bellows' volume gain `volume_gain_per_rad`. Throws InputError when the model has no continuous
/// counterpart (an eigenvalue of A on the negative real axis).
ClosedLoopPrior closed_loop_prior(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double sample_time_s,
                                  double volume_gain_per_rad, const ControllerParameters& controller);

/// The learned part's shape: per joint, the FIR taps and the low-passes' time constants.
struct CorrectionShape {
  int taps = 8;
  std::vector<double> lowpass_time_constants_s{0.25, 1.0};
  int per_joint() const { return taps + static_cast<int>(lowpass_time_constants_s.size()); }
};

/// The model with the correction's coefficients `correction`, column i joint i's output: per_joint() x J
/// (diagonal: from joint i's input only) or per_joint() J x J (cross-joint: rows k per_joint() ... from
/// joint k's input), or empty (none).
StateSpaceModel closed_loop_model(const ClosedLoopPrior& prior, const CorrectionShape& shape,
                                  const Eigen::MatrixXd& correction);

/// Writes the coefficients `correction` (as closed_loop_model's) into the outputs of `model`, a
/// closed_loop_model of the same prior and shape: a refit changes C only, not A and B.
void set_correction(const CorrectionShape& shape, const Eigen::MatrixXd& correction, StateSpaceModel& model);

/// Regressors of the correction for one joint's input change du(0..N-1): row t-1 holds what the
/// correction states hold at sample t (N x per_joint()), so that y_correction = Phi * coefficients.
Eigen::MatrixXd correction_regressors(const Eigen::Ref<const Eigen::VectorXd>& du, const CorrectionShape& shape,
                                      double sample_time_s);

}  // namespace bellows
