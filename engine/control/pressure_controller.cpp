#include "engine/control/pressure_controller.hpp"

#include <algorithm>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/model/valve_flow.hpp"
#include "engine/base/units.hpp"

namespace bellows {
PressureController::PressureController(const ControllerParameters& params) : params_(params) {
  if (params.filter_samples < 1 || params.filter_samples > kMaxFilterSamples) {
    throw InputError("controller.filter_samples must be between 1 and " + std::to_string(kMaxFilterSamples));
  }
}

DutyCycles PressureController::step(double desired_bar, double measured_bar, double supply_bar) {
  // Moving average over the last `filter_samples` measurements (a running sum, no allocation).
  const int length = params_.filter_samples;
  if (state_.count == length) state_.sum_bar -= state_.history_bar[state_.next];
  else ++state_.count;
  state_.history_bar[state_.next] = measured_bar;
  state_.sum_bar += measured_bar;
  state_.next = (state_.next + 1) % length;
  const double filtered_Pa = filtered_bar() * kPaPerBar;

  const GasParameters& gas = params_.gas;
  const double volume_m3 = params_.volume_l * 1e-3;
  const double desired_flow = volume_m3 / (gas.gas_constant_J_per_kgK * gas.temperature_K * params_.tau_p_s) *
                              (desired_bar * kPaPerBar - filtered_Pa);
  const double ports = params_.valves_per_port;
  DutyCycles duty;
  if (desired_flow > 0.0) {
    const double capacity =
        ports * iso6358_mass_flow_kg_per_s(supply_bar * kPaPerBar, filtered_Pa, params_.valve_conductance_m3_per_sPa,
                                           params_.valve_critical_ratio, gas.reference_density_kg_per_m3);
    duty.inlet = capacity > 0.0 ? std::min(1.0, desired_flow / capacity) : 0.0;
  } else if (desired_flow < 0.0) {
    const double capacity = ports * iso6358_mass_flow_kg_per_s(
                                        filtered_Pa, gas.ambient_bar * kPaPerBar, params_.valve_conductance_m3_per_sPa,
                                        params_.valve_critical_ratio, gas.reference_density_kg_per_m3);
    duty.outlet = capacity > 0.0 ? std::min(1.0, -desired_flow / capacity) : 1.0;
  }
  return duty;
}

}  // namespace bellows
