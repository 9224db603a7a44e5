#include "engine/learning/lifted_operators.hpp"

#include <cmath>

namespace bellows {

void apply_lifted(const DiscreteArmModel& model, const Eigen::Ref<const Eigen::VectorXd>& v,
                  Eigen::Ref<Eigen::VectorXd> out) {
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (Eigen::Index t = 0; t < v.size(); ++t) {
    x = model.A * x + model.B * v(t);
    out(t) = model.C * x;
  }
}

void apply_lifted_transpose(const DiscreteArmModel& model, const Eigen::Ref<const Eigen::VectorXd>& e,
                            Eigen::Ref<Eigen::VectorXd> out) {
  // (P'e)(t) = sum_{k >= t} C A^(k-t) B e(k): the adjoint state lambda(t) = A' lambda(t+1) + C' e(t).
  Eigen::Vector2d adjoint = Eigen::Vector2d::Zero();
  const Eigen::Matrix2d At = model.A.transpose();
  const Eigen::Vector2d Ct = model.C.transpose();
  for (Eigen::Index t = e.size() - 1; t >= 0; --t) {
    adjoint = At * adjoint + Ct * e(t);
    out(t) = model.B.dot(adjoint);
  }
}

std::complex<double> lifted_symbol(const DiscreteArmModel& model, double theta_rad_per_sample) {
  // C (I - A z^-1)^-1 B with z = e^{i theta}
  const std::complex<double> z_inverse = std::polar(1.0, -theta_rad_per_sample);
  const Eigen::Matrix2cd resolvent = Eigen::Matrix2cd::Identity() - model.A.cast<std::complex<double>>() * z_inverse;
  const Eigen::Vector2cd solved = resolvent.partialPivLu().solve(model.B.cast<std::complex<double>>());
  return model.C.cast<std::complex<double>>() * solved;
}

double lifted_norm(const DiscreteArmModel& model, int samples) {
  Eigen::VectorXd v = Eigen::VectorXd::Ones(samples), image(samples), back(samples);
  double estimate = 0.0;
  constexpr int kMaxIterations = 500;
  constexpr double kTolerance = 1e-7;
  for (int i = 0; i < kMaxIterations; ++i) {
    v.normalize();
    apply_lifted(model, v, image);
    apply_lifted_transpose(model, image, back);
    const double next = std::sqrt(v.dot(back));
    v = back;
    if (std::abs(next - estimate) <= kTolerance * next) return next;
    estimate = next;
  }
  return estimate;
}

}  // namespace bellows
