#include "engine/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/errors.hpp"

namespace bellows {
namespace {

template <typename Member>
ParameterBinding number(std::string section, std::string key, std::string unit, std::string description,
                        Constraint constraint, Member member) {
  ParameterBinding b{std::move(section), std::move(key), std::move(unit), std::move(description), constraint, {}, {}, {}};
  b.real = member;
  return b;
}

template <typename Member>
ParameterBinding whole(std::string section, std::string key, std::string description, Member member) {
  ParameterBinding b{std::move(section), std::move(key), "", std::move(description), Constraint::kPositive, {}, {}, {}};
  b.integer = member;
  return b;
}

std::vector<ParameterBinding> make_bindings() {
  using C = Configuration;
  constexpr Constraint kPos = Constraint::kPositive, kNonNeg = Constraint::kNonNegative, kAny = Constraint::kAny;
  std::vector<ParameterBinding> b = {
      // [plant]: the simulated arm's truth
      number("plant", "kappa", "rad/bar", "static gain from pressure difference to angle", kPos, [](C& c) { return &c.plant.kappa_rad_per_bar; }),
      number("plant", "omega0", "rad/s", "natural frequency", kPos, [](C& c) { return &c.plant.omega0_rad_per_s; }),
      number("plant", "damping", "", "damping ratio delta", kPos, [](C& c) { return &c.plant.damping; }),
      number("plant", "volume_l", "L", "average volume of one bellows", kPos, [](C& c) { return &c.plant.volume_l; }),
      number("plant", "volume_gain", "1/rad", "beta: V = V0 (1 +- beta alpha)", kNonNeg, [](C& c) { return &c.plant.volume_gain_per_rad; }),
      number("plant", "valve_conductance", "m^3/(s Pa)", "ISO 6358 sonic conductance of one valve", kPos, [](C& c) { return &c.plant.valve_conductance_m3_per_sPa; }),
      number("plant", "valve_critical_ratio", "", "ISO 6358 critical pressure ratio b", Constraint::kFraction, [](C& c) { return &c.plant.valve_critical_ratio; }),
      whole("plant", "valves_per_port", "valves per inlet and per outlet of one actuator", [](C& c) { return &c.plant.valves_per_port; }),
      number("plant", "creep_gain", "", "c_z of the viscoelastic creep", kNonNeg, [](C& c) { return &c.plant.creep_gain; }),
      number("plant", "creep_tau_s", "s", "time constant of the creep", kPos, [](C& c) { return &c.plant.creep_tau_s; }),
      number("plant", "supply_bar", "bar", "absolute supply pressure", kPos, [](C& c) { return &c.plant.supply_bar; }),
      number("plant", "encoder_resolution_deg", "deg", "encoder quantization step", kNonNeg, [](C& c) { return &c.plant.encoder_resolution_deg; }),
      number("plant", "pressure_noise_bar", "bar", "sigma of the pressure-sensor noise", kNonNeg, [](C& c) { return &c.plant.pressure_noise_bar; }),
      number("plant", "hard_stop_deg", "deg", "angle of the hard stops", kPos, [](C& c) { return &c.plant.hard_stop_deg; }),
      number("plant", "hard_stop_stiffness", "1/s^2", "stiffness of the hard stops", kPos, [](C& c) { return &c.plant.hard_stop_stiffness_per_s2; }),
      number("plant", "hard_stop_damping", "1/s", "damping of the hard stops", kNonNeg, [](C& c) { return &c.plant.hard_stop_damping_per_s; }),
      number("plant", "integration_step_s", "s", "fixed internal integration step", kPos, [](C& c) { return &c.plant.integration_step_s; }),
      number("plant", "pwm_period_s", "s", "PWM period of the switching valves", kPos, [](C& c) { return &c.plant.pwm_period_s; }),
      number("plant", "fault_at_s", "s", "device time of the injected fault", kNonNeg, [](C& c) { return &c.plant.fault_at_s; }),
      number("plant", "spike_bar", "bar", "size of an injected pressure-sensor spike", kNonNeg, [](C& c) { return &c.plant.spike_bar; }),
      number("plant", "spike_s", "s", "duration of an injected pressure-sensor spike", kPos, [](C& c) { return &c.plant.spike_s; }),
      number("plant", "temperature_K", "K", "air temperature", kPos, [](C& c) { return &c.plant.gas.temperature_K; }),
      // [model]: the nominal model the learning uses
      number("model", "kappa", "rad/bar", "nominal static gain", kPos, [](C& c) { return &c.model.kappa_rad_per_bar; }),
      number("model", "omega0", "rad/s", "nominal natural frequency", kPos, [](C& c) { return &c.model.omega0_rad_per_s; }),
      number("model", "damping", "", "nominal damping ratio", kPos, [](C& c) { return &c.model.damping; }),
      number("model", "volume_gain", "1/rad", "beta of V = V0 (1 +- beta alpha) the convergence prediction assumes", kNonNeg, [](C& c) { return &c.model.volume_gain_per_rad; }),
      // [controller]
      number("controller", "k_ff", "", "feed-forward gain (normalized)", kAny, [](C& c) { return &c.controller.k_ff; }),
      number("controller", "k_p", "", "proportional gain (normalized)", kNonNeg, [](C& c) { return &c.controller.k_p; }),
      number("controller", "k_i", "1/s", "integral gain (normalized)", kNonNeg, [](C& c) { return &c.controller.k_i_per_s; }),
      number("controller", "k_d", "s", "derivative gain (normalized)", kNonNeg, [](C& c) { return &c.controller.k_d_s; }),
      number("controller", "integrator_limit_bar", "bar", "bound on the integral term", kNonNeg, [](C& c) { return &c.controller.integrator_limit_bar; }),
      number("controller", "tau_p_s", "s", "desired time constant of the pressure response", kPos, [](C& c) { return &c.controller.tau_p_s; }),
      number("controller", "p_max_bar", "bar", "highest absolute pressure set point", kPos, [](C& c) { return &c.controller.p_max_bar; }),
      whole("controller", "filter_samples", "moving-average length on measured pressure", [](C& c) { return &c.controller.filter_samples; }),
      number("controller", "valve_conductance", "m^3/(s Pa)", "nominal conductance the inversion uses", kPos, [](C& c) { return &c.controller.valve_conductance_m3_per_sPa; }),
      number("controller", "valve_critical_ratio", "", "nominal critical ratio the inversion uses", Constraint::kFraction, [](C& c) { return &c.controller.valve_critical_ratio; }),
      whole("controller", "valves_per_port", "nominal valves per port the inversion uses", [](C& c) { return &c.controller.valves_per_port; }),
      number("controller", "volume_l", "L", "nominal bellows volume the inversion uses", kPos, [](C& c) { return &c.controller.volume_l; }),
      // [ilc]
      number("ilc", "m", "", "weight M = m I on the predicted error", kNonNeg, [](C& c) { return &c.ilc.m; }),
      number("ilc", "s", "", "weight S = s I on the change of correction", kNonNeg, [](C& c) { return &c.ilc.s; }),
      number("ilc", "w", "", "weight W = w I on the correction's rate", kNonNeg, [](C& c) { return &c.ilc.w; }),
      number("ilc", "admm_rho", "", "noilc-constrained: ADMM penalty", kPos, [](C& c) { return &c.ilc.admm_rho; }),
      whole("ilc", "admm_max_iterations", "noilc-constrained: ADMM iteration limit per update", [](C& c) { return &c.ilc.admm_max_iterations; }),
      number("ilc", "admm_tolerance", "bar", "noilc-constrained: ADMM residual tolerance", kPos, [](C& c) { return &c.ilc.admm_tolerance; }),
      number("ilc", "limit_margin_bar", "bar", "noilc-constrained: keep u_pid + u_ilc this far inside the pressure limits", kNonNeg, [](C& c) { return &c.ilc.limit_margin_bar; }),
      number("ilc", "limit_recovery_s", "s", "noilc-constrained: errors this long after a set point on the pressure limit are not learned from", kNonNeg, [](C& c) { return &c.ilc.limit_recovery_s; }),
      number("ilc", "pd_kp", "", "pd: proportional learning gain", kAny, [](C& c) { return &c.ilc.pd_kp; }),
      number("ilc", "pd_kd_s", "s", "pd: derivative learning gain", kAny, [](C& c) { return &c.ilc.pd_kd_s; }),
      number("ilc", "pd_q_cutoff_hz", "Hz", "pd: cutoff of the zero-phase Q-filter", kPos, [](C& c) { return &c.ilc.pd_q_cutoff_hz; }),
      number("ilc", "gradient_step", "", "gradient: step as a fraction of 1/||P||^2, in (0, 2)", kPos, [](C& c) { return &c.ilc.gradient_step; }),
      number("ilc", "inverse_gain", "", "inverse: learning gain in (0, 1]", kPos, [](C& c) { return &c.ilc.inverse_gain; }),
      number("ilc", "inverse_q_cutoff_hz", "Hz", "inverse: cutoff of the zero-phase Q-filter", kPos, [](C& c) { return &c.ilc.inverse_q_cutoff_hz; }),
      number("ilc", "prediction_model_error", "", "convergence prediction: relative error of kappa and omega0 on the grid", Constraint::kFraction, [](C& c) { return &c.ilc.prediction_model_error; }),
      whole("ilc", "prediction_grid_points", "convergence prediction: grid points per parameter", [](C& c) { return &c.ilc.prediction_grid_points; }),
      // [identify]
      number("identify", "amplitude_deg", "deg", "excitation amplitude of the reference angle", kPos, [](C& c) { return &c.identify.amplitude_deg; }),
      number("identify", "max_abs_angle_deg", "deg", "abort the identification trial beyond this angle", kPos, [](C& c) { return &c.identify.max_abs_angle_deg; }),
      number("identify", "duration_s", "s", "length of each identification trial", kPos, [](C& c) { return &c.identify.duration_s; }),
      number("identify", "chirp_start_hz", "Hz", "chirp: start frequency", kPos, [](C& c) { return &c.identify.chirp_start_hz; }),
      number("identify", "chirp_end_hz", "Hz", "chirp: end frequency", kPos, [](C& c) { return &c.identify.chirp_end_hz; }),
      number("identify", "step_hold_s", "s", "steps: time between steps", kPos, [](C& c) { return &c.identify.step_hold_s; }),
      // [timing]
      number("timing", "tick_s", "s", "loop period (pressure controllers, PWM)", kPos, [](C& c) { return &c.timing.tick_s; }),
      whole("timing", "ticks_per_sample", "loop ticks per ILC sample", [](C& c) { return &c.timing.ticks_per_sample; }),
      number("timing", "settle_s", "s", "hold at the start before each trial", kNonNeg, [](C& c) { return &c.timing.settle_s; }),
      // [trajectory]
      // [safety]: the guards' limits
      number("safety", "angle_limit_deg", "deg", "fault beyond this angle", kPos, [](C& c) { return &c.safety.angle_limit_deg; }),
      number("safety", "pressure_margin_bar", "bar", "fault when a chamber exceeds p_max plus this", kNonNeg, [](C& c) { return &c.safety.pressure_margin_bar; }),
      number("safety", "supply_min_bar", "bar", "fault below this absolute supply pressure", kPos, [](C& c) { return &c.safety.supply_min_bar; }),
      number("safety", "sensor_min_bar", "bar", "lowest plausible pressure reading", kNonNeg, [](C& c) { return &c.safety.sensor_min_bar; }),
      number("safety", "sensor_max_bar", "bar", "highest plausible pressure reading", kPos, [](C& c) { return &c.safety.sensor_max_bar; }),
      number("safety", "sensor_max_angle_deg", "deg", "largest plausible encoder reading", kPos, [](C& c) { return &c.safety.sensor_max_angle_deg; }),
      whole("safety", "stale_ticks", "ticks without a fresh reading before a stale-sensor fault", [](C& c) { return &c.safety.stale_ticks; }),
      whole("safety", "missed_deadline_streak", "consecutive missed deadlines before a fault", [](C& c) { return &c.safety.missed_deadline_streak; }),
      number("safety", "heartbeat_timeout_s", "s", "console silent this long: fault", kPos, [](C& c) { return &c.safety.heartbeat_timeout_s; }),
      number("safety", "black_box_s", "s", "ticks kept before a fault", kPos, [](C& c) { return &c.safety.black_box_s; }),
      number("trajectory", "max_abs_angle_deg", "deg", "joint range every trajectory must stay inside", kPos, [](C& c) { return &c.trajectory.max_abs_angle_deg; }),
      number("lcm", "rig_timeout_s", "s", "a rig vents by itself when commands stop for this long", kPos, [](C& c) { return &c.lcm.rig_timeout_s; }),
      number("lcm", "connect_timeout_s", "s", "run --device lcm waits this long for a rig to answer", kPos, [](C& c) { return &c.lcm.connect_timeout_s; }),
      number("t7", "response_timeout_s", "s", "one Modbus request to the T7 waits this long for its answer", kPos, [](C& c) { return &c.t7.response_timeout_s; }),
      number("t7", "connect_timeout_s", "s", "connecting to the T7 and configuring it may take this long", kPos, [](C& c) { return &c.t7.connect_timeout_s; }),
      whole("t7", "watchdog_timeout_s", "the T7's own watchdog vents after this much silence (whole seconds, at least 1)", [](C& c) { return &c.t7.watchdog_timeout_s; }),
      number("t7", "command_timeout_s", "s", "the T7 link vents when the engine sends no command this long", kPos, [](C& c) { return &c.t7.command_timeout_s; }),
  };
  ParameterBinding fault{"plant", "fault", "", "injected fault: none, sensor-dropout, stuck-inlet, supply-loss, nan-angle, pressure-spike", Constraint::kAny, {}, {}, {}};
  fault.text = [](C& c) { return &c.plant.fault; };
  const auto after_plant = std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.key == "fault_at_s"; });
  b.insert(after_plant, fault);
  ParameterBinding law{"ilc", "law", "", "learning law: noilc, noilc-dense, noilc-constrained, pd, gradient or inverse",
                       Constraint::kAny, {}, {}, {}};
  law.text = [](C& c) { return &c.ilc.law; };
  const auto first_ilc = std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.section == "ilc"; });
  b.insert(first_ilc, law);
  ParameterBinding signal{"identify", "signal", "", "excitation of the identification trial: chirp or steps",
                          Constraint::kAny, {}, {}, {}};
  signal.text = [](C& c) { return &c.identify.signal; };
  const auto first_identify = std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.section == "identify"; });
  b.insert(first_identify, signal);
  return b;
}

