// The two multi-joint engine pieces together: J-joint norm-optimal ILC (engine/learning/noilc_mimo) learning
// on the simulated chain's mechanics (engine/model/arm_chain) of `arm2` and `arm3`, each joint with the spec's PID
// and feed-forward, with the coupled model (the chain linearized stretched out) and with independent
// joints (each joint's own single-joint model). Mechanics only: the input is each joint's pressure
// difference as commanded, no valves or chambers; the loop, trajectories and device for J joints are
// not written yet, so this stands in for `bellows run --config arm2.toml --trajectory paper2` (and arm3).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "engine/model/arm_chain_linearization.hpp"
#include "engine/config/joint_learning_factory.hpp"
#include "engine/model/arm_model.hpp"
#include "engine/learning/noilc_mimo.hpp"
#include "engine/control/pid_controller.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

constexpr double kSampleTime_s = 0.02;

/// paper2 and paper3 of ../shared/spec/multi-joint.md section 3: the shoulder 0 -> 20 -> -20 -> 20 -> 0
/// deg with 0.3 s moves at 0.6, 2.0, 3.4, 4.8 s; the elbow the paper's trajectory; for paper3 the
/// wrist the paper's moves 0.3 s later. (N + 1) x J, rad.
Eigen::MatrixXd paper_rad(int joints) {
  const std::vector<TrapezoidalMove> shoulder_moves = {
      {0.6, 0.0, 20.0, 0.3}, {2.0, 20.0, -20.0, 0.3}, {3.4, -20.0, 20.0, 0.3}, {4.8, 20.0, 0.0, 0.3}};
  const Trajectory shoulder = trajectory_from_moves("shoulder", 0.0, shoulder_moves, 8.0, kSampleTime_s);
  const Trajectory elbow = library_trajectory("paper", kSampleTime_s);
  Eigen::MatrixXd reference(shoulder.joint(0).size(), joints);
  reference.col(0) = shoulder.joint(0);
  reference.col(1) = elbow.joint(0);
  if (joints == 3) {
    std::vector<TrapezoidalMove> wrist_moves;
    const double paper_moves[6][3] = {{0.6, 0, 30},   {1.6, 30, -30}, {2.6, -30, 30},
                                      {3.6, 30, -30}, {4.6, -30, 30}, {5.6, 30, 0}};
    for (const auto& m : paper_moves) wrist_moves.push_back({m[0] + 0.3, m[1], m[2]});
    reference.col(2) = trajectory_from_moves("wrist", 0.0, wrist_moves, 8.0, kSampleTime_s).joint(0);
  }
  return reference;
}

class ArmTrials {
 public:
  explicit ArmTrials(const char* preset) : chain_(chain_preset(preset)) {
    reference_ = paper_rad(chain_.joints);
    chain_.integration_step_s = 1e-3;  // the mechanics alone need no finer step (RK4; w0 <= 14 rad/s)
  }
  int samples() const { return static_cast<int>(reference_.rows()) - 1; }
  const ChainParameters& chain() const { return chain_; }

  int joints() const { return chain_.joints; }

  /// One trial from rest, stretched out, with the correction u_ilc (N x J, bar). Returns the
  /// normalized error (yD - y) / pi at samples 1..N.
  Eigen::MatrixXd run(const Eigen::MatrixXd& u_ilc) const {
    ArmChain arm(chain_);
    const ControllerParameters controller;
    const double limit_bar = controller.p_max_bar - controller.gas.ambient_bar;
    const int J = joints();
    std::vector<PidController> pids(static_cast<std::size_t>(J), PidController(controller, kSampleTime_s));
    std::vector<int> saturation(static_cast<std::size_t>(J), 0);
    Eigen::MatrixXd error(samples(), J);
    JointVector dp(J);
    for (int t = 0; t < samples(); ++t) {
      for (int i = 0; i < J; ++i) {
        const double desired = reference_(t, i) / std::numbers::pi,
                     measured = arm.state().angle_rad(i) / std::numbers::pi;
        const double total =
            pids[static_cast<std::size_t>(i)].step(desired, measured, saturation[static_cast<std::size_t>(i)]) +
            u_ilc(t, i);
        dp(i) = std::clamp(total, -limit_bar, limit_bar);
        saturation[static_cast<std::size_t>(i)] = total > limit_bar ? 1 : (total < -limit_bar ? -1 : 0);
      }
      arm.advance(kSampleTime_s, dp);
      error.row(t) = (reference_.row(t + 1) - arm.state().angle_rad.transpose()) / std::numbers::pi;
    }
    return error;
  }

 private:
  Eigen::MatrixXd reference_;
  ChainParameters chain_;
};

