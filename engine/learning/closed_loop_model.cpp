#include "engine/learning/closed_loop_model.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include <unsupported/Eigen/MatrixFunctions>

#include "engine/base/errors.hpp"

namespace bellows {

ClosedLoopPrior closed_loop_prior(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double sample_time_s,
                                  double volume_gain_per_rad, const ControllerParameters& controller) {
  constexpr double kVelocityScale = 10.0 * std::numbers::pi;  // x2 = alpha_dot / (10 pi), spec section 2
  const Eigen::Index n = A.rows(), J = B.cols();
  // exp([[Ac, Bc], [0, 0]] T) = [[A, B], [0, I]]: the continuous model is its logarithm over T.
  Eigen::MatrixXd hold = Eigen::MatrixXd::Identity(n + J, n + J);
  hold.topLeftCorner(n, n) = A;
  hold.topRightCorner(n, J) = B;
  const Eigen::EigenSolver<Eigen::MatrixXd> spectrum(A);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::complex<double> lambda = spectrum.eigenvalues()(i);
    if (std::abs(lambda.imag()) < 1e-12 && lambda.real() <= 0.0) {
      throw InputError("noilc-learned: the arm's discrete model has no continuous counterpart (an eigenvalue <= 0)");
    }
  }
  const Eigen::MatrixXd continuous = hold.log() / sample_time_s;
  ClosedLoopPrior prior;
  prior.arm_A = continuous.topLeftCorner(n, n);
  prior.arm_B = continuous.topRightCorner(n, J);
  if (!prior.arm_A.allFinite() || !prior.arm_B.allFinite())
    throw InputError("noilc-learned: the arm's model is not finite");
  prior.bounce_back =
      Eigen::VectorXd::Constant(J, -2.0 * controller.gas.ambient_bar * volume_gain_per_rad * kVelocityScale);
  prior.tau_p_s = controller.tau_p_s;
  prior.pid = controller;
  prior.sample_time_s = sample_time_s;
  return prior;
}

StateSpaceModel closed_loop_model(const ClosedLoopPrior& prior, const CorrectionShape& shape,
                                  const Eigen::MatrixXd& correction) {
  const int J = prior.joints(), arm = 2 * J, actuated = 3 * J, per_joint = shape.per_joint();
  const double T = prior.sample_time_s;
  // Arm behind the pressure lag, continuous, then exact zero-order hold (as convergence.cpp).
  Eigen::MatrixXd continuous = Eigen::MatrixXd::Zero(actuated + J, actuated + J);
  continuous.topLeftCorner(arm, arm) = prior.arm_A;
  continuous.block(0, arm, arm, J) = prior.arm_B;  // driven by the achieved pressure difference
  for (int i = 0; i < J; ++i) {
    continuous(arm + i, arm + i) = -1.0 / prior.tau_p_s;
    continuous(arm + i, actuated + i) = 1.0 / prior.tau_p_s;  // following the commanded one
    continuous(arm + i, 2 * i + 1) = prior.bounce_back(i);
  }
  const Eigen::MatrixXd exponential = (continuous * T).exp();
  const Eigen::MatrixXd Ad = exponential.topLeftCorner(actuated, actuated);
  const Eigen::MatrixXd Bd = exponential.block(0, actuated, actuated, J);
  Eigen::MatrixXd Cd = Eigen::MatrixXd::Zero(J, actuated);
  for (int i = 0; i < J; ++i) Cd(i, 2 * i) = 1.0;
  // The PID for a zero reference: u_pid(t) = -(k_p y + k_i T (I(t-1) + y) + k_d (y - y(t-1)) / T).
  const double kp = prior.pid.k_p, kiT = prior.pid.k_i_per_s * T, kdT = prior.pid.k_d_s / T;
  const int integral = actuated, previous = actuated + J, learned = actuated + 2 * J;
  const int n = learned + per_joint * J;
  StateSpaceModel m;
  m.sample_time_s = T;
  m.A = Eigen::MatrixXd::Zero(n, n);
  m.B = Eigen::MatrixXd::Zero(n, J);
  m.C = Eigen::MatrixXd::Zero(J, n);
  m.A.topLeftCorner(actuated, actuated) = Ad - (kp + kiT + kdT) * Bd * Cd;
  m.A.block(0, integral, actuated, J) = -kiT * Bd;
  m.A.block(0, previous, actuated, J) = kdT * Bd;
  m.A.block(integral, 0, J, actuated) = Cd;
  m.A.block(integral, integral, J, J).setIdentity();
  m.A.block(previous, 0, J, actuated) = Cd;
  m.B.topRows(actuated) = Bd;
  m.C.leftCols(actuated) = Cd;
  for (int i = 0; i < J; ++i) {
    const int first = learned + i * per_joint;
    for (int k = 0; k < shape.taps; ++k) {
      if (k == 0) m.B(first, i) = 1.0;  // d_0(t+1) = u(t), d_k(t+1) = d_{k-1}(t): d_k(t) = u(t-1-k)
      else m.A(first + k, first + k - 1) = 1.0;
    }
    for (std::size_t f = 0; f < shape.lowpass_time_constants_s.size(); ++f) {
      const int state = first + shape.taps + static_cast<int>(f);
      const double a = std::exp(-T / shape.lowpass_time_constants_s[f]);
      m.A(state, state) = a;
      m.B(state, i) = 1.0 - a;
    }
  }
  set_correction(shape, correction, m);
  return m;
}

void set_correction(const CorrectionShape& shape, const Eigen::MatrixXd& correction, StateSpaceModel& model) {
  const int J = model.inputs(), per_joint = shape.per_joint(), learned = model.states() - per_joint * J;
  model.C.rightCols(per_joint * J).setZero();
  if (correction.size() == 0) return;
  if (correction.cols() != J || (correction.rows() != per_joint && correction.rows() != per_joint * J)) {
    throw InputError("the learned correction is not " + std::to_string(per_joint) + " (or " +
                     std::to_string(per_joint * J) + ") x " + std::to_string(J));
  }
  const bool cross_joint = correction.rows() == per_joint * J;
  for (int i = 0; i < J; ++i) {
    if (cross_joint) model.C.block(i, learned, 1, per_joint * J) = correction.col(i).transpose();
    else model.C.block(i, learned + i * per_joint, 1, per_joint) = correction.col(i).transpose();
  }
}

Eigen::MatrixXd correction_regressors(const Eigen::Ref<const Eigen::VectorXd>& du, const CorrectionShape& shape,
                                      double sample_time_s) {
  const Eigen::Index N = du.size();
  Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(N, shape.per_joint());
  for (Eigen::Index t = 1; t <= N; ++t) {
    for (int k = 0; k < shape.taps && t - 1 - k >= 0; ++k) phi(t - 1, k) = du(t - 1 - k);
  }
  for (std::size_t f = 0; f < shape.lowpass_time_constants_s.size(); ++f) {
    const double a = std::exp(-sample_time_s / shape.lowpass_time_constants_s[f]);
    double state = 0.0;  // l(t) = a l(t-1) + (1 - a) u(t-1), from rest
    for (Eigen::Index t = 1; t <= N; ++t) {
      state = a * state + (1.0 - a) * du(t - 1);
      phi(t - 1, shape.taps + static_cast<Eigen::Index>(f)) = state;
    }
  }
  return phi;
}

}  // namespace bellows