std::string describe(const ParameterBinding& b) { return "[" + b.section + "] " + b.key; }

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

const std::vector<ParameterBinding>& parameter_bindings() {
  static const std::vector<ParameterBinding> bindings = make_bindings();
  return bindings;
}

void validate_configuration(const Configuration& config) {
  Configuration copy = config;  // the bindings hand out pointers into a mutable configuration
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.text) continue;
    const double value = b.real ? *b.real(copy) : static_cast<double>(*b.integer(copy));
    const std::string where = describe(b) + " = " + format_number(value);
    if (!std::isfinite(value)) throw InputError(where + ": must be a finite number");
    switch (b.constraint) {
      case Constraint::kPositive:
        if (!(value > 0.0)) throw InputError(where + ": must be positive");
        break;
      case Constraint::kNonNegative:
        if (value < 0.0) throw InputError(where + ": must not be negative");
        break;
      case Constraint::kFraction:
        if (value < 0.0 || value >= 1.0) throw InputError(where + ": must be in [0, 1)");
        break;
      case Constraint::kAny:
        break;
    }
  }
  const double ambient = config.controller.gas.ambient_bar;
  if (config.controller.p_max_bar <= ambient) {
    throw InputError("[controller] p_max_bar = " + format_number(config.controller.p_max_bar) +
                     ": must be above ambient pressure " + format_number(ambient) + " bar");
  }
  if (config.plant.supply_bar <= config.controller.p_max_bar) {
    throw InputError("[plant] supply_bar = " + format_number(config.plant.supply_bar) +
                     ": must be above [controller] p_max_bar = " + format_number(config.controller.p_max_bar));
  }
  if (config.plant.volume_gain_per_rad * config.plant.hard_stop_deg * 3.14159265358979 / 180.0 >= 0.9) {
    throw InputError("[plant] volume_gain = " + format_number(config.plant.volume_gain_per_rad) +
                     ": the bellows volume would vanish before the hard stops");
  }
  if (config.trajectory.max_abs_angle_deg >= config.safety.angle_limit_deg) {
    throw InputError("[trajectory] max_abs_angle_deg must be below [safety] angle_limit_deg");
  }
  if (config.plant.integration_step_s > config.plant.pwm_period_s) {
    throw InputError("[plant] integration_step_s must not exceed [plant] pwm_period_s");
  }
  if (config.t7.watchdog_timeout_s < 1) {
    throw InputError("[t7] watchdog_timeout_s = " + std::to_string(config.t7.watchdog_timeout_s) +
                     ": the T7's watchdog counts whole seconds, 1 at least");
  }
}

}  // namespace bellows
