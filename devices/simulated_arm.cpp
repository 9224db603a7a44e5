#include "devices/simulated_arm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {}  // namespace

const char* to_string(SimulatedFault fault) {
  switch (fault) {
    case SimulatedFault::kNone:
      return "none";
    case SimulatedFault::kSensorDropout:
      return "sensor-dropout";
    case SimulatedFault::kStuckInlet:
      return "stuck-inlet";
    case SimulatedFault::kSupplyLoss:
      return "supply-loss";
    case SimulatedFault::kNanAngle:
      return "nan-angle";
    case SimulatedFault::kPressureSpike:
      return "pressure-spike";
    case SimulatedFault::kSwappedChambers:
      return "swapped-chambers";
    case SimulatedFault::kDeadInlet:
      return "dead-inlet";
  }
  return "?";
}

std::string simulated_fault_names() {
  std::string names;
  for (const SimulatedFault fault : kSimulatedFaults)
    names += (names.empty() ? "" : ", ") + std::string(to_string(fault));
  return names;
}

SimulatedFault simulated_fault_from_string(const std::string& name) {
  for (const SimulatedFault fault : kSimulatedFaults) {
    if (name == to_string(fault)) return fault;
  }
  throw InputError("unknown simulated fault '" + printable(name) + "' (" + simulated_fault_names() + ")");
}

SimulatedArm::SimulatedArm(const PlantParameters& params, std::uint64_t seed)
    : params_(params),
      bellows_(bellows_of(params), params.gas),
      supply_Pa_(params.supply_bar * kPaPerBar),
      noise_(seed) {
  state_.chamber_Pa = {params.gas.ambient_bar * kPaPerBar, params.gas.ambient_bar * kPaPerBar};
  state_.command = ValveCommand::vented().joint[0];
  state_.noise = noise_.state();
  const SimulatedFault configured = simulated_fault_from_string(params.fault);
  if (configured != SimulatedFault::kNone) inject_fault(configured, params.fault_at_s);
}

void SimulatedArm::inject_fault(SimulatedFault fault, double at_s) {
  scheduled_at_s_.store(at_s, std::memory_order_relaxed);
  scheduled_fault_.store(static_cast<std::uint8_t>(fault), std::memory_order_release);
}

void SimulatedArm::activate_scheduled_fault() {
  const auto scheduled = static_cast<SimulatedFault>(scheduled_fault_.load(std::memory_order_acquire));
  if (scheduled == SimulatedFault::kNone || scheduled_at_s_.load(std::memory_order_relaxed) > state_.time_s) return;
  scheduled_fault_.store(0, std::memory_order_relaxed);
  state_.fault = scheduled;
  state_.fault_since_s = state_.time_s;
  if (scheduled == SimulatedFault::kSupplyLoss) supply_Pa_ = params_.gas.ambient_bar * kPaPerBar;
}

SimulatedArm::State SimulatedArm::state() const {
  State s = state_;
  s.noise = noise_.state();
  return s;
}

void SimulatedArm::set_state(const State& state) {
  state_ = state;
  noise_.set_state(state.noise);
}

double SimulatedArm::chamber_volume_m3(int actuator) const {
  return bellows_.chamber_volume_m3(actuator, state_.angle_rad);
}

double SimulatedArm::air_mass_kg() const { return bellows_.air_mass_kg(state_.angle_rad, state_.chamber_Pa); }

SensorReading SimulatedArm::read_sensors() {
  activate_scheduled_fault();
  if (state_.fault == SimulatedFault::kSensorDropout) return frozen_reading_;
  SensorReading r;
  r.time_s = state_.time_s;
  const double resolution_rad = params_.encoder_resolution_deg * kRadPerDeg;
  JointReading& joint = r.joint[0];
  joint.angle_rad =
      resolution_rad > 0.0 ? std::round(state_.angle_rad / resolution_rad) * resolution_rad : state_.angle_rad;
  for (int i = 0; i < kActuatorCount; ++i) {
    joint.chamber_bar[i] = state_.chamber_Pa[i] / kPaPerBar + params_.pressure_noise_bar * noise_.standard_normal();
  }
  r.supply_bar = supply_Pa_ / kPaPerBar + params_.pressure_noise_bar * noise_.standard_normal();
  r.temperature_K = params_.gas.temperature_K;
  if (state_.fault == SimulatedFault::kNanAngle) joint.angle_rad = std::numeric_limits<double>::quiet_NaN();
  if (state_.fault == SimulatedFault::kPressureSpike && state_.time_s - state_.fault_since_s < params_.spike_s) {
    joint.chamber_bar[0] += params_.spike_bar;
  }
  frozen_reading_ = r;
  return r;
}

