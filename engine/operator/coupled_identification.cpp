#include "engine/operator/coupled_identification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"
#include "engine/operator/levenberg_marquardt.hpp"

namespace bellows {
namespace {

constexpr int kCoupledFitMaxIterations = 100;
constexpr double kCoupledFitRelativeCostTolerance = 1e-10;
constexpr double kRelativeStep = 1e-6;  // finite-difference step, relative to the entry's matrix scale
constexpr Eigen::Index kMinimumSamples = 50;

// The 3 J^2 entries as one parameter vector (column-major per matrix: per_angle, per_velocity, per_bar).
Eigen::VectorXd to_parameters(const CoupledJointDynamics& d) {
  const Eigen::Index m = static_cast<Eigen::Index>(d.joints()) * d.joints();
  Eigen::VectorXd p(3 * m);
  p.segment(0, m) = Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(d.per_angle).data(), m);
  p.segment(m, m) = Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(d.per_velocity).data(), m);
  p.segment(2 * m, m) = Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(d.per_bar).data(), m);
  return p;
}

CoupledJointDynamics from_parameters(const Eigen::VectorXd& p, int J) {
  const Eigen::Index m = static_cast<Eigen::Index>(J) * J;
  CoupledJointDynamics d;
  d.per_angle = Eigen::Map<const Eigen::MatrixXd>(p.data(), J, J);
  d.per_velocity = Eigen::Map<const Eigen::MatrixXd>(p.data() + m, J, J);
  d.per_bar = Eigen::Map<const Eigen::MatrixXd>(p.data() + 2 * m, J, J);
  return d;
}

// Each entry's finite-difference step: relative to the largest entry of its matrix (the
// off-diagonal entries start at zero).
Eigen::VectorXd difference_steps(const CoupledJointDynamics& d) {
  const Eigen::Index m = static_cast<Eigen::Index>(d.joints()) * d.joints();
  Eigen::VectorXd steps(3 * m);
  const double scales[3] = {d.per_angle.cwiseAbs().maxCoeff(), d.per_velocity.cwiseAbs().maxCoeff(),
                            d.per_bar.cwiseAbs().maxCoeff()};
  for (int block = 0; block < 3; ++block)
    steps.segment(block * m, m).setConstant(kRelativeStep * std::max(scales[block], 1.0));
  return steps;
}

double spread(const Eigen::VectorXd& v) {
  return std::sqrt((v.array() - v.mean()).square().sum() / static_cast<double>(std::max<Eigen::Index>(v.size(), 1)));
}

void check_trials(std::span<const JointIdentificationData> trials) {
  if (trials.empty()) throw InputError("identification: no trials to fit the coupled model on");
  const int J = trials.front().joints();
  if (!valid_joint_count(J)) throw InputError("identification: 1 to " + std::to_string(kMaxJoints) + " joints");
  JointVector largest_spread = JointVector::Zero(J);
  for (const JointIdentificationData& t : trials) {
    if (t.joints() != J || t.pressure_difference_bar.cols() != J ||
        t.pressure_difference_bar.rows() != t.angle_rad.rows()) {
      throw InputError("identification: every trial of the coupled fit needs the same " + std::to_string(J) +
                       " joints");
    }
    if (t.angle_rad.rows() < kMinimumSamples || !(t.sample_time_s > 0.0) ||
        t.sample_time_s != trials.front().sample_time_s) {
      throw InputError("identification: each trial needs at least 50 samples at one sample time, got " +
                       std::to_string(t.angle_rad.rows()));
    }
    if (!t.angle_rad.allFinite() || !t.pressure_difference_bar.allFinite()) {
      throw InputError("identification: the recorded data contain non-finite values");
    }
    for (int j = 0; j < J; ++j) largest_spread(j) = std::max(largest_spread(j), spread(t.angle_rad.col(j)));
  }
  for (int j = 0; j < J; ++j) {
    if (largest_spread(j) < 1.0 * kRadPerDeg) {
      throw InputError("identification: joint " + std::to_string(j + 1) + " never moved (no trial excited it)");
    }
  }
}

}  // namespace

JointIdentificationData joint_identification_data(const TrialRecord& record, const ControllerParameters& controller,
                                                  double tick_s, double rest_s) {
  const int J = record.joint_count();
  JointIdentificationData data;
  data.sample_time_s = tick_s;
  const Eigen::Index n = record.tick_time_s.size();
  data.angle_rad.resize(n, J);
  data.pressure_difference_bar.resize(n, J);
  const Eigen::Index rest = std::clamp<Eigen::Index>(std::lround(rest_s / tick_s), 1, std::max<Eigen::Index>(n, 1));
  for (int j = 0; j < J; ++j) {
    const IdentificationData single = identification_data(record, controller, tick_s, j);
    if (n == 0) continue;
    data.angle_rad.col(j) = single.angle_rad.array() - single.angle_rad.head(rest).mean();
    data.pressure_difference_bar.col(j) =
        single.pressure_difference_bar.array() - single.pressure_difference_bar.head(rest).mean();
  }
  return data;
}

