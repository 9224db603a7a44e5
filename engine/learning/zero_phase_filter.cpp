#include "engine/learning/zero_phase_filter.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include "engine/base/errors.hpp"

namespace bellows {

ZeroPhaseLowPass::ZeroPhaseLowPass(double cutoff_hz, double sample_time_s) {
  const double nyquist_hz = 0.5 / sample_time_s;
  if (!(cutoff_hz > 0.0) || !(cutoff_hz < nyquist_hz)) {
    std::ostringstream message;
    message << "Q-filter cutoff " << cutoff_hz << " Hz must be positive and below the Nyquist frequency " << nyquist_hz
            << " Hz";
    throw InputError(message.str());
  }
  // Bilinear transform of the analogue Butterworth prototype, pre-warped to the cutoff.
  const double k = std::tan(std::numbers::pi * cutoff_hz * sample_time_s);
  const double norm = 1.0 / (1.0 + std::numbers::sqrt2 * k + k * k);
  b0_ = k * k * norm;
  b1_ = 2.0 * b0_;
  b2_ = b0_;
  a1_ = 2.0 * (k * k - 1.0) * norm;
  a2_ = (1.0 - std::numbers::sqrt2 * k + k * k) * norm;
}

void ZeroPhaseLowPass::apply(const Eigen::Ref<const Eigen::VectorXd>& in, Eigen::Ref<Eigen::VectorXd> out) const {
  const Eigen::Index n = in.size();
  if (n == 0) return;
  // Transposed direct form II; steady state for a constant input x0 (unit DC gain) is
  // s1 = (b1 - a1 + b2 - a2) x0, s2 = (b2 - a2) x0.
  auto pass = [this](auto read, auto write, Eigen::Index count) {
    const double first = read(0);
    double s2 = (b2_ - a2_) * first;
    double s1 = (b1_ - a1_) * first + s2;
    for (Eigen::Index i = 0; i < count; ++i) {
      const double x = read(i);
      const double y = b0_ * x + s1;
      s1 = b1_ * x - a1_ * y + s2;
      s2 = b2_ * x - a2_ * y;
      write(i, y);
    }
  };
  pass([&](Eigen::Index i) { return in(i); }, [&](Eigen::Index i, double y) { out(i) = y; }, n);
  pass([&](Eigen::Index i) { return out(n - 1 - i); }, [&](Eigen::Index i, double y) { out(n - 1 - i) = y; }, n);
}

double ZeroPhaseLowPass::gain(double theta_rad_per_sample) const {
  const std::complex<double> z_inverse = std::polar(1.0, -theta_rad_per_sample);
  const std::complex<double> h =
      (b0_ + b1_ * z_inverse + b2_ * z_inverse * z_inverse) / (1.0 + a1_ * z_inverse + a2_ * z_inverse * z_inverse);
  return std::norm(h);
}

}  // namespace bellows
