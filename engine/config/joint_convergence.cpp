#include "engine/config/joint_convergence.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "engine/config/joint_learning_factory.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/learning/closed_loop_model.hpp"
#include "engine/model/arm_chain.hpp"
#include "engine/model/arm_chain_linearization.hpp"

namespace bellows {
namespace {

/// The chain's coupled closed loop seen by the correction, every joint's kappa and omega0 scaled
/// (omega0 through the bellows' stiffness, K = w0^2 M_ii(0)).
StateSpaceModel scaled_closed_loop(const Configuration& config, double kappa_scale, double omega0_scale) {
  ChainParameters chain = chain_of(config.arm);
  for (int i = 0; i < chain.joints; ++i) {
    ChainLink& link = chain.links[static_cast<std::size_t>(i)];
    link.kappa_rad_per_bar *= kappa_scale;
    link.omega0_straight_rad_per_s *= omega0_scale;
    link.stiffness_Nm_per_rad *= omega0_scale * omega0_scale;
  }
  const double T = config.timing.sample_s();
  const MultiJointModel arm = linearize_chain(ArmChain(chain), JointVector::Zero(chain.joints), T);
  const ClosedLoopPrior prior = closed_loop_prior(arm.A, arm.B, T, config.model.volume_gain_per_rad, config.controller);
  return closed_loop_model(prior, CorrectionShape{0, {}}, Eigen::MatrixXd());
}

struct TopSingular {
  double value = 0.0;
  Eigen::VectorXd direction;  // unit right singular vector
  int iterations = 0;
};

/// The largest singular value of `m`: Lanczos on m'm from `start`, every new direction orthogonalized
/// against all before it (Golub and Van Loan 10.1; the extreme Ritz value converges in tens of steps,
/// a handful from a start near the answer), until the Ritz value changes by less than the tolerance.
TopSingular largest_singular(const Eigen::Ref<const Eigen::MatrixXd>& m, const Eigen::VectorXd& start,
                             const LiftedPredictionSettings& settings) {
  const Eigen::Index n = m.cols();
  const int steps = static_cast<int>(std::min<Eigen::Index>(settings.max_iterations, n));
  Eigen::MatrixXd basis(n, steps);
  Eigen::VectorXd diagonal(steps), off_diagonal(steps), image(m.rows()), next(n);
  basis.col(0) = start.normalized();
  TopSingular top;
  double previous = 0.0;
  for (int k = 0; k < steps; ++k) {
    image.noalias() = m * basis.col(k);
    next.noalias() = m.transpose() * image;
    diagonal(k) = basis.col(k).dot(next);
    for (int pass = 0; pass < 2; ++pass)  // twice is enough (Kahan's "twice is enough")
      next.noalias() -= basis.leftCols(k + 1) * (basis.leftCols(k + 1).transpose() * next);
    off_diagonal(k) = next.norm();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz;
    ritz.computeFromTridiagonal(diagonal.head(k + 1), off_diagonal.head(k), Eigen::ComputeEigenvectors);
    const double value = std::sqrt(std::max(0.0, ritz.eigenvalues()(k)));
    top.iterations = k + 1;
    top.value = value;
    top.direction = basis.leftCols(k + 1) * ritz.eigenvectors().col(k);
    const bool exhausted = !(off_diagonal(k) > settings.relative_tolerance * std::max(value * value, 1e-300));
    if (exhausted || (k > 0 && std::abs(value - previous) <= settings.relative_tolerance * value)) break;
    previous = value;
    if (k + 1 < steps) basis.col(k + 1) = next / off_diagonal(k);
  }
  top.direction.normalize();
  return top;
}

/// Where the direction's spectrum (summed over joints, joint-major blocks of `samples`) peaks, among
/// the frequencies a trial resolves, k / (N T) for k = 1..N/2.
double spectrum_peak_hz(const Eigen::VectorXd& direction, int joints, int samples, double sample_time_s) {
  std::vector<std::complex<double>> roots(static_cast<std::size_t>(samples));  // e^{-2 pi i m / N}
  for (int m = 0; m < samples; ++m)
    roots[static_cast<std::size_t>(m)] = std::polar(1.0, -2.0 * std::numbers::pi * m / samples);
  double best_power = -1.0;
  int best = 1;
  for (int k = 1; k <= samples / 2; ++k) {
    double power = 0.0;
    for (int j = 0; j < joints; ++j) {
      std::complex<double> sum = 0.0;
      for (int t = 0; t < samples; ++t)
        sum += direction(j * samples + t) * roots[static_cast<std::size_t>((static_cast<long>(k) * t) % samples)];
      power += std::norm(sum);
    }
    if (power > best_power) best_power = power, best = k;
  }
  return best / (samples * sample_time_s);
}

/// A start with every frequency in it, the same every run (a fixed seed: the prediction is reproducible).
Eigen::VectorXd broadband_start(Eigen::Index size) {
  std::mt19937 generator(1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd start(size);
  for (Eigen::Index i = 0; i < size; ++i) start(i) = uniform(generator);
  return start;
}

/// Each joint's one-joint prediction on its own model; false when a joint's law has none.
bool predict_each_joint(const Configuration& config, int samples, StopFlag stop, JointConvergencePrediction& p) {
  const std::vector<ModelParameters> models = independent_joint_parameters(chain_of(config.arm));
  for (std::size_t j = 0; j < models.size(); ++j) {
    Configuration own = config;
    own.model = models[j];
    own.model.volume_gain_per_rad = config.model.volume_gain_per_rad;  // the bellows' own, as the lifted truth
    const auto law = make_learning_law(own, discretize_arm_model(own.model, own.timing.sample_s()), samples);
    p.joints[j].own = predict_convergence(*law, own, samples, stop);
    if (!p.joints[j].own.available) return false;
  }
  return true;
}

}  // namespace

Eigen::MatrixXd lifted_learning_operator(JointLearning& law, const Configuration& config, double kappa_scale,
                                         double omega0_scale, int samples) {
  const StateSpaceModel loop = scaled_closed_loop(config, kappa_scale, omega0_scale);
  const int J = loop.inputs(), N = samples;
  std::vector<Eigen::MatrixXd> impulse;  // y(1..N) after a unit correction of joint i at sample 0
  for (int i = 0; i < J; ++i) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(N, J);
    u(0, i) = 1.0;
    impulse.push_back(loop.simulate(u));
  }
  Eigen::MatrixXd m(N * J, N * J);
  Eigen::MatrixXd u(N, J), e(N, J), next(N, J);
  for (int i = 0; i < J; ++i) {
    for (int k = 0; k < N; ++k) {
      u.setZero();
      u(k, i) = 1.0;
      e.setZero();  // the error the unit correction leaves: -Pcl u (the reference is the law's affine part)
      e.bottomRows(N - k) = -impulse[static_cast<std::size_t>(i)].topRows(N - k);
      law.update(u, e, next);
      m.col(i * N + k) = Eigen::Map<const Eigen::VectorXd>(next.data(), N * J);
    }
  }
  return m;
}

namespace {

JointConvergencePrediction predict_lifted(const Configuration& config, int joints, int samples, StopFlag stop,
                                          const LiftedPredictionSettings& settings) {
  JointConvergencePrediction p;
  p.joints.resize(static_cast<std::size_t>(joints));
  const std::string& law_name = config.ilc.law;
  p.learned_together = learns_joints_together(law_name);
  if (samples < 2 || law_name == "noilc-learned") {  // it refits its model: not one linear map
    p.unavailable_reason = samples < 2 ? "a trial of fewer than 2 samples"
                                       : "it refits its model between trials: no one linear map to predict";
    return p;
  }
  Configuration linear = config;
  if (law_name == "noilc-constrained") linear.ilc.law = "noilc";  // its bounds inactive
  const double T = config.timing.sample_s();
  const std::unique_ptr<JointLearning> law =  // also refuses a joint count that is not the [arm]'s
      make_joint_learning(linear, discretize_arm_model(config.model, T), joints, samples);
  if (!p.learned_together && !predict_each_joint(config, samples, stop, p)) {
    p.unavailable_reason = "a joint's law has no frequency response";
    return p;
  }

  ConvergencePrediction& arm = p.arm;
  arm.available = true;
  arm.band_low_hz = 1.0 / (samples * T);
  arm.band_high_hz = 0.5 / T;
  arm.model_error = config.ilc.prediction_model_error;
  Eigen::VectorXd direction = broadband_start(static_cast<Eigen::Index>(samples) * joints);
  const auto estimate = [&](double kappa_scale, double omega0_scale, Eigen::MatrixXd* kept) {
    Eigen::MatrixXd m = lifted_learning_operator(*law, linear, kappa_scale, omega0_scale, samples);
    const TopSingular top = largest_singular(m, direction, settings);
    direction = top.direction;
    p.iterations += top.iterations;
    if (kept != nullptr) *kept = std::move(m);
    return ContractionEstimate{kappa_scale, omega0_scale, top.value,
                               spectrum_peak_hz(top.direction, joints, samples, T)};
  };

  Eigen::MatrixXd nominal;
  arm.nominal = estimate(1.0, 1.0, &nominal);
  const Eigen::VectorXd slowest = direction;
  for (int j = 0; j < joints; ++j) {
    JointConvergence& joint = p.joints[static_cast<std::size_t>(j)];
    const TopSingular rows = largest_singular(nominal.middleRows(j * samples, samples), slowest, settings);
    p.iterations += rows.iterations;
    joint.contraction = rows.value;
    joint.slowest_direction_share = slowest.segment(j * samples, samples).squaredNorm();
  }
  const int n = config.ilc.prediction_grid_points;
  arm.worst = arm.nominal;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) {
      if (stop_is_requested(stop)) throw Cancelled("convergence prediction stopped by a signal");
      const double a = n == 1 ? 0.0 : -1.0 + 2.0 * i / (n - 1);
      const double b = n == 1 ? 0.0 : -1.0 + 2.0 * k / (n - 1);
      const ContractionEstimate e = estimate(1.0 + a * arm.model_error, 1.0 + b * arm.model_error, nullptr);
      arm.grid.push_back(e);
      if (e.contraction > 1.0 + kDivergenceTolerance) ++arm.diverging_points;
      if (e.contraction > arm.worst.contraction) arm.worst = e;
    }
  }
  arm.warning = convergence_warning(arm, law_name + " for " + std::to_string(joints) + " joints");
  return p;
}

}  // namespace

JointConvergencePrediction predict_joint_convergence(const Configuration& config, int joints, int samples,
                                                     StopFlag stop, LiftedPredictionSettings settings) {
  try {
    return predict_lifted(config, joints, samples, stop, settings);
  } catch (const InputError& error) {  // e.g. a chain whose linearization has no continuous counterpart
    JointConvergencePrediction p;
    p.joints.resize(static_cast<std::size_t>(joints));
    p.learned_together = learns_joints_together(config.ilc.law);
    p.unavailable_reason = error.what();
    return p;
  }
}

}  // namespace bellows