IdentificationData single_joint_data(const JointIdentificationData& data, int joint) {
  IdentificationData single;
  single.sample_time_s = data.sample_time_s;
  single.angle_rad = data.angle_rad.col(joint);
  single.pressure_difference_bar = data.pressure_difference_bar.col(joint);
  return single;
}

Eigen::MatrixXd simulate_joint_angles(const CoupledJointDynamics& dynamics, const JointIdentificationData& data) {
  const Eigen::Index n = data.angle_rad.rows();
  const int J = dynamics.joints();
  Eigen::MatrixXd angle(n, J);
  if (n == 0) return angle;
  const MultiJointModel d = discretize_joint_dynamics(dynamics, data.sample_time_s);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * J);
  for (int j = 0; j < J; ++j) x(2 * j) = data.angle_rad(0, j) / std::numbers::pi;
  angle.row(0) = data.angle_rad.row(0);
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    x = d.A * x + d.B * data.pressure_difference_bar.row(k).transpose();
    angle.row(k + 1) = std::numbers::pi * (d.C * x).transpose();
  }
  return angle;
}

JointVector joint_fit_percent(const CoupledJointDynamics& dynamics, std::span<const JointIdentificationData> trials) {
  const int J = dynamics.joints();
  Eigen::Index total = 0;
  for (const JointIdentificationData& t : trials) total += t.angle_rad.rows();
  Eigen::MatrixXd measured(total, J), predicted(total, J);
  Eigen::Index at = 0;
  for (const JointIdentificationData& t : trials) {
    measured.middleRows(at, t.angle_rad.rows()) = t.angle_rad;
    predicted.middleRows(at, t.angle_rad.rows()) = simulate_joint_angles(dynamics, t);
    at += t.angle_rad.rows();
  }
  JointVector fit(J);
  for (int j = 0; j < J; ++j) fit(j) = normalized_fit_percent(measured.col(j), predicted.col(j));
  return fit;
}

CoupledModelFit fit_coupled_model(std::span<const JointIdentificationData> trials, const CoupledJointDynamics& initial,
                                  StopFlag stop) {
  check_trials(trials);
  const int J = trials.front().joints();
  if (initial.joints() != J)
    throw InputError("identification: the starting model has another joint count than the trials");
  Eigen::Index total = 0;
  for (const JointIdentificationData& t : trials) total += t.angle_rad.size();
  // Every trial's simulated minus measured angles, stacked (an unstable candidate gives infinities).
  auto residual = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    if (stop_is_requested(stop)) throw Cancelled("identification stopped by a signal");
    const CoupledJointDynamics d = from_parameters(p, J);
    Eigen::VectorXd r(total);
    Eigen::Index at = 0;
    for (const JointIdentificationData& t : trials) {
      const Eigen::MatrixXd error = simulate_joint_angles(d, t) - t.angle_rad;
      r.segment(at, error.size()) = Eigen::Map<const Eigen::VectorXd>(error.data(), error.size());
      at += error.size();
    }
    if (!r.allFinite()) r.setConstant(std::numeric_limits<double>::infinity());
    return r;
  };

  CoupledModelFit fit;
  fit.initial = initial;
  Eigen::VectorXd p = to_parameters(initial);
  const Eigen::VectorXd steps = difference_steps(initial);
  const Eigen::VectorXd start_residual = residual(p);
  if (!std::isfinite(start_residual.squaredNorm()))
    throw InputError("identification: the coupled model's starting point is unstable on the data");
  const LeastSquaresSolution<Eigen::VectorXd> solution = levenberg_marquardt(
      residual, p, start_residual, steps, kCoupledFitMaxIterations, kCoupledFitRelativeCostTolerance);
  fit.iterations = solution.iterations;
  fit.converged = solution.converged;
  p = solution.parameters;
  const double cost = solution.cost;
  fit.dynamics = from_parameters(p, J);
  fit.fit_percent = joint_fit_percent(fit.dynamics, trials);
  fit.rms_residual_deg = std::sqrt(cost / static_cast<double>(total)) / kRadPerDeg;
  return fit;
}

}  // namespace bellows
