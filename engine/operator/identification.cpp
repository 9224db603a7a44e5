#include "engine/operator/identification.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <optional>
#include <string>

#include <unsupported/Eigen/MatrixFunctions>

#include "engine/model/arm_model.hpp"
#include "engine/base/errors.hpp"
#include "engine/model/valve_flow.hpp"
#include "engine/base/units.hpp"
#include "engine/operator/levenberg_marquardt.hpp"

namespace bellows {
namespace {

constexpr int kMaxIterations = 100;
constexpr double kRelativeCostTolerance = 1e-12;
constexpr double kArxMinimumStep_s = 0.02;  // equation error is fitted no faster than this: less noise bias

Eigen::Vector3d to_log_parameters(const ModelParameters& m) {
  return {std::log(m.kappa_rad_per_bar), std::log(m.omega0_rad_per_s), std::log(m.damping)};
}

ModelParameters from_log_parameters(const Eigen::Vector3d& p) {
  ModelParameters m;
  m.kappa_rad_per_bar = std::exp(p(0));
  m.omega0_rad_per_s = std::exp(p(1));
  m.damping = std::exp(p(2));
  return m;
}

// Second-order ARX y(k) = a1 y(k-1) + a2 y(k-2) + b1 u(k-1) + b2 u(k-2) on decimated data, mapped to
// continuous kappa, omega0, delta. Empty when its poles are not those of a stable second-order arm.
std::optional<ModelParameters> arx_estimate(const IdentificationData& data) {
  const int stride = std::max(1, static_cast<int>(std::lround(kArxMinimumStep_s / data.sample_time_s)));
  const double h = stride * data.sample_time_s;
  const Eigen::Index count = (data.angle_rad.size() - 1) / stride + 1;
  if (count < 10) return std::nullopt;
  Eigen::MatrixXd regressors(count - 2, 4);
  Eigen::VectorXd target(count - 2);
  auto y = [&](Eigen::Index k) { return data.angle_rad(k * stride); };
  auto u = [&](Eigen::Index k) { return data.pressure_difference_bar(k * stride); };
  for (Eigen::Index k = 2; k < count; ++k) {
    regressors.row(k - 2) << y(k - 1), y(k - 2), u(k - 1), u(k - 2);
    target(k - 2) = y(k);
  }
  const Eigen::Vector4d theta = regressors.colPivHouseholderQr().solve(target);
  const double a1 = theta(0), a2 = theta(1);
  const double gain = (theta(2) + theta(3)) / (1.0 - a1 - a2);
  // Poles: z^2 - a1 z - a2 = 0.
  const std::complex<double> root = std::sqrt(std::complex<double>(a1 * a1 + 4.0 * a2, 0.0));
  const std::complex<double> z1 = 0.5 * (a1 + root), z2 = 0.5 * (a1 - root);
  if (std::abs(z1) >= 1.0 || std::abs(z2) >= 1.0 || std::abs(z1) == 0.0 || std::abs(z2) == 0.0) return std::nullopt;
  if (z1.imag() == 0.0 && (z1.real() <= 0.0 || z2.real() <= 0.0)) return std::nullopt;
  const std::complex<double> s1 = std::log(z1) / h, s2 = std::log(z2) / h;
  const double omega0 = std::sqrt(std::abs(s1 * s2));
  const double damping = -(s1 + s2).real() / (2.0 * omega0);
  if (!(gain > 0.0) || !(omega0 > 0.0) || !(damping > 0.0) || !std::isfinite(gain + omega0 + damping)) {
    return std::nullopt;
  }
  ModelParameters m;
  m.kappa_rad_per_bar = gain;
  m.omega0_rad_per_s = omega0;
  m.damping = damping;
  return m;
}

double standard_deviation(const Eigen::VectorXd& v) {
  return std::sqrt((v.array() - v.mean()).square().sum() / static_cast<double>(v.size()));
}

}  // namespace

IdentificationData identification_data(const TrialRecord& record, const ControllerParameters& controller, double tick_s,
                                       int joint) {
  IdentificationData data;
  data.sample_time_s = tick_s;
  const TrialTicks& t = record.joint_ticks(joint);
  const Eigen::VectorXd& supply_bar = record.supply_bar;
  data.angle_rad = t.angle_rad;
  const Eigen::Index n = t.angle_rad.size();
  data.pressure_difference_bar.resize(n);
  const GasParameters& gas = controller.gas;
  // Pressure change per unit of mass, with the controller's nominal volume (bar per kg).
  const double bar_per_kg = gas.gas_constant_J_per_kgK * gas.temperature_K / (controller.volume_l * 1e-3) / kPaPerBar;
  auto capacity = [&](double from_bar, double to_bar) {
    return controller.valves_per_port *
           iso6358_mass_flow_kg_per_s(from_bar * kPaPerBar, to_bar * kPaPerBar, controller.valve_conductance_m3_per_sPa,
                                      controller.valve_critical_ratio, gas.reference_density_kg_per_m3);
  };
  // Mean pressure of one chamber over tick k: the valve pulse, open from the tick's start for the
  // fraction `open`, counts (1 - open/2) of its rise; the rest of the change (the bellows' volume
  // following the arm) is spread over the whole tick and counts one half.
  auto tick_mean = [&](double start, double end, double inlet, double outlet, double supply) {
    const double in = std::clamp(inlet, 0.0, 1.0), out = std::clamp(outlet, 0.0, 1.0);
    const double pulse = bar_per_kg * tick_s * (in * capacity(supply, start) - out * capacity(start, gas.ambient_bar));
    const double open = std::max(in, out);
    return start + pulse * (1.0 - 0.5 * open) + 0.5 * (end - start - pulse);
  };
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    data.pressure_difference_bar(k) =
        tick_mean(t.pressure_a_bar(k), t.pressure_a_bar(k + 1), t.inlet_a(k), t.outlet_a(k), supply_bar(k)) -
        tick_mean(t.pressure_b_bar(k), t.pressure_b_bar(k + 1), t.inlet_b(k), t.outlet_b(k), supply_bar(k));
  }
  if (n > 0) {
    data.pressure_difference_bar(n - 1) =
        n > 1 ? data.pressure_difference_bar(n - 2) : t.pressure_a_bar(0) - t.pressure_b_bar(0);
  }
  return data;
}