void SimulatedArm::write_valves(const ValveCommand& command) {
  const JointValves valves = single_joint_valves(command);
  for (int i = 0; i < kActuatorCount; ++i) {
    state_.command.inlet_duty[i] = std::clamp(valves.inlet_duty[i], 0.0, 1.0);
    state_.command.outlet_duty[i] = std::clamp(valves.outlet_duty[i], 0.0, 1.0);
    if (!std::isfinite(valves.inlet_duty[i])) state_.command.inlet_duty[i] = 0.0;
    if (!std::isfinite(valves.outlet_duty[i])) state_.command.outlet_duty[i] = 1.0;
  }
  state_.pwm_phase_s = 0.0;  // a new command starts a new PWM period
}

void SimulatedArm::vent() { write_valves(ValveCommand::vented()); }

BellowsDuties SimulatedArm::duties() const { return {state_.command.inlet_duty, state_.command.outlet_duty}; }

BellowsOpenings SimulatedArm::openings_at(double phase_s) const {
  BellowsOpenings open = pwm_openings(duties(), phase_s, params_.pwm_period_s);
  if (state_.fault == SimulatedFault::kStuckInlet) open.inlet[0] = true;
  if (state_.fault == SimulatedFault::kDeadInlet) open.inlet[0] = false;
  if (state_.fault == SimulatedFault::kSwappedChambers) {
    std::swap(open.inlet[0], open.inlet[1]);
    std::swap(open.outlet[0], open.outlet[1]);
  }
  return open;
}

double SimulatedArm::time_to_next_switch(double phase_s) const {
  return pwm_time_to_next_edge(duties(), phase_s, params_.pwm_period_s);
}

SimulatedArm::Physical SimulatedArm::derivative(const Physical& x, const BellowsOpenings& open) const {
  const PlantParameters& p = params_;
  double pressure_rate[2];
  bellows_.pressure_rates(x.angle_rad, x.velocity_rad_per_s, x.pa_Pa, x.pb_Pa, open, supply_Pa_, pressure_rate[0],
                          pressure_rate[1]);
  const double w0 = p.omega0_rad_per_s;
  const double dp_bar = (x.pa_Pa - x.pb_Pa) / kPaPerBar;
  double acceleration = w0 * w0 * (p.kappa_rad_per_bar * dp_bar - x.angle_rad - x.creep_rad) -
                        2.0 * p.damping * w0 * x.velocity_rad_per_s;
  const double stop_rad = p.hard_stop_deg * kRadPerDeg;
  const double beyond = std::abs(x.angle_rad) - stop_rad;
  if (beyond > 0.0) {
    const double direction = x.angle_rad > 0.0 ? 1.0 : -1.0;
    acceleration -=
        direction * p.hard_stop_stiffness_per_s2 * beyond + p.hard_stop_damping_per_s * x.velocity_rad_per_s;
  }
  return {x.velocity_rad_per_s, acceleration, (p.creep_gain * x.angle_rad - x.creep_rad) / p.creep_tau_s,
          pressure_rate[0], pressure_rate[1]};
}

void SimulatedArm::integrate(double h, const BellowsOpenings& open) {
  // Classical RK4 with the valve openings constant over the step (steps end on switching edges).
  const Physical x{state_.angle_rad, state_.angular_velocity_rad_per_s, state_.creep_rad, state_.chamber_Pa[0],
                   state_.chamber_Pa[1]};
  auto axpy = [](const Physical& a, double k, const Physical& d) {
    return Physical{a.angle_rad + k * d.angle_rad, a.velocity_rad_per_s + k * d.velocity_rad_per_s,
                    a.creep_rad + k * d.creep_rad, a.pa_Pa + k * d.pa_Pa, a.pb_Pa + k * d.pb_Pa};
  };
  const Physical k1 = derivative(x, open);
  const Physical k2 = derivative(axpy(x, h / 2, k1), open);
  const Physical k3 = derivative(axpy(x, h / 2, k2), open);
  const Physical k4 = derivative(axpy(x, h, k3), open);
  auto combine = [&](double Physical::*f) { return x.*f + h / 6.0 * (k1.*f + 2.0 * k2.*f + 2.0 * k3.*f + k4.*f); };
  state_.angle_rad = combine(&Physical::angle_rad);
  state_.angular_velocity_rad_per_s = combine(&Physical::velocity_rad_per_s);
  state_.creep_rad = combine(&Physical::creep_rad);
  state_.chamber_Pa[0] = std::max(1.0, combine(&Physical::pa_Pa));
  state_.chamber_Pa[1] = std::max(1.0, combine(&Physical::pb_Pa));
}

void SimulatedArm::advance(double dt_s) {
  // Tolerance so that float drift never produces sliver steps at period boundaries.
  constexpr double kEpsilon_s = 1e-12;
  const double period = params_.pwm_period_s;
  activate_scheduled_fault();
  double remaining = dt_s;
  while (remaining > kEpsilon_s) {
    if (state_.pwm_phase_s >= period - kEpsilon_s) state_.pwm_phase_s = 0.0;  // PWM repeats
    const double h = std::min({params_.integration_step_s, remaining, time_to_next_switch(state_.pwm_phase_s)});
    integrate(h, openings_at(state_.pwm_phase_s));
    state_.pwm_phase_s += h;
    state_.time_s += h;
    remaining -= h;
  }
}

}  // namespace bellows
