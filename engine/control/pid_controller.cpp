#include "engine/control/pid_controller.hpp"

#include <algorithm>

namespace bellows {

double PidController::step(double desired, double measured, int saturation_sign) {
  const double error = desired - measured;
  const bool pushing_into_saturation = (saturation_sign > 0 && error > 0.0) || (saturation_sign < 0 && error < 0.0);
  if (!pushing_into_saturation) state_.integral_s += error * sample_time_s_;
  if (params_.k_i_per_s > 0.0) {
    const double bound = params_.integrator_limit_bar / params_.k_i_per_s;
    state_.integral_s = std::clamp(state_.integral_s, -bound, bound);
  }
  const double rate = state_.has_previous ? (measured - state_.previous_output) / sample_time_s_ : 0.0;
  state_.previous_output = measured;
  state_.has_previous = true;
  return params_.k_ff * desired + params_.k_p * error + params_.k_i_per_s * state_.integral_s - params_.k_d_s * rate;
}

}  // namespace bellows