using JointRms = Eigen::RowVectorXd;

/// RMS error per joint (deg) of iterations 0..iterations with the given model.
std::vector<JointRms> learn(const ArmTrials& trials, const MultiJointModel& model, int iterations) {
  const int J = trials.joints();
  MultiJointNoilc law;
  EXPECT_EQ(law.setup(model, MultiJointWeights::uniform(IlcParameters{}, J), trials.samples()),
            MultiJointNoilcStatus::kOk);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(trials.samples(), J), next(trials.samples(), J);
  std::vector<JointRms> rms;
  for (int j = 0; j <= iterations; ++j) {
    const Eigen::MatrixXd error = trials.run(u);
    rms.push_back(error.colwise().norm() / std::sqrt(static_cast<double>(trials.samples())) * 180.0);
    EXPECT_EQ(law.update(u, error, next), MultiJointNoilcStatus::kOk);
    u = next;
  }
  return rms;
}

std::string table(const std::vector<JointRms>& rms) {
  std::ostringstream out;
  out.precision(3);
  for (int j : {0, 5, 10, 30, 60}) {
    if (static_cast<std::size_t>(j) < rms.size()) out << "  it " << j << ": " << rms[static_cast<std::size_t>(j)];
  }
  return out.str();
}

/// Each joint's own single-joint model from its row of the spec's table (kappa, w0 straight, delta).
MultiJointModel independent_joints(const ChainParameters& chain) {
  return block_diagonal_model(independent_joint_models(chain, kSampleTime_s));
}

/// The bar for every joint: iteration 30 at most 1/8 of iteration 0, and no iteration to
/// the last above 1.25 x the best before it.
void expect_converges(const std::vector<JointRms>& rms, const char* what) {
  for (Eigen::Index i = 0; i < rms[0].size(); ++i) {
    EXPECT_GT(rms[0](i), 1.0) << what << " joint " << i + 1 << ": the feedback alone must leave an error to learn";
    EXPECT_LT(rms[30](i), rms[0](i) / 8.0) << what << " joint " << i + 1;
    double best = rms[0](i);
    for (std::size_t j = 1; j < rms.size(); ++j) {
      EXPECT_LE(rms[j](i), 1.25 * best) << what << " joint " << i + 1 << ", iteration " << j;
      best = std::min(best, rms[j](i));
    }
  }
}

TEST(MultiJointLearning, Arm2LearnsPaper2WithTheCoupledModelNotWithIndependentJoints) {
  const ArmTrials trials("arm2");
  const MultiJointModel coupled = linearize_chain(ArmChain(trials.chain()), JointVector::Zero(2), kSampleTime_s);
  const std::vector<JointRms> with_coupled = learn(trials, coupled, 60);
  const std::vector<JointRms> with_independent = learn(trials, independent_joints(trials.chain()), 30);
  std::cout << "arm2 RMS per joint (deg), coupled:    " << table(with_coupled) << "\n"
            << "arm2 RMS per joint (deg), independent:" << table(with_independent) << "\n";
  expect_converges(with_coupled, "arm2 coupled");
  // Independent joints treat the coupling as a disturbance: with the paper's weights the light
  // elbow's model is wrong enough (the shoulder moves under it) that learning does not converge.
  for (int i = 0; i < 2; ++i) {
    for (int j : {10, 30}) {
      EXPECT_LT(2.0 * with_coupled[static_cast<std::size_t>(j)](i), with_independent[static_cast<std::size_t>(j)](i))
          << "joint " << i + 1 << ", iteration " << j;
    }
  }
}

TEST(MultiJointLearning, Arm3LearnsPaper3WithTheCoupledModel) {
  const ArmTrials trials("arm3");
  const MultiJointModel coupled = linearize_chain(ArmChain(trials.chain()), JointVector::Zero(3), kSampleTime_s);
  const std::vector<JointRms> with_coupled = learn(trials, coupled, 60);
  const std::vector<JointRms> with_independent = learn(trials, independent_joints(trials.chain()), 30);
  std::cout << "arm3 RMS per joint (deg), coupled:    " << table(with_coupled) << "\n"
            << "arm3 RMS per joint (deg), independent:" << table(with_independent) << "\n";
  expect_converges(with_coupled, "arm3 coupled");
  for (int i = 0; i < 3; ++i) {
    for (int j : {10, 30}) {
      EXPECT_LT(2.0 * with_coupled[static_cast<std::size_t>(j)](i), with_independent[static_cast<std::size_t>(j)](i))
          << "joint " << i + 1 << ", iteration " << j;
    }
  }
}

}  // namespace
}  // namespace bellows
