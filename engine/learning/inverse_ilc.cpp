#include "engine/learning/inverse_ilc.hpp"

#include <cmath>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/learning/lifted_operators.hpp"

namespace bellows {

InverseIlc::InverseIlc(const DiscreteArmModel& model, const IlcParameters& parameters, int samples)
    : model_(model),
      samples_(samples),
      gain_(parameters.inverse_gain),
      filter_(parameters.inverse_q_cutoff_hz, model.sample_time_s) {
  if (samples < 1) throw InputError("inverse-model ILC needs at least 1 sample, got " + std::to_string(samples));
  if (!(gain_ > 0.0) || gain_ > 1.0) throw InputError("[ilc] inverse_gain must be in (0, 1]");
  const double first_markov = model.C * model.B;
  if (!(std::abs(first_markov) > 1e-12)) throw InputError("inverse-model ILC: the model has no direct response CB");
}

void InverseIlc::update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
                        Eigen::Ref<Eigen::VectorXd> u_next) {
  // Solve P v = e by forward substitution on the state: e(t) = C (A x(t) + B v(t)).
  const double first_markov = model_.C * model_.B;
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int t = 0; t < samples_; ++t) {
    const Eigen::Vector2d free_response = model_.A * x;
    const double v = (e_j(t) - model_.C * free_response) / first_markov;
    x = free_response + model_.B * v;
    u_next(t) = u_j(t) + gain_ * v;
  }
  filter_.apply(u_next, u_next);
}

std::optional<LawFrequencyResponse> InverseIlc::frequency_response(double theta_rad_per_sample) const {
  const double q = filter_.gain(theta_rad_per_sample);
  return LawFrequencyResponse{q, q * gain_ / lifted_symbol(model_, theta_rad_per_sample)};
}

}  // namespace bellows