Eigen::VectorXd simulate_arm_angle(const ModelParameters& model, const IdentificationData& data) {
  const Eigen::Index n = data.angle_rad.size();
  Eigen::VectorXd angle(n);
  if (n == 0) return angle;
  // Zero-order hold: the input of each step is the tick's mean pressure difference.
  const DiscreteArmModel d = discretize_arm_model(model, data.sample_time_s);
  Eigen::Vector2d x(data.angle_rad(0) / std::numbers::pi, 0.0);
  angle(0) = data.angle_rad(0);
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    x = d.A * x + d.B * data.pressure_difference_bar(k);
    angle(k + 1) = std::numbers::pi * x(0);
  }
  return angle;
}

double normalized_fit_percent(const Eigen::VectorXd& measured, const Eigen::VectorXd& predicted) {
  const double spread = (measured.array() - measured.mean()).matrix().norm();
  if (!(spread > 0.0)) return 0.0;
  return 100.0 * (1.0 - (measured - predicted).norm() / spread);
}

ArmModelFit fit_arm_model(const IdentificationData& data, const ModelParameters& fallback, StopFlag stop) {
  const Eigen::Index n = data.angle_rad.size();
  if (n < 50 || data.pressure_difference_bar.size() != n || !(data.sample_time_s > 0.0)) {
    throw InputError("identification: need at least 50 samples of angle and pressure difference, got " +
                     std::to_string(n));
  }
  if (!data.angle_rad.allFinite() || !data.pressure_difference_bar.allFinite()) {
    throw InputError("identification: the recorded data contain non-finite values");
  }
  constexpr double kMinimumSpread_rad = 1.0 * std::numbers::pi / 180.0, kMinimumSpread_bar = 1e-3;
  if (standard_deviation(data.angle_rad) < kMinimumSpread_rad ||
      standard_deviation(data.pressure_difference_bar) < kMinimumSpread_bar) {
    throw InputError("identification: the trial did not excite the arm (angle or pressure barely moved)");
  }

  ArmModelFit fit;
  fit.initial = arx_estimate(data).value_or(fallback);
  Eigen::Vector3d p = to_log_parameters(fit.initial);
  auto residual = [&](const Eigen::Vector3d& q) -> Eigen::VectorXd {
    if (stop_is_requested(stop)) throw Cancelled("identification stopped by a signal");
    return simulate_arm_angle(from_log_parameters(q), data) - data.angle_rad;
  };
  const Eigen::Vector3d difference_steps = Eigen::Vector3d::Constant(1e-6);  // in log parameters
  const LeastSquaresSolution<Eigen::Vector3d> solution =
      levenberg_marquardt(residual, p, residual(p), difference_steps, kMaxIterations, kRelativeCostTolerance);
  fit.iterations = solution.iterations;
  fit.converged = solution.converged;
  p = solution.parameters;
  const Eigen::VectorXd& r = solution.residual;
  const double cost = solution.cost;
  fit.model = from_log_parameters(p);
  fit.fit_percent = normalized_fit_percent(data.angle_rad, data.angle_rad + r);
  fit.rms_residual_deg = std::sqrt(cost / static_cast<double>(n)) * 180.0 / std::numbers::pi;
  return fit;
}

}  // namespace bellows
