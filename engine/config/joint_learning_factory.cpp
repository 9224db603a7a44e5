#include "engine/config/joint_learning_factory.hpp"

#include <algorithm>

#include "engine/model/arm_chain.hpp"
#include "engine/model/arm_chain_linearization.hpp"
#include "engine/model/coupled_joint_dynamics.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/learning/noilc_learned.hpp"
#include "engine/learning/noilc_mimo.hpp"
#include "engine/learning/noilc_mimo_constrained.hpp"

namespace bellows {
namespace {

FaultError update_failed(const std::string& law, MultiJointNoilcStatus status) {
  return FaultError("learning law " + law + " could not update the correction: " + to_string(status));
}

/// noilc for J joints: the O(N) multi-input multi-output norm-optimal update.
class JointNormOptimal final : public JointLearning {
 public:
  JointNormOptimal(const MultiJointModel& model, const IlcParameters& weights, int samples) {
    const MultiJointNoilcStatus status =
        solver_.setup(model, MultiJointWeights::uniform(weights, model.joints()), samples);
    if (status != MultiJointNoilcStatus::kOk) throw InputError(std::string("[ilc] weights: ") + to_string(status));
  }
  void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
              Eigen::Ref<Eigen::MatrixXd> u_next) override {
    const MultiJointNoilcStatus status = solver_.update(u_j, e_j, u_next);
    if (status != MultiJointNoilcStatus::kOk) throw update_failed(name(), status);
  }
  std::string name() const override { return "noilc"; }
  int samples() const override { return solver_.info().samples; }
  int joints() const override { return solver_.info().joints; }

 private:
  MultiJointNoilc solver_;
};

/// noilc-constrained for J joints: the same cost, each joint's u_pid + u_ilc kept within its reach.
class JointNormOptimalConstrained final : public JointLearning {
 public:
  JointNormOptimalConstrained(const MultiJointModel& model, const IlcParameters& ilc, int samples)
      : margin_bar_(ilc.limit_margin_bar) {
    const MultiJointAdmmSettings admm{ilc.admm_rho, ilc.admm_max_iterations, ilc.admm_tolerance};
    const MultiJointNoilcStatus status =
        solver_.setup(model, MultiJointWeights::uniform(ilc, model.joints()), samples, admm);
    if (status != MultiJointNoilcStatus::kOk) throw InputError(std::string("[ilc] weights: ") + to_string(status));
    lower_.resize(samples, model.joints());
    upper_.resize(samples, model.joints());
  }
  void set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar, double input_limit_bar) override {
    const double reach_bar = input_limit_bar - margin_bar_;
    if (!(reach_bar > 0.0)) throw InputError("[ilc] limit_margin_bar leaves no room below the pressure limit");
    lower_ = -reach_bar - feedback_bar.array();
    upper_ = reach_bar - feedback_bar.array();
    const MultiJointNoilcStatus status = solver_.set_bounds(lower_, upper_);
    if (status != MultiJointNoilcStatus::kOk) throw update_failed(name(), status);
  }
  void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
              Eigen::Ref<Eigen::MatrixXd> u_next) override {
    const MultiJointNoilcStatus status = solver_.solve(u_j, e_j, u_next);
    // Not converged still gives a feasible correction: better than none, and the report says so.
    if (status != MultiJointNoilcStatus::kOk && status != MultiJointNoilcStatus::kNotConverged)
      throw update_failed(name(), status);
  }
  std::string name() const override { return "noilc-constrained"; }
  int samples() const override { return solver_.info().samples; }
  int joints() const override { return solver_.info().joints; }

 private:
  double margin_bar_;
  MultiJointNoilcConstrained solver_;
  Eigen::MatrixXd lower_, upper_;
};

/// noilc-learned for J joints: the closed loop of the J-joint model ([ilc] joint_model) as the prior.
class JointNormOptimalLearned final : public JointLearning {
 public:
  JointNormOptimalLearned(const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings, int samples)
      : core_(prior, settings, samples) {}
  void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
              Eigen::Ref<Eigen::MatrixXd> u_next) override {
    core_.update(u_j, e_j, u_next);
  }
  void set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar, double input_limit_bar) override {
    core_.set_input_context(feedback_bar, input_limit_bar);
  }
  void set_held_outputs(const std::vector<unsigned char>& held) override { core_.set_held_outputs(held); }
  std::string name() const override { return "noilc-learned"; }
  int samples() const override { return core_.samples(); }
  int joints() const override { return core_.joints(); }
  std::string take_note() override { return core_.take_note(); }
  std::optional<ModelCheck> model_check() const override { return core_.model_check(); }

 private:
  LearnedModelNoilc core_;
};

