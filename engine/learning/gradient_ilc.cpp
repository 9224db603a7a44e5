#include "engine/learning/gradient_ilc.hpp"

#include <string>

#include "engine/base/errors.hpp"
#include "engine/learning/lifted_operators.hpp"

namespace bellows {

GradientIlc::GradientIlc(const DiscreteArmModel& model, const IlcParameters& parameters, int samples)
    : model_(model), samples_(samples), step_(0.0) {
  if (samples < 1) throw InputError("gradient ILC needs at least 1 sample, got " + std::to_string(samples));
  if (!(parameters.gradient_step > 0.0) || !(parameters.gradient_step < 2.0)) {
    throw InputError("[ilc] gradient_step must be in (0, 2) (a fraction of the largest stable step)");
  }
  const double norm = lifted_norm(model, samples);
  step_ = parameters.gradient_step / (norm * norm);
}

void GradientIlc::update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
                         Eigen::Ref<Eigen::VectorXd> u_next) {
  apply_lifted_transpose(model_, e_j, u_next);
  u_next = u_j + step_ * u_next;
}

std::optional<LawFrequencyResponse> GradientIlc::frequency_response(double theta_rad_per_sample) const {
  return LawFrequencyResponse{1.0, step_ * std::conj(lifted_symbol(model_, theta_rad_per_sample))};
}

}  // namespace bellows
