#include "engine/learning/pd_ilc.hpp"

#include <string>

#include "engine/base/errors.hpp"

namespace bellows {

PdIlc::PdIlc(const DiscreteArmModel& model, const IlcParameters& parameters, int samples)
    : kp_(parameters.pd_kp),
      kd_s_(parameters.pd_kd_s),
      sample_time_s_(model.sample_time_s),
      samples_(samples),
      filter_(parameters.pd_q_cutoff_hz, model.sample_time_s) {
  if (samples < 1) throw InputError("PD-type ILC needs at least 1 sample, got " + std::to_string(samples));
}

void PdIlc::update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
                   Eigen::Ref<Eigen::VectorXd> u_next) {
  double previous_error = 0.0;  // e_j(0): the trial starts on the reference
  for (int t = 0; t < samples_; ++t) {
    u_next(t) = u_j(t) + kp_ * e_j(t) + kd_s_ * (e_j(t) - previous_error) / sample_time_s_;
    previous_error = e_j(t);
  }
  filter_.apply(u_next, u_next);
}

std::optional<LawFrequencyResponse> PdIlc::frequency_response(double theta_rad_per_sample) const {
  const double q = filter_.gain(theta_rad_per_sample);
  const std::complex<double> difference = 1.0 - std::polar(1.0, -theta_rad_per_sample);
  return LawFrequencyResponse{q, q * (kp_ + kd_s_ * difference / sample_time_s_)};
}

}  // namespace bellows