/// Any other law, one per joint, each on its joint's own model.
class PerJointLearning final : public JointLearning {
 public:
  explicit PerJointLearning(std::vector<std::unique_ptr<LearningLaw>> laws) : laws_(std::move(laws)) {}
  void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
              Eigen::Ref<Eigen::MatrixXd> u_next) override {
    for (int j = 0; j < joints(); ++j)
      laws_[static_cast<std::size_t>(j)]->update(u_j.col(j), e_j.col(j), u_next.col(j));
  }
  void set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar, double input_limit_bar) override {
    for (int j = 0; j < joints(); ++j)
      laws_[static_cast<std::size_t>(j)]->set_input_context(feedback_bar.col(j), input_limit_bar);
  }
  void set_held_outputs(const std::vector<unsigned char>& held) override {
    for (const auto& law : laws_) law->set_held_outputs(held);
  }
  std::string name() const override { return laws_.front()->name(); }
  int samples() const override { return laws_.front()->samples(); }
  int joints() const override { return static_cast<int>(laws_.size()); }

 private:
  std::vector<std::unique_ptr<LearningLaw>> laws_;
};

}  // namespace

std::vector<ModelParameters> independent_joint_parameters(const ChainParameters& chain) {
  std::vector<ModelParameters> joints;
  for (int i = 0; i < chain.joints; ++i) {
    const ChainLink& link = chain.links[static_cast<std::size_t>(i)];
    ModelParameters joint;
    joint.kappa_rad_per_bar = link.kappa_rad_per_bar;
    joint.omega0_rad_per_s = link.omega0_straight_rad_per_s;
    joint.damping = link.damping_ratio;
    joints.push_back(joint);
  }
  return joints;
}

std::vector<DiscreteArmModel> independent_joint_models(const ChainParameters& chain, double sample_time_s) {
  std::vector<DiscreteArmModel> models;
  for (const ModelParameters& joint : independent_joint_parameters(chain))
    models.push_back(discretize_arm_model(joint, sample_time_s));
  return models;
}

MultiJointModel joint_learning_model(const ChainParameters& chain, const std::string& joint_model, double sample_time_s,
                                     const IdentifiedArmParameters& identified) {
  if (joint_model == "coupled") return linearize_chain(ArmChain(chain), JointVector::Zero(chain.joints), sample_time_s);
  if (joint_model == "independent") return block_diagonal_model(independent_joint_models(chain, sample_time_s));
  if (joint_model == "identified") {
    try {
      return discretize_joint_dynamics(identified_dynamics(identified, chain.joints), sample_time_s);
    } catch (const InputError& error) {
      throw InputError(std::string("[ilc] joint_model = 'identified': ") + error.what());
    }
  }
  throw InputError("[ilc] joint_model = '" + joint_model + "': unknown (known: coupled, independent, identified)");
}

bool learns_joints_together(const std::string& law) {
  return law == "noilc" || law == "noilc-constrained" || law == "noilc-learned";
}

std::unique_ptr<JointLearning> make_joint_learning(const Configuration& config, const DiscreteArmModel& model,
                                                   int joints, int samples) {
  if (joints == 1 && !config.arm.has_chain())
    return std::make_unique<SingleJointLearning>(make_learning_law(config, model, samples));
  const ChainParameters chain = chain_of(config.arm);
  if (chain.joints != joints) {
    throw InputError("the trajectory has " + std::to_string(joints) + " joints; the arm has " +
                     std::to_string(chain.joints) + " (" + config.arm.name() + ")");
  }
  const std::string& law = config.ilc.law;
  const double sample_s = config.timing.sample_s();
  try {
    if (law == "noilc")
      return std::make_unique<JointNormOptimal>(
          joint_learning_model(chain, config.ilc.joint_model, sample_s, config.identified), config.ilc, samples);
    if (law == "noilc-constrained") {
      return std::make_unique<JointNormOptimalConstrained>(
          joint_learning_model(chain, config.ilc.joint_model, sample_s, config.identified), config.ilc, samples);
    }
    if (law == "noilc-learned") {
      const MultiJointModel joints_model =
          joint_learning_model(chain, config.ilc.joint_model, sample_s, config.identified);
      return std::make_unique<JointNormOptimalLearned>(
          closed_loop_prior(joints_model.A, joints_model.B, sample_s, config.model.volume_gain_per_rad,
                            config.controller),
          learned_noilc_settings(config.ilc), samples);
    }
    std::vector<std::unique_ptr<LearningLaw>> laws;
    for (const DiscreteArmModel& joint : independent_joint_models(chain, sample_s))
      laws.push_back(make_learning_law(config, joint, samples));
    return std::make_unique<PerJointLearning>(std::move(laws));
  } catch (const InputError& error) {
    const std::string what = error.what();
    if (what.rfind("[ilc]", 0) == 0) throw;
    throw InputError("[ilc] law = '" + law + "' for " + std::to_string(joints) + " joints: " + what);
  }
}

}  // namespace bellows
