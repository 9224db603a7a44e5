#include "engine/learning/learning_transfer_fit.hpp"

#include <algorithm>
#include <cmath>

namespace bellows {
namespace {

/// First-order low-pass of s from rest at s(0): z(k) = a z(k-1) + (1 - a) s(k).
Eigen::VectorXd lowpass(const Eigen::VectorXd& s, double tau_s, double sample_time_s) {
  const double a = std::exp(-sample_time_s / tau_s);
  Eigen::VectorXd z(s.size());
  double state = s.size() > 0 ? s(0) : 0.0;
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    state = a * state + (1.0 - a) * s(k);
    z(k) = state;
  }
  return z;
}

}  // namespace

int RegressorShape::count() const {
  return (constant ? 1 : 0) + taps_behind + taps_ahead + 1 + derivatives +
         static_cast<int>(lowpass_time_constants_s.size()) + 2 * static_cast<int>(nonlinear_leads.size());
}

Eigen::MatrixXd build_regressors(const Eigen::VectorXd& signal, const RegressorShape& shape, int first_center, int rows,
                                 double sample_time_s) {
  const Eigen::Index last = signal.size() - 1;
  const auto at = [&](Eigen::Index k) { return signal(std::clamp<Eigen::Index>(k, 0, last)); };
  std::vector<Eigen::VectorXd> slow;
  for (const double tau : shape.lowpass_time_constants_s) slow.push_back(lowpass(signal, tau, sample_time_s));
  Eigen::MatrixXd phi(rows, shape.count());
  for (int i = 0; i < rows; ++i) {
    const Eigen::Index c = first_center + i;
    int col = 0;
    if (shape.constant) phi(i, col++) = 1.0;
    for (int k = -shape.taps_behind; k <= shape.taps_ahead; ++k) phi(i, col++) = at(c + k);
    // Differences, not derivatives: dimensionless, so one ridge weight suits every order.
    const double m2 = at(c - 2), m1 = at(c - 1), z = at(c), p1 = at(c + 1), p2 = at(c + 2);
    const double differences[4] = {0.5 * (p1 - m1), p1 - 2.0 * z + m1, 0.5 * (p2 - 2.0 * p1 + 2.0 * m1 - m2),
                                   p2 - 4.0 * p1 + 6.0 * z - 4.0 * m1 + m2};
    for (int d = 0; d < shape.derivatives && d < 4; ++d) phi(i, col++) = differences[d];
    for (const Eigen::VectorXd& z_slow : slow) phi(i, col++) = z_slow(std::clamp<Eigen::Index>(c, 0, last));
    for (const int lead : shape.nonlinear_leads) {
      const double step = 0.5 * (at(c + lead + 1) - at(c + lead - 1));  // per sample
      phi(i, col++) = std::abs(step) * step / sample_time_s;
      phi(i, col++) = std::abs(at(c + lead)) * step;
    }
  }
  return phi;
}

Eigen::MatrixXd build_causal_regressors(const Eigen::VectorXd& input, int taps,
                                        const std::vector<double>& lowpass_time_constants_s, double sample_time_s) {
  const Eigen::Index n = input.size();
  std::vector<Eigen::VectorXd> slow;
  for (const double tau : lowpass_time_constants_s) {
    Eigen::VectorXd from_zero(n + 1);
    from_zero << 0.0, input;  // the correction is zero before the trial
    slow.push_back(lowpass(from_zero, tau, sample_time_s));
  }
  Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(n, taps + static_cast<Eigen::Index>(slow.size()));
  for (Eigen::Index t = 1; t <= n; ++t) {
    for (int k = 0; k < taps && t - 1 - k >= 0; ++k) phi(t - 1, k) = input(t - 1 - k);
    for (std::size_t f = 0; f < slow.size(); ++f) phi(t - 1, taps + static_cast<Eigen::Index>(f)) = slow[f](t - 1);
  }
  return phi;
}

RidgeAccumulator::RidgeAccumulator(int parameters, int groups)
    : gram_(static_cast<std::size_t>(groups), Eigen::MatrixXd::Zero(parameters, parameters)),
      moment_(static_cast<std::size_t>(groups), Eigen::VectorXd::Zero(parameters)),
      rows_(static_cast<std::size_t>(groups), 0) {}

void RidgeAccumulator::add(int group, const Eigen::MatrixXd& regressors, const Eigen::VectorXd& target) {
  const auto g = static_cast<std::size_t>(group);
  gram_[g].selfadjointView<Eigen::Lower>().rankUpdate(regressors.transpose());
  moment_[g].noalias() += regressors.transpose() * target;
  rows_[g] += regressors.rows();
}

long RidgeAccumulator::rows(int left_out) const {
  long total = 0;
  for (std::size_t g = 0; g < rows_.size(); ++g) {
    if (static_cast<int>(g) != left_out) total += rows_[g];
  }
  return total;
}

Eigen::VectorXd RidgeAccumulator::solve(double relative_ridge, int left_out) const {
  if (rows(left_out) == 0 || gram_.empty()) return {};
  const Eigen::Index p = gram_.front().rows();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(p);
  for (std::size_t g = 0; g < gram_.size(); ++g) {
    if (static_cast<int>(g) == left_out) continue;
    a.triangularView<Eigen::Lower>() += gram_[g];
    b += moment_[g];
  }
  const double scale = a.diagonal().sum() / static_cast<double>(p);
  if (!(scale > 0.0)) return {};
  a.diagonal().array() += relative_ridge * scale;
  Eigen::VectorXd theta = a.selfadjointView<Eigen::Lower>().ldlt().solve(b);
  if (!theta.allFinite()) return {};
  return theta;
}

}  // namespace bellows
