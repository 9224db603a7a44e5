// PID with feed-forward at the ILC sample rate (spec section 3), in normalized units:
//   u_pid = k_ff yD + k_p e + k_i integral(e) - k_d y_dot,   e = yD - y,   y = angle / pi.
// Derivative on the measurement (no kick on set-point jumps). Anti-windup: the integral stops
// growing while the total input is saturated in the direction the error pushes, and its
// contribution is bounded by `integrator_limit_bar`.
#pragma once

#include "engine/base/parameters.hpp"

namespace bellows {

class PidController {
 public:
  struct State {
    double integral_s = 0.0;       // integral of the normalized error
    double previous_output = 0.0;  // y at the previous sample
    bool has_previous = false;
  };

  PidController(const ControllerParameters& params, double sample_time_s)
      : params_(params), sample_time_s_(sample_time_s) {}

  /// One sample: desired and measured normalized angle in, u_pid (bar) out. `saturation_sign`
  /// is +1 / -1 while the previous total input was clamped high / low, 0 otherwise.
  double step(double desired, double measured, int saturation_sign);

  void reset() { state_ = {}; }
  const State& state() const { return state_; }
  void set_state(const State& state) { state_ = state; }
  void set_gains(const ControllerParameters& params) { params_ = params; }
  const ControllerParameters& parameters() const { return params_; }

 private:
  ControllerParameters params_;
  double sample_time_s_;
  State state_;
};

}  // namespace bellows
