// Gradient (steepest-descent) ILC (`gradient`):  u_{j+1} = u_j + beta P' e_j,
// beta = gradient_step / ||P||^2. For the nominal model the error falls monotonically for any
// gradient_step in (0, 2); P' e is an adjoint (backward) simulation, so an update is O(N).
#pragma once

#include "engine/model/arm_model.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

class GradientIlc final : public LearningLaw {
 public:
  GradientIlc(const DiscreteArmModel& model, const IlcParameters& parameters, int samples);

  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override;
  std::string name() const override { return "gradient"; }
  int samples() const override { return samples_; }
  std::optional<LawFrequencyResponse> frequency_response(double theta_rad_per_sample) const override;

  /// beta, the step actually taken.
  double step() const { return step_; }

 private:
  DiscreteArmModel model_;
  int samples_;
  double step_;
};

}  // namespace bellows
