// PD-type ILC with a zero-phase Q-filter (`pd`), the classic law the paper compares against:
//   u_{j+1}(t) = Q[ u_j(t) + k_p e_j(t+1) + k_d (e_j(t+1) - e_j(t)) / T ]
// The error one sample ahead is used because the input at t first shows in the output at t+1.
// Q trades the final error (it stops learning above its cutoff) for robustness.
#pragma once

#include "engine/model/arm_model.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/base/parameters.hpp"
#include "engine/learning/zero_phase_filter.hpp"

namespace bellows {

class PdIlc final : public LearningLaw {
 public:
  PdIlc(const DiscreteArmModel& model, const IlcParameters& parameters, int samples);

  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override;
  std::string name() const override { return "pd"; }
  int samples() const override { return samples_; }
  std::optional<LawFrequencyResponse> frequency_response(double theta_rad_per_sample) const override;

 private:
  double kp_, kd_s_, sample_time_s_;
  int samples_;
  ZeroPhaseLowPass filter_;
};

}  // namespace bellows
