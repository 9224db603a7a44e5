// Convergence prediction for an arm of J >= 2 joints (engine/config/convergence is the one-joint
// one; docs/learning-laws.md, "Several joints"). The joints move each other, so the honest question is
// how the whole arm's correction contracts: with the law's update u_{j+1} = Lu u_j + Le e_j and the
// arm's closed loop e_j = r - Pcl u_j, the correction contracts per trial by the lifted operator
// M = Lu - Le Pcl (NJ x NJ, every joint and sample), and the prediction is its largest singular
// value ||M||_2: the correction's distance to its limit shrinks at least that much per trial.
//  - Pcl is the chain linearized stretched out (its coupled model, what the simulated arm is near
//    rest) behind each joint's pressure lag and PID (engine/learning/closed_loop_model), whatever
//    model the law itself uses ([ilc] joint_model): a law on the independent model meets the coupling.
//  - Lu, Le are read off the law by applying its update to unit corrections and errors (a linear law:
//    noilc; noilc-constrained as noilc, its bounds inactive; pd, gradient, inverse and noilc-dense per
//    joint). noilc-learned refits its model between trials: no prediction, as for one joint.
//  - the grid scales every joint's kappa and omega0 alike by 1 -+ [ilc] prediction_model_error.
// Per joint j: the largest gain of M's rows of joint j (how much joint j's correction can keep of the
// arm's, per trial) and joint j's share of the slowest direction. Laws that learn each joint on its
// own (pd, gradient, inverse, noilc-dense) also get each joint's one-joint prediction on its own model
// (its row of the chain's table, the others held still), the frequency method of convergence.hpp.
#pragma once

#include <string>
#include <vector>

#include "engine/base/cancellation.hpp"
#include "engine/config/configuration.hpp"
#include "engine/config/convergence.hpp"
#include "engine/learning/joint_learning.hpp"

namespace bellows {

/// How the largest singular value is found: Lanczos on M'M from the last grid point's slowest
/// direction (neighbouring grid points have nearly the same one).
struct LiftedPredictionSettings {
  int max_iterations = 200;          // Lanczos steps at most (each: M and M' applied once)
  double relative_tolerance = 1e-8;  // stop when the largest Ritz value changes less than this per step
};

struct JointConvergence {
  double contraction = 0.0;              // nominal: the largest gain of M's rows of this joint
  double slowest_direction_share = 0.0;  // nominal: this joint's part of ||v||^2, v the slowest direction
  ConvergencePrediction own;             // laws per joint: this joint's one-joint prediction; else unavailable
};

struct JointConvergencePrediction {
  /// The whole arm's: band, model error, nominal, worst, grid, diverging points and warning as for one
  /// joint; worst_frequency_hz is where the slowest direction's spectrum peaks.
  ConvergencePrediction arm;
  bool learned_together = false;  // one law for every joint (noilc, noilc-constrained): no `own`
  std::vector<JointConvergence> joints;
  int iterations = 0;              // Lanczos steps spent, every grid point together
  std::string unavailable_reason;  // why arm.available is false
};

/// The prediction for an arm of `joints` (>= 2) joints ([arm] chain) learning with `config`'s law on
/// trials of `samples` samples. Unavailable (arm.available false, unavailable_reason saying why) for
/// laws that are not linear and for a configuration make_joint_learning or the chain's closed loop
/// refuses. Throws Cancelled when `stop` is set (looked at between grid points).
JointConvergencePrediction predict_joint_convergence(const Configuration& config, int joints, int samples,
                                                     StopFlag stop = nullptr, LiftedPredictionSettings settings = {});

/// The lifted operator M (NJ x NJ, joint-major: entry j N + t is joint j at sample t) of `law` (a
/// linear one, of `samples` samples and the [arm]'s joints) on the coupled closed loop of `config`'s
/// [arm], every joint's kappa and omega0 scaled: what the prediction takes the norm of.
Eigen::MatrixXd lifted_learning_operator(JointLearning& law, const Configuration& config, double kappa_scale,
                                         double omega0_scale, int samples);

}  // namespace bellows
