#include "engine/learning/noilc_dense.hpp"

#include <string>

#include "engine/base/errors.hpp"
#include "engine/learning/noilc_riccati.hpp"

namespace bellows {

Eigen::MatrixXd rate_difference_matrix(int samples, double sample_time_s) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(samples, samples);
  for (int row = 0; row + 1 < samples; ++row) {
    D(row, row) = -1.0 / sample_time_s;
    D(row, row + 1) = 1.0 / sample_time_s;
  }
  if (samples >= 2) D.row(samples - 1) = D.row(samples - 2);
  return D;
}

NormOptimalDense::NormOptimalDense(const DiscreteArmModel& model, const IlcParameters& weights, int samples)
    : model_(model), weights_(weights) {
  if (samples < 2) throw InputError("norm-optimal ILC needs at least 2 samples, got " + std::to_string(samples));
  lifted_ = model.lifted(samples);
  rate_ = rate_difference_matrix(samples, model.sample_time_s);
  tracking_plus_change_ = weights.m * lifted_.transpose() * lifted_;
  tracking_plus_change_.diagonal().array() += weights.s;
  const Eigen::MatrixXd hessian = tracking_plus_change_ + weights.w * rate_.transpose() * rate_;
  factor_.compute(hessian);
  if (factor_.info() != Eigen::Success) {
    throw InputError(
        "norm-optimal ILC: the weights do not give a positive definite cost (m, s, w must be >= 0, s + w > 0)");
  }
  rhs_.resize(samples);
}

void NormOptimalDense::update(const Eigen::Ref<const Eigen::VectorXd>& u_j,
                              const Eigen::Ref<const Eigen::VectorXd>& e_j, Eigen::Ref<Eigen::VectorXd> u_next) {
  rhs_.noalias() = tracking_plus_change_ * u_j;
  rhs_.noalias() += weights_.m * lifted_.transpose() * e_j;
  u_next = factor_.solve(rhs_);
}

std::optional<LawFrequencyResponse> NormOptimalDense::frequency_response(double theta_rad_per_sample) const {
  return norm_optimal_frequency_response(model_, weights_, theta_rad_per_sample);
}

std::size_t NormOptimalDense::memory_bytes() const {
  const auto n = static_cast<std::size_t>(lifted_.rows());
  return sizeof(double) * (4 * n * n + n);  // P, D, P'MP + S, the factor, and the right-hand side
}

Eigen::VectorXd NormOptimalDense::cost_gradient(const Eigen::VectorXd& u_j, const Eigen::VectorXd& e_j,
                                                const Eigen::VectorXd& u_next) const {
  // J = 1/2 [ e' M e + (u - u_j)' S (u - u_j) + u' D'WD u ],  e = e_j - P (u - u_j)
  const Eigen::VectorXd predicted_error = e_j - lifted_ * (u_next - u_j);
  return -weights_.m * lifted_.transpose() * predicted_error + weights_.s * (u_next - u_j) +
         weights_.w * rate_.transpose() * (rate_ * u_next);
}

}  // namespace bellows
