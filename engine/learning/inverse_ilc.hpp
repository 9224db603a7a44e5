// Robust inverse-model ILC (`inverse`):  u_{j+1} = Q[ u_j + beta P^-1 e_j ].
// With the exact model and beta = 1 one trial would remove the error; beta < 1 buys robustness to
// model error (Harte, Hatonen, Owens 2005: monotone if |1 - beta P_true / P| < 1). P^-1 e is a
// forward simulation of the model's inverse, O(N). The zero-order hold puts a model zero near
// z = -1, so the inverse rings at the Nyquist frequency; the zero-phase Q-filter removes that.
#pragma once

#include "engine/model/arm_model.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/base/parameters.hpp"
#include "engine/learning/zero_phase_filter.hpp"

namespace bellows {

class InverseIlc final : public LearningLaw {
 public:
  InverseIlc(const DiscreteArmModel& model, const IlcParameters& parameters, int samples);

  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override;
  std::string name() const override { return "inverse"; }
  int samples() const override { return samples_; }
  std::optional<LawFrequencyResponse> frequency_response(double theta_rad_per_sample) const override;

 private:
  DiscreteArmModel model_;
  int samples_;
  double gain_;
  ZeroPhaseLowPass filter_;
};

}  // namespace bellows
