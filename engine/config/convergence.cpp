#include "engine/config/convergence.hpp"

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include <unsupported/Eigen/MatrixFunctions>

#include "engine/model/arm_model.hpp"

namespace bellows {
namespace {

using Complex = std::complex<double>;

// Arm behind a first-order pressure response, x = (alpha/pi, alpha_dot/(10 pi), dp), ZOH at T.
struct ActuatedArm {
  Eigen::Matrix3d A;
  Eigen::Vector3d B;
  Eigen::RowVector3d C;
};

ActuatedArm actuated_arm(const ModelParameters& arm, double tau_p_s, double ambient_bar, double sample_time_s) {
  constexpr double kVelocityScale = 10.0 * std::numbers::pi;  // x2 = alpha_dot / (10 pi), spec section 2
  Eigen::Matrix2d Ac;
  Eigen::Vector2d Bc;
  continuous_arm_model(arm, Ac, Bc);
  Eigen::Matrix4d augmented = Eigen::Matrix4d::Zero();
  augmented.topLeftCorner<2, 2>() = Ac;
  augmented.block<2, 1>(0, 2) = Bc;  // the arm is driven by the achieved pressure difference
  augmented(2, 2) = -1.0 / tau_p_s;
  augmented(2, 3) = 1.0 / tau_p_s;  // which follows the commanded one with time constant tau_p
  augmented(2, 1) = -2.0 * ambient_bar * arm.volume_gain_per_rad * kVelocityScale;  // minus the bounce-back
  const Eigen::Matrix4d exponential = (augmented * sample_time_s).exp();
  ActuatedArm d;
  d.A = exponential.topLeftCorner<3, 3>();
  d.B = exponential.block<3, 1>(0, 3);
  d.C << 1.0, 0.0, 0.0;
  return d;
}

// Closed-loop symbol from the correction u(t) to the output y(t+1), with the PID of section 3
// (u_pid = -(k_p + k_i T / (1 - z^-1) + k_d (1 - z^-1) / T) y for a zero reference).
Complex closed_loop_symbol(const ActuatedArm& arm, const ControllerParameters& pid, double T, double theta) {
  const Complex z = std::polar(1.0, theta);
  const Complex z_inverse = 1.0 / z;
  const Eigen::Matrix3cd resolvent = z * Eigen::Matrix3cd::Identity() - arm.A.cast<Complex>();
  const Complex G = arm.C.cast<Complex>() * resolvent.partialPivLu().solve(arm.B.cast<Complex>());
  const Complex controller = pid.k_p + pid.k_i_per_s * T / (1.0 - z_inverse) + pid.k_d_s * (1.0 - z_inverse) / T;
  return z * G / (1.0 + G * controller);
}

ContractionEstimate estimate(const LearningLaw& law, const Configuration& config, double kappa_scale,
                             double omega0_scale, double theta_low, int points) {
  ModelParameters truth = config.model;
  truth.kappa_rad_per_bar *= kappa_scale;
  truth.omega0_rad_per_s *= omega0_scale;
  const double T = config.timing.sample_s();
  const ActuatedArm arm = actuated_arm(truth, config.controller.tau_p_s, config.controller.gas.ambient_bar, T);
  ContractionEstimate e{kappa_scale, omega0_scale, 0.0, 0.0};
  // Log-spaced from the lowest resolved frequency to Nyquist: slow modes and resonances both matter.
  for (int i = 0; i < points; ++i) {
    const double fraction = points == 1 ? 0.0 : static_cast<double>(i) / (points - 1);
    const double theta = theta_low * std::pow(std::numbers::pi / theta_low, fraction);
    const std::optional<LawFrequencyResponse> response = law.frequency_response(theta);
    if (!response) return e;
    const Complex lambda =
        response->from_correction - response->from_error * closed_loop_symbol(arm, config.controller, T, theta);
    if (std::abs(lambda) > e.contraction) {
      e.contraction = std::abs(lambda);
      e.worst_frequency_hz = theta / (2.0 * std::numbers::pi * T);
    }
  }
  return e;
}

constexpr int kFrequencyPoints = 600;

}  // namespace

std::string convergence_warning(const ConvergencePrediction& p, const std::string& law_name) {
  const bool nominal_diverges = p.nominal.contraction > 1.0 + kDivergenceTolerance;
  if (!nominal_diverges && p.diverging_points == 0) return {};
  const ContractionEstimate& w = nominal_diverges ? p.nominal : p.worst;
  char text[320];
  if (nominal_diverges) {
    std::snprintf(text, sizeof text,
                  "learning law '%s' is predicted to diverge on the nominal model: contraction %.3f > 1 at %.2f Hz",
                  law_name.c_str(), w.contraction, w.worst_frequency_hz);
  } else {
    std::snprintf(text, sizeof text,
                  "learning law '%s' may diverge if the arm differs from the model by up to %.0f %%: contraction "
                  "%.3f > 1 at %.2f Hz for kappa x%.2f, omega0 x%.2f (%d of %zu grid points; nominal %.3f)",
                  law_name.c_str(), 100.0 * p.model_error, w.contraction, w.worst_frequency_hz, w.kappa_scale,
                  w.omega0_scale, p.diverging_points, p.grid.size(), p.nominal.contraction);
  }
  return text;
}

ConvergencePrediction predict_convergence(const LearningLaw& law, const Configuration& config, int samples,
                                          StopFlag stop) {
  ConvergencePrediction p;
  if (samples < 2 || !law.frequency_response(std::numbers::pi / 2.0)) return p;
  p.available = true;
  const double T = config.timing.sample_s();
  const double theta_low = 2.0 * std::numbers::pi / samples;
  p.band_low_hz = 1.0 / (samples * T);
  p.band_high_hz = 0.5 / T;
  p.model_error = config.ilc.prediction_model_error;
  p.nominal = estimate(law, config, 1.0, 1.0, theta_low, kFrequencyPoints);
  const int n = config.ilc.prediction_grid_points;
  p.worst = p.nominal;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) {
      if (stop_is_requested(stop)) throw Cancelled("convergence prediction stopped by a signal");
      const double a = n == 1 ? 0.0 : -1.0 + 2.0 * i / (n - 1);
      const double b = n == 1 ? 0.0 : -1.0 + 2.0 * k / (n - 1);
      const ContractionEstimate e =
          estimate(law, config, 1.0 + a * p.model_error, 1.0 + b * p.model_error, theta_low, kFrequencyPoints);
      p.grid.push_back(e);
      if (e.contraction > 1.0 + kDivergenceTolerance) ++p.diverging_points;
      if (e.contraction > p.worst.contraction) p.worst = e;
    }
  }
  p.warning = convergence_warning(p, law.name());
  return p;
}

}  // namespace bellows
