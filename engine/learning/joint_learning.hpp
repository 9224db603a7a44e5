// Learning between trials for an arm of J joints: the next correction from the last one and the
// trial's normalized errors, both N x J (one column per joint, as the engine's trial takes them).
// Built once per model, weights and trial length (the expensive set-up happens there), then updated
// per trial. With one joint it is a LearningLaw (engine/learning/learning_law.hpp) on the only column.
#pragma once

#include <memory>
#include <string>

#include <Eigen/Dense>

#include "engine/learning/learning_law.hpp"

namespace bellows {

class JointLearning {
 public:
  virtual ~JointLearning() = default;
  /// u_next = law(u_j, e_j), each N x J; u_next may not alias the inputs. Throws FaultError when the
  /// update cannot be made (non-finite data); u_next is then unchanged.
  virtual void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
                      Eigen::Ref<Eigen::MatrixXd> u_next) = 0;
  /// The law's configuration name, with how the joints are modelled when J > 1.
  virtual std::string name() const = 0;
  virtual int samples() const = 0;
  virtual int joints() const = 0;
  /// Per joint (columns), the last trial's feedback u_pid(0..N-1) in bar, and the largest |u_pid +
  /// u_ilc| the set-point clamp lets through; before update(). Laws that keep the correction inside
  /// the pressure limits use it.
  virtual void set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& /*feedback_bar*/,
                                 double /*input_limit_bar*/) {}
  /// As LearningLaw::set_held_outputs (one row per sample, for every joint); before update().
  virtual void set_held_outputs(const std::vector<unsigned char>& /*held*/) {}
  /// The single-joint law underneath when J = 1 (for the convergence prediction), else null.
  virtual const LearningLaw* single_joint_law() const { return nullptr; }
  /// As LearningLaw::take_note: a note for the session's events since the last call, then forgotten.
  virtual std::string take_note() { return {}; }
  /// As LearningLaw::model_check, over every joint.
  virtual std::optional<ModelCheck> model_check() const { return std::nullopt; }
};

/// One joint: `law` on the only column, exactly as the single-joint product has always learned.
/// Borrows the law, or owns it when given one.
class SingleJointLearning final : public JointLearning {
 public:
  explicit SingleJointLearning(LearningLaw& law) : law_(law) {}
  explicit SingleJointLearning(std::unique_ptr<LearningLaw> law) : owned_(std::move(law)), law_(*owned_) {}
  void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
              Eigen::Ref<Eigen::MatrixXd> u_next) override;
  std::string name() const override { return law_.name(); }
  int samples() const override { return law_.samples(); }
  int joints() const override { return 1; }
  void set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar, double input_limit_bar) override;
  void set_held_outputs(const std::vector<unsigned char>& held) override { law_.set_held_outputs(held); }
  const LearningLaw* single_joint_law() const override { return &law_; }
  std::string take_note() override { return law_.take_note(); }
  std::optional<ModelCheck> model_check() const override { return law_.model_check(); }

 private:
  std::unique_ptr<LearningLaw> owned_;  // null when borrowed
  LearningLaw& law_;
};

}  // namespace bellows
