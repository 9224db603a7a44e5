#include "engine/learning/noilc_riccati.hpp"

#include <cmath>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/learning/lifted_operators.hpp"

namespace bellows {

RiccatiNoilcSolver::RiccatiNoilcSolver(const DiscreteArmModel& model, const IlcParameters& weights, int samples,
                                       double proximal_weight)
    : A_(model.A),
      B_(model.B),
      C_(model.C),
      m_(weights.m),
      s_(weights.s),
      rate_weight_(weights.w / (model.sample_time_s * model.sample_time_s)),
      proximal_weight_(proximal_weight),
      gains_(3, samples),
      inverse_curvature_(samples),
      feedforward_(samples) {
  if (samples < 2) throw InputError("norm-optimal ILC needs at least 2 samples, got " + std::to_string(samples));
  if (!(m_ >= 0.0) || !(s_ >= 0.0) || !(weights.w >= 0.0) || !(proximal_weight >= 0.0)) {
    throw InputError("norm-optimal ILC: the weights m, s, w must not be negative");
  }
  // Augmented model z = [dx; v(t-1)]: Ab = [[A, 0], [0, 0]], Bb = [B; 1], Cb = [C, 0], E = [0, 0, 1].
  Eigen::Matrix3d Ab = Eigen::Matrix3d::Zero();
  Ab.topLeftCorner<2, 2>() = A_;
  Eigen::Vector3d Bb;
  Bb << B_, 1.0;
  Eigen::RowVector3d Cb;
  Cb << C_, 0.0;
  const Eigen::Matrix3d output_weight = m_ * Cb.transpose() * Cb;
  Eigen::Matrix3d P = output_weight;  // P_N
  for (int t = samples - 1; t >= 0; --t) {
    const double W = rate_weight(t);
    Eigen::Matrix3d Q = t >= 1 ? output_weight : Eigen::Matrix3d::Zero();
    Q(2, 2) += W;
    const Eigen::Vector3d PB = P * Bb;
    const double curvature = s_ + proximal_weight_ + W + Bb.dot(PB);
    Eigen::RowVector3d cross = PB.transpose() * Ab;  // H_ux = N_t' + Bb' P Ab, N_t = -W E'
    cross(2) -= W;
    if (!(curvature > 0.0) || !std::isfinite(curvature)) {
      throw InputError("norm-optimal ILC: the weights do not give a positive definite cost (need s + w > 0 or m > 0)");
    }
    gains_.col(t) = -cross.transpose() / curvature;
    inverse_curvature_(t) = 1.0 / curvature;
    P = Q + Ab.transpose() * P * Ab - cross.transpose() * cross / curvature;
    P = 0.5 * (P + P.transpose()).eval();
  }
}

double RiccatiNoilcSolver::rate_weight(int t) const {
  // D's rows are (u(t+1) - u(t)) / T for t = 0..N-2 and the last row repeats the one before: the
  // change at t = N-1 counts twice, and u(0) has no change of its own.
  if (t == 0) return 0.0;
  return t == samples() - 1 ? 2.0 * rate_weight_ : rate_weight_;
}

void RiccatiNoilcSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& u_j,
                               const Eigen::Ref<const Eigen::VectorXd>& e_j,
                               const Eigen::Ref<const Eigen::VectorXd>& target, Eigen::Ref<Eigen::VectorXd> u_next) {
  const int n = samples();
  const bool proximal = proximal_weight_ > 0.0;
  const Eigen::Matrix2d At = A_.transpose();
  const Eigen::Vector2d Ct = C_.transpose();
  // Backward pass for the affine terms: p = [p_x; p_v], starting from p_N = -m e(N) Cb'.
  // Error e_j(t) of sample t is entry t-1 of e_j.
  Eigen::Vector2d p_x = -m_ * e_j(n - 1) * Ct;
  double p_v = 0.0;
  for (int t = n - 1; t >= 0; --t) {
    const double W = rate_weight(t);
    const double rate = t >= 1 ? u_j(t) - u_j(t - 1) : 0.0;
    double r = W * rate;
    if (proximal) r -= proximal_weight_ * (target(t) - u_j(t));
    const double h = r + B_.dot(p_x) + p_v;
    feedforward_(t) = -h * inverse_curvature_(t);
    const Eigen::Vector3d K = gains_.col(t);
    Eigen::Vector2d next_x = At * p_x + K.head<2>() * h;
    if (t >= 1) next_x -= m_ * e_j(t - 1) * Ct;
    p_x = next_x;
    p_v = -W * rate + K(2) * h;
  }
  // Forward pass: v(t) = K_t z(t) + k_t.
  Eigen::Vector2d dx = Eigen::Vector2d::Zero();
  double previous_change = 0.0;
  for (int t = 0; t < n; ++t) {
    const Eigen::Vector3d K = gains_.col(t);
    const double change = K.head<2>().dot(dx) + K(2) * previous_change + feedforward_(t);
    u_next(t) = u_j(t) + change;
    dx = A_ * dx + B_ * change;
    previous_change = change;
  }
}

std::size_t RiccatiNoilcSolver::memory_bytes() const {
  return sizeof(double) * static_cast<std::size_t>(gains_.size() + inverse_curvature_.size() + feedforward_.size());
}

NormOptimalRiccati::NormOptimalRiccati(const DiscreteArmModel& model, const IlcParameters& weights, int samples)
    : model_(model), weights_(weights), solver_(model, weights, samples) {}

void NormOptimalRiccati::update(const Eigen::Ref<const Eigen::VectorXd>& u_j,
                                const Eigen::Ref<const Eigen::VectorXd>& e_j, Eigen::Ref<Eigen::VectorXd> u_next) {
  solver_.solve(u_j, e_j, u_j, u_next);
}

std::optional<LawFrequencyResponse> NormOptimalRiccati::frequency_response(double theta_rad_per_sample) const {
  return norm_optimal_frequency_response(model_, weights_, theta_rad_per_sample);
}

LawFrequencyResponse norm_optimal_frequency_response(const DiscreteArmModel& model, const IlcParameters& weights,
                                                     double theta_rad_per_sample) {
  // U_{j+1} = H^-1 [(m|P|^2 + s) U_j + m conj(P) E_j],  H = m|P|^2 + s + w |D|^2,  |D|^2 = (2 - 2 cos)/T^2
  const std::complex<double> P = lifted_symbol(model, theta_rad_per_sample);
  const double T = model.sample_time_s;
  const double rate_gain = (2.0 - 2.0 * std::cos(theta_rad_per_sample)) / (T * T);
  const double tracking = weights.m * std::norm(P) + weights.s;
  const double hessian = tracking + weights.w * rate_gain;
  return {tracking / hessian, weights.m * std::conj(P) / hessian};
}

}  // namespace bellows
