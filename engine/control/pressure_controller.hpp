// Pressure controller of one actuator at the tick rate (spec section 3): a moving average of the
// measured pressure, a desired first-order response p_dot = (p_des - p) / tau_p, hence a desired
// mass flow mdot = V / (R T tau_p) (p_des - p), and the inverted valve model gives the inlet duty
// (mdot > 0) or the outlet duty (mdot < 0) in [0, 1].
#pragma once

#include <array>

#include "engine/base/parameters.hpp"

namespace bellows {

struct DutyCycles {
  double inlet = 0.0;
  double outlet = 0.0;
};

class PressureController {
 public:
  static constexpr int kMaxFilterSamples = 32;

  struct State {
    std::array<double, kMaxFilterSamples> history_bar{};
    int count = 0;  // samples in the filter so far (up to its length)
    int next = 0;   // ring position of the next sample
    double sum_bar = 0.0;
  };

  /// Throws InputError if the filter length is outside [1, kMaxFilterSamples].
  explicit PressureController(const ControllerParameters& params);

  /// One tick: desired and measured chamber pressure and supply pressure (absolute, bar) in.
  DutyCycles step(double desired_bar, double measured_bar, double supply_bar);
  /// The filtered pressure of the last step.
  double filtered_bar() const { return state_.count > 0 ? state_.sum_bar / state_.count : 0.0; }

  void reset() { state_ = {}; }
  const State& state() const { return state_; }
  void set_state(const State& state) { state_ = state; }

 private:
  ControllerParameters params_;
  State state_;
};

}  // namespace bellows
