#include "engine/config/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <tuple>

#include "engine/config/configuration_cost.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/identification_trial.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/control/pressure_controller.hpp"

namespace bellows {
namespace {

// Ranges. They are physical bounds wide enough for any lab's arm, and narrow enough that no value
// inside them makes a run allocate or compute without limit (the costs that depend on several keys
// together are checked by engine/config/configuration_cost).
Range pos(double max) { return {0.0, max, true, false}; }    // (0, max]
Range upto(double max) { return {0.0, max, false, false}; }  // [0, max]
Range between(double min, double max) { return {min, max, false, false}; }
Range fraction() { return {0.0, 1.0, false, true}; }                            // [0, 1)
Range count(int max) { return {1.0, static_cast<double>(max), false, false}; }  // whole numbers 1..max

template <typename Member>
ParameterBinding number(std::string section, std::string key, std::string unit, std::string description, Range range,
                        Member member) {
  ParameterBinding b{std::move(section), std::move(key), std::move(unit), std::move(description), range, {}, {}, {}};
  b.real = member;
  return b;
}

template <typename Member>
ParameterBinding whole(std::string section, std::string key, std::string description, Range range, Member member) {
  ParameterBinding b{std::move(section), std::move(key), "", std::move(description), range, {}, {}, {}};
  b.integer = member;
  return b;
}

// Strings have no range; the law, signal and fault names are checked where they are used.
template <typename Member>
ParameterBinding name(std::string section, std::string key, std::string description, Member member) {
  ParameterBinding b{std::move(section), std::move(key), "", std::move(description), {}, {}, {}, {}};
  b.text = member;
  return b;
}

std::vector<ParameterBinding> make_bindings() {
  using C = Configuration;
  std::vector<ParameterBinding> b = {
      // [plant]: the simulated arm's truth
      number("plant", "kappa", "rad/bar", "static gain from pressure difference to angle", pos(100.0),
             [](C& c) { return &c.plant.kappa_rad_per_bar; }),
      number("plant", "omega0", "rad/s", "natural frequency", pos(1000.0),
             [](C& c) { return &c.plant.omega0_rad_per_s; }),
      number("plant", "damping", "", "damping ratio delta", pos(10.0), [](C& c) { return &c.plant.damping; }),
      number("plant", "volume_l", "L", "average volume of one bellows", pos(10.0),
             [](C& c) { return &c.plant.volume_l; }),
      number("plant", "volume_gain", "1/rad", "beta: V = V0 (1 +- beta alpha)", upto(10.0),
             [](C& c) { return &c.plant.volume_gain_per_rad; }),
      number("plant", "valve_conductance", "m^3/(s Pa)", "ISO 6358 sonic conductance of one valve", pos(1e-6),
             [](C& c) { return &c.plant.valve_conductance_m3_per_sPa; }),
      number("plant", "valve_critical_ratio", "", "ISO 6358 critical pressure ratio b", fraction(),
             [](C& c) { return &c.plant.valve_critical_ratio; }),
      whole("plant", "valves_per_port", "valves per inlet and per outlet of one actuator", count(16),
            [](C& c) { return &c.plant.valves_per_port; }),
      number("plant", "creep_gain", "", "c_z of the viscoelastic creep", upto(10.0),
             [](C& c) { return &c.plant.creep_gain; }),
      number("plant", "creep_tau_s", "s", "time constant of the creep", pos(1000.0),
             [](C& c) { return &c.plant.creep_tau_s; }),
      number("plant", "supply_bar", "bar", "absolute supply pressure", pos(20.0),
             [](C& c) { return &c.plant.supply_bar; }),
      number("plant", "encoder_resolution_deg", "deg", "encoder quantization step", upto(10.0),
             [](C& c) { return &c.plant.encoder_resolution_deg; }),
      number("plant", "pressure_noise_bar", "bar", "sigma of the pressure-sensor noise", upto(1.0),
             [](C& c) { return &c.plant.pressure_noise_bar; }),
      number("plant", "hard_stop_deg", "deg", "angle of the hard stops", pos(180.0),
             [](C& c) { return &c.plant.hard_stop_deg; }),
      number("plant", "hard_stop_stiffness", "1/s^2", "stiffness of the hard stops", pos(1e8),
             [](C& c) { return &c.plant.hard_stop_stiffness_per_s2; }),
      number("plant", "hard_stop_damping", "1/s", "damping of the hard stops", upto(1e6),
             [](C& c) { return &c.plant.hard_stop_damping_per_s; }),
      number("plant", "integration_step_s", "s", "fixed internal integration step", between(1e-6, 1e-2),
             [](C& c) { return &c.plant.integration_step_s; }),
      number("plant", "pwm_period_s", "s", "PWM period of the switching valves", between(1e-4, 1.0),
             [](C& c) { return &c.plant.pwm_period_s; }),
      number("plant", "fault_at_s", "s", "device time of the injected fault", upto(1e6),
             [](C& c) { return &c.plant.fault_at_s; }),
      number("plant", "spike_bar", "bar", "size of an injected pressure-sensor spike", upto(10.0),
             [](C& c) { return &c.plant.spike_bar; }),
      number("plant", "spike_s", "s", "duration of an injected pressure-sensor spike", pos(60.0),
             [](C& c) { return &c.plant.spike_s; }),
      number("plant", "temperature_K", "K", "air temperature", between(200.0, 400.0),
             [](C& c) { return &c.plant.gas.temperature_K; }),
      // [model]: the nominal model the learning uses
      number("model", "kappa", "rad/bar", "nominal static gain", pos(100.0),
             [](C& c) { return &c.model.kappa_rad_per_bar; }),
      number("model", "omega0", "rad/s", "nominal natural frequency", pos(1000.0),
             [](C& c) { return &c.model.omega0_rad_per_s; }),
      number("model", "damping", "", "nominal damping ratio", pos(10.0), [](C& c) { return &c.model.damping; }),
      number("model", "volume_gain", "1/rad", "beta of V = V0 (1 +- beta alpha) the convergence prediction assumes",
             upto(10.0), [](C& c) { return &c.model.volume_gain_per_rad; }),
      // [controller]
      number("controller", "k_ff", "", "feed-forward gain (normalized)", between(-100.0, 100.0),
             [](C& c) { return &c.controller.k_ff; }),
      number("controller", "k_p", "", "proportional gain (normalized)", upto(100.0),
             [](C& c) { return &c.controller.k_p; }),
      number("controller", "k_i", "1/s", "integral gain (normalized)", upto(1000.0),
             [](C& c) { return &c.controller.k_i_per_s; }),
      number("controller", "k_d", "s", "derivative gain (normalized)", upto(10.0),
             [](C& c) { return &c.controller.k_d_s; }),
      number("controller", "integrator_limit_bar", "bar", "bound on the integral term", upto(20.0),
             [](C& c) { return &c.controller.integrator_limit_bar; }),
      number("controller", "tau_p_s", "s", "desired time constant of the pressure response", pos(10.0),
             [](C& c) { return &c.controller.tau_p_s; }),
      number("controller", "p_max_bar", "bar", "highest absolute pressure set point", pos(20.0),
             [](C& c) { return &c.controller.p_max_bar; }),
      whole("controller", "filter_samples", "moving-average length on measured pressure",
            count(PressureController::kMaxFilterSamples), [](C& c) { return &c.controller.filter_samples; }),
      number("controller", "valve_conductance", "m^3/(s Pa)", "nominal conductance the inversion uses", pos(1e-6),
             [](C& c) { return &c.controller.valve_conductance_m3_per_sPa; }),
      number("controller", "valve_critical_ratio", "", "nominal critical ratio the inversion uses", fraction(),
             [](C& c) { return &c.controller.valve_critical_ratio; }),
      whole("controller", "valves_per_port", "nominal valves per port the inversion uses", count(16),
            [](C& c) { return &c.controller.valves_per_port; }),
      number("controller", "volume_l", "L", "nominal bellows volume the inversion uses", pos(10.0),
             [](C& c) { return &c.controller.volume_l; }),
      // [ilc]
      number("ilc", "m", "", "weight M = m I on the predicted error", upto(1e6), [](C& c) { return &c.ilc.m; }),
      number("ilc", "s", "", "weight S = s I on the change of correction", upto(1e6), [](C& c) { return &c.ilc.s; }),
      number("ilc", "w", "", "weight W = w I on the correction's rate", upto(1e6), [](C& c) { return &c.ilc.w; }),
      number("ilc", "admm_rho", "", "noilc-constrained: ADMM penalty", pos(1e6), [](C& c) { return &c.ilc.admm_rho; }),
      whole("ilc", "admm_max_iterations", "noilc-constrained: ADMM iteration limit per update", count(100000),
            [](C& c) { return &c.ilc.admm_max_iterations; }),
      number("ilc", "admm_tolerance", "bar", "noilc-constrained: ADMM residual tolerance", pos(1.0),
             [](C& c) { return &c.ilc.admm_tolerance; }),
      number("ilc", "limit_margin_bar", "bar",
             "noilc-constrained: keep u_pid + u_ilc this far inside the pressure limits", upto(10.0),
             [](C& c) { return &c.ilc.limit_margin_bar; }),
      number("ilc", "limit_recovery_s", "s",
             "noilc-constrained: errors this long after a set point on the pressure limit are not learned from",
             upto(60.0), [](C& c) { return &c.ilc.limit_recovery_s; }),
      number("ilc", "pd_kp", "", "pd: proportional learning gain", between(-100.0, 100.0),
             [](C& c) { return &c.ilc.pd_kp; }),
      number("ilc", "pd_kd_s", "s", "pd: derivative learning gain", between(-10.0, 10.0),
             [](C& c) { return &c.ilc.pd_kd_s; }),
      number("ilc", "pd_q_cutoff_hz", "Hz", "pd: cutoff of the zero-phase Q-filter", pos(1e4),
             [](C& c) { return &c.ilc.pd_q_cutoff_hz; }),
      number("ilc", "gradient_step", "", "gradient: step as a fraction of 1/||P||^2, in (0, 2)",
             Range{0.0, 2.0, true, true}, [](C& c) { return &c.ilc.gradient_step; }),
      number("ilc", "inverse_gain", "", "inverse: learning gain in (0, 1]", pos(1.0),
             [](C& c) { return &c.ilc.inverse_gain; }),
      number("ilc", "inverse_q_cutoff_hz", "Hz", "inverse: cutoff of the zero-phase Q-filter", pos(1e4),
             [](C& c) { return &c.ilc.inverse_q_cutoff_hz; }),
      number("ilc", "prediction_model_error", "",
             "convergence prediction: relative error of kappa and omega0 on the grid", fraction(),
             [](C& c) { return &c.ilc.prediction_model_error; }),
      number("ilc", "learned_s", "", "noilc-learned: weight S = s I on the change of correction", upto(1e6),
             [](C& c) { return &c.ilc.learned_s; }),
      number("ilc", "learned_forgetting", "", "noilc-learned: weight of an older trial in the model's refit, per trial",
             Range{0.0, 1.0, true, false}, [](C& c) { return &c.ilc.learned_forgetting; }),
      number("ilc", "learned_ridge", "", "noilc-learned: ridge of the refit, relative to the data's scale", pos(1e6),
             [](C& c) { return &c.ilc.learned_ridge; }),
      number("ilc", "learned_guard", "",
             "noilc-learned: a trial whose squared error rose more than this fraction over the best falls back to the "
             "prior",
             upto(100.0), [](C& c) { return &c.ilc.learned_guard; }),
      whole("ilc", "learned_taps", "noilc-learned: FIR taps of the model's learned correction per joint", count(32),
            [](C& c) { return &c.ilc.learned_taps; }),
      whole("ilc", "learned_joints_refit_plans",
            "noilc-learned, several joints: 1 lets the refit model plan when it predicted better; 0 the prior plans",
            between(0.0, 1.0), [](C& c) { return &c.ilc.learned_joints_refit_plans; }),
      whole(
          "ilc", "learned_joints_zero_limited",
          "noilc-learned, several joints: 1 zeroes the limit-shaped errors in the update; 0 only the refit omits them",
          between(0.0, 1.0), [](C& c) { return &c.ilc.learned_joints_zero_limited; }),
      number("ilc", "learned_joints_descent_slack", "",
             "noilc-learned, several joints: a trial within this fraction above the best's squared error counts as a "
             "descent",
             between(0.0, 1.0), [](C& c) { return &c.ilc.learned_joints_descent_slack; }),
      whole("ilc", "prediction_grid_points", "convergence prediction: grid points per parameter", count(21),
            [](C& c) { return &c.ilc.prediction_grid_points; }),
      // [identify]
      number("identify", "amplitude_deg", "deg", "excitation amplitude of the reference angle", pos(90.0),
             [](C& c) { return &c.identify.amplitude_deg; }),
      number("identify", "max_abs_angle_deg", "deg", "abort the identification trial beyond this angle", pos(180.0),
             [](C& c) { return &c.identify.max_abs_angle_deg; }),
      number("identify", "duration_s", "s", "length of each identification trial", between(3.0, 600.0),
             [](C& c) { return &c.identify.duration_s; }),
      number("identify", "chirp_start_hz", "Hz", "chirp: start frequency", pos(1000.0),
             [](C& c) { return &c.identify.chirp_start_hz; }),
      number("identify", "chirp_end_hz", "Hz", "chirp: end frequency", pos(1000.0),
             [](C& c) { return &c.identify.chirp_end_hz; }),
      number("identify", "step_hold_s", "s", "steps: time between steps", pos(600.0),
             [](C& c) { return &c.identify.step_hold_s; }),
      // [timing]
      number("timing", "tick_s", "s", "loop period (pressure controllers, PWM)", between(1e-4, 1.0),
             [](C& c) { return &c.timing.tick_s; }),
      whole("timing", "ticks_per_sample", "loop ticks per ILC sample", count(1000),
            [](C& c) { return &c.timing.ticks_per_sample; }),
      number("timing", "settle_s", "s", "hold at the start before each trial", upto(60.0),
             [](C& c) { return &c.timing.settle_s; }),
      number("timing", "settle_max_s", "s", "hold on after settle_s while a joint is off its start, up to this in all",
             upto(60.0), [](C& c) { return &c.timing.settle_max_s; }),
      number("timing", "settle_tolerance_deg", "deg", "a joint this close to its first set point is at its start",
             pos(90.0), [](C& c) { return &c.timing.settle_tolerance_deg; }),
      // [trajectory]
      // [safety]: the guards' limits
      number("safety", "angle_limit_deg", "deg", "fault beyond this angle", pos(180.0),
             [](C& c) { return &c.safety.angle_limit_deg; }),
      number("safety", "pressure_margin_bar", "bar", "fault when a chamber exceeds p_max plus this", upto(10.0),
             [](C& c) { return &c.safety.pressure_margin_bar; }),
      number("safety", "supply_min_bar", "bar", "fault below this absolute supply pressure", pos(20.0),
             [](C& c) { return &c.safety.supply_min_bar; }),
      number("safety", "sensor_min_bar", "bar", "lowest plausible pressure reading", upto(20.0),
             [](C& c) { return &c.safety.sensor_min_bar; }),
      number("safety", "sensor_max_bar", "bar", "highest plausible pressure reading", pos(100.0),
             [](C& c) { return &c.safety.sensor_max_bar; }),
      number("safety", "sensor_max_angle_deg", "deg", "largest plausible encoder reading", pos(360.0),
             [](C& c) { return &c.safety.sensor_max_angle_deg; }),
      whole("safety", "stale_ticks",
            "ticks in a row without a fresh reading (valves held closed) before the fault: 8 x 5 ms = 40 ms, "
            "docs/architecture.md",
            count(100000), [](C& c) { return &c.safety.stale_ticks; }),
      whole("safety", "missed_deadline_streak",
            "missed deadlines in a row before a fault (a rig whose time is its own; held below it): 8 x 5 ms = 40 ms, "
            "docs/architecture.md",
            count(1000000), [](C& c) { return &c.safety.missed_deadline_streak; }),
      number("safety", "heartbeat_timeout_s", "s", "console silent this long: fault", pos(3600.0),
             [](C& c) { return &c.safety.heartbeat_timeout_s; }),
      number("safety", "black_box_s", "s", "ticks kept before a fault", pos(60.0),
             [](C& c) { return &c.safety.black_box_s; }),
      number("trajectory", "max_abs_angle_deg", "deg", "joint range every trajectory must stay inside", pos(180.0),
             [](C& c) { return &c.trajectory.max_abs_angle_deg; }),
      number("lcm", "rig_timeout_s", "s", "a rig vents by itself when commands stop for this long", pos(60.0),
             [](C& c) { return &c.lcm.rig_timeout_s; }),
      number("lcm", "connect_timeout_s", "s", "run --device lcm waits this long for a rig to answer", pos(3600.0),
             [](C& c) { return &c.lcm.connect_timeout_s; }),
      number("lcm", "lockstep_timeout_s", "s",
             "run --clock lockstep: a tick waits this long for the rig's answer (else it has no reading); io-sim "
             "--stepped drops a session silent this long",
             pos(60.0), [](C& c) { return &c.lcm.lockstep_timeout_s; }),
      whole("lcm", "seq_window", "largest step a rig accepts between a session's command sequence numbers",
            count(1000000), [](C& c) { return &c.lcm.seq_window; }),
      number("lcm", "rig_pressure_margin_bar", "bar",
             "a rig vents a chamber above [controller] p_max_bar plus this, at least [safety] pressure_margin_bar",
             upto(10.0), [](C& c) { return &c.lcm.rig_pressure_margin_bar; }),
      number("lcm", "rig_angle_limit_deg", "deg",
             "a rig vents and drops its session beyond this angle, in [[safety] angle_limit_deg, 180]", pos(180.0),
             [](C& c) { return &c.lcm.rig_angle_limit_deg; }),
      number("lcm", "tick_phase_lead", "",
             "on the wall clock the engine's ticks lock to the phase of the rig's states: each is read this share of "
             "a tick after it arrives (in (0, 1); half a tick leaves the most room for jitter)",
             Range{0.0, 1.0, true, true}, [](C& c) { return &c.lcm.tick_phase_lead; }),
      number("lcm", "tick_phase_step_s", "s",
             "largest shift of one tick's deadline towards that phase, at most a tenth of [timing] tick_s; 0: no lock",
             upto(0.01), [](C& c) { return &c.lcm.tick_phase_step_s; }),
      name("lcm", "key_file",
           "shared key (32 bytes, not world-readable; relative to the config file) authenticating rig commands and "
           "states; empty: none",
           [](C& c) { return &c.lcm.key_file; }),
      // [device]: which rig
      name("device", "kind",
           "the rig: sim (the simulated arm), lcm (a rig over LCM) or t7 (a LabJack T7 over Modbus TCP)",
           [](C& c) { return &c.device.kind; }),
      name("device", "lcm", "lcm: the rig's LCM bus URL (empty: udpm://239.255.76.67:7667?ttl=0)",
           [](C& c) { return &c.device.lcm_url; }),
      name("device", "t7", "t7: the T7's address HOST[:PORT] (port 502 by default)",
           [](C& c) { return &c.device.t7_address; }),
      name("device", "rig_profile", "t7: the rig profile file (empty: the paper's rig)",
           [](C& c) { return &c.device.rig_profile; }),
      // [arm]: which simulated arm
      name("arm", "preset",
           "the simulated arm's chain: arm2 (shoulder, elbow) or arm3 (shoulder, elbow, wrist) of "
           "../shared/spec/multi-joint.md; empty: one joint, the [plant] arm",
           [](C& c) { return &c.arm.preset; }),
      // [rig_check]: the valve test of the first day (docs/rig-bring-up.md)
      number("rig_check", "vent_s", "s", "both outlets open before each valve's test (back to ambient)", pos(60.0),
             [](C& c) { return &c.rig_check.vent_s; }),
      number("rig_check", "fill_s", "s", "both inlets open before an outlet's test (air to let out)", pos(10.0),
             [](C& c) { return &c.rig_check.fill_s; }),
      number("rig_check", "valve_pulse_s", "s", "how long the valve under test opens, alone", pos(10.0),
             [](C& c) { return &c.rig_check.valve_pulse_s; }),
      number("rig_check", "min_change_bar", "bar",
             "a chamber moved: by at least this, and this much more than the other", pos(10.0),
             [](C& c) { return &c.rig_check.min_change_bar; }),
      number("rig_check", "timeout_tolerance_s", "s",
             "`rig check --device lcm`: the rig's command timeout, provoked, acts within [lcm] rig_timeout_s +- this",
             pos(60.0), [](C& c) { return &c.rig_check.timeout_tolerance_s; }),
      whole("rig_check", "valve_pulse_attempts",
            "a valve that moved nothing is pulsed again, up to this many pulses in all, before it is called dead",
            count(10), [](C& c) { return &c.rig_check.valve_pulse_attempts; }),
      whole("rig_check", "zero_readings", "`rig check --zero-angle` averages this many fresh readings, the arm at rest",
            count(1000000), [](C& c) { return &c.rig_check.zero_readings; }),
      number("t7", "response_timeout_s", "s", "one Modbus request to the T7 waits this long for its answer", pos(1.0),
             [](C& c) { return &c.t7.response_timeout_s; }),
      number("t7", "connect_timeout_s", "s",
             "looking up the T7's name, connecting to it and configuring it may take this long", pos(3600.0),
             [](C& c) { return &c.t7.connect_timeout_s; }),
      whole("t7", "watchdog_timeout_s", "the T7's own watchdog vents after this much silence (whole seconds)",
            count(3600), [](C& c) { return &c.t7.watchdog_timeout_s; }),
      number("t7", "command_timeout_s", "s", "the T7 link vents when the engine sends no command this long", pos(60.0),
             [](C& c) { return &c.t7.command_timeout_s; }),
  };
  const ParameterBinding fault = name("plant", "fault",
                                      "injected fault: none, sensor-dropout, stuck-inlet, supply-loss, nan-angle, "
                                      "pressure-spike, swapped-chambers, dead-inlet",
                                      [](C& c) { return &c.plant.fault; });
  const auto after_plant =
      std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.key == "fault_at_s"; });
  b.insert(after_plant, fault);
  // The laws the factory knows, named once there.
  const std::vector<std::string> laws = learning_law_names();
  std::string law_names;
  for (std::size_t i = 0; i < laws.size(); ++i)
    law_names += (i == 0 ? "" : i + 1 == laws.size() ? " or " : ", ") + laws[i];
  const ParameterBinding law = name("ilc", "law", "learning law: " + law_names, [](C& c) { return &c.ilc.law; });
  const auto first_ilc = std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.section == "ilc"; });
  const auto after_law = b.insert(first_ilc, law) + 1;
  b.insert(after_law,
           name("ilc", "joint_model",
                "several joints: the model of the norm-optimal update, coupled (the chain linearized stretched out), "
                "independent (each joint's own single-joint model) or identified ([identified_joint1..J], by bellows "
                "identify)",
                [](C& c) { return &c.ilc.joint_model; }));
  // [arm] joints and [arm_joint1] .. [arm_joint4]: a chain of its own keys, after [arm] preset.
  auto after_preset = std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.key == "preset"; }) + 1;
  after_preset = b.insert(after_preset, whole("arm", "joints",
                                              "a chain of its own keys: this many joints (2..4) from [arm_joint1] on; "
                                              "0: none ([arm] preset, or one joint)",
                                              Range{0.0, 4.0, false, false}, [](C& c) { return &c.arm.joints; })) +
                 1;
  after_preset = b.insert(after_preset, whole("arm", "gravity",
                                              "that chain: 1 in a vertical plane (gravity), 0 in the horizontal plane",
                                              Range{0.0, 1.0, false, false}, [](C& c) { return &c.arm.gravity; })) +
                 1;
  using Joint = ArmJointParameters;
  const auto joint_key = [](std::string key, std::string unit, std::string meaning, Range range,
                            double Joint::*member) {
    return std::make_tuple(std::move(key), std::move(unit), std::move(meaning), range, member);
  };
  const std::array joint_keys = {
      joint_key("mass_kg", "kg", "link mass m", pos(100.0), &Joint::mass_kg),
      joint_key("length_m", "m", "link length l, joint to the next joint", pos(10.0), &Joint::length_m),
      joint_key("center_of_mass_m", "m", "link centre of mass c, from the joint", upto(10.0), &Joint::center_of_mass_m),
      joint_key("inertia_kg_m2", "kg m^2", "link inertia I about its centre of mass", upto(100.0),
                &Joint::inertia_kg_m2),
      joint_key("tip_mass_kg", "kg", "point mass m_a at the link's end (the next joint's bellows)", upto(100.0),
                &Joint::tip_mass_kg),
      joint_key("stiffness_Nm_per_rad", "N m/rad", "joint stiffness K (the bellows' retraction)", pos(1.0e4),
                &Joint::stiffness_Nm_per_rad),
      joint_key("kappa_rad_per_bar", "rad/bar", "gain kappa: the torque per bar is K kappa", pos(100.0),
                &Joint::kappa_rad_per_bar),
      joint_key("omega0_straight_rad_per_s", "rad/s",
                "natural frequency w0 with the arm straight (damping 2 delta w0 M_ii)", pos(1000.0),
                &Joint::omega0_straight_rad_per_s),
      joint_key("damping_ratio", "", "damping ratio delta", upto(10.0), &Joint::damping_ratio),
      joint_key("bellows_scale", "", "the paper's bellows volume and valve conductance times this", pos(100.0),
                &Joint::bellows_scale),
  };
  for (std::size_t j = 0; j < ArmParameters{}.joint.size(); ++j) {
    const std::string section = "arm_joint" + std::to_string(j + 1);
    const std::string joint = "joint " + std::to_string(j + 1);
    for (const auto& [key, unit, meaning, range, member] : joint_keys) {
      after_preset =
          b.insert(after_preset, number(section, key, unit, "[arm] joints: " + joint + "'s " + meaning, range,
                                        [j, member = member](C& c) { return &(c.arm.joint[j].*member); })) +
          1;
    }
    // The guard's limit is every arm's (a preset's, a chain of its own keys, the one joint of [plant]).
    after_preset =
        b.insert(after_preset, number(section, "angle_limit_deg", "deg",
                                      "any arm: the engine's guard faults when " + joint +
                                          " goes beyond this angle; 0: [safety] angle_limit_deg",
                                      upto(180.0), [j](C& c) { return &c.safety.joint_angle_limit_deg[j]; })) +
        1;
  }
  // [identified_joint1] .. [identified_joint4]: the coupled model `bellows identify` fitted, after the chain's keys.
  using Row = IdentifiedJointRow;
  const auto row_key = [](std::string key, std::string unit, std::string meaning, std::array<double, 4> Row::*member) {
    return std::make_tuple(std::move(key), std::move(unit), std::move(meaning), member);
  };
  const std::array row_keys = {
      row_key("per_angle_j", "1/s^2", "acceleration per radian of joint ", &Row::per_angle_per_s2),
      row_key("per_velocity_j", "1/s", "acceleration per rad/s of joint ", &Row::per_velocity_per_s),
      row_key("per_bar_j", "rad/(s^2 bar)", "acceleration per bar of joint ", &Row::per_bar_rad_per_s2),
  };
  const char* row_unit_suffix[] = {"_per_s2", "_per_s", "_rad_per_s2"};
  for (std::size_t i = 0; i < IdentifiedArmParameters{}.joint.size(); ++i) {
    const std::string section = "identified_joint" + std::to_string(i + 1);
    for (std::size_t r = 0; r < row_keys.size(); ++r) {
      const auto& [key, unit, meaning, member] = row_keys[r];
      for (std::size_t k = 0; k < IdentifiedJointRow{}.per_angle_per_s2.size(); ++k) {
        after_preset = b.insert(after_preset,
                                number(section, key + std::to_string(k + 1) + row_unit_suffix[r], unit,
                                       "[ilc] joint_model = identified: joint " + std::to_string(i + 1) + "'s " +
                                           meaning + std::to_string(k + 1) + " (bellows identify)",
                                       between(-1e9, 1e9),
                                       [i, k, member = member](C& c) { return &(c.identified.joint[i].*member)[k]; })) +
                       1;
      }
    }
  }
  const ParameterBinding signal = name("identify", "signal", "excitation of the identification trial: chirp or steps",
                                       [](C& c) { return &c.identify.signal; });
  const auto first_identify =
      std::find_if(b.begin(), b.end(), [](const ParameterBinding& p) { return p.section == "identify"; });
  b.insert(first_identify, signal);
  return b;
}

std::string describe(const ParameterBinding& b) { return "[" + b.section + "] " + b.key; }

std::string format_number(double value) {
  std::ostringstream out;
  out << std::setprecision(12) << value;
  return out.str();
}

void check_below_nyquist(const char* key, double cutoff_hz, const TimingParameters& timing) {
  const double nyquist_hz = 0.5 / timing.sample_s();
  if (cutoff_hz >= nyquist_hz) {
    throw InputError(std::string("[ilc] ") + key + " = " + format_number(cutoff_hz) +
                     ": must be below the Nyquist frequency " + format_number(nyquist_hz) +
                     " Hz of the ILC sample time");
  }
}

}  // namespace

std::string Range::text() const {
  // Appended in place: GCC 12 warns falsely (-Wrestrict, its bug 105651) on a chain of rvalue +.
  std::string out(min_open ? "(" : "[");
  out += format_number(min);
  out += ", ";
  out += format_number(max);
  out += max_open ? ")" : "]";
  return out;
}

const std::vector<ParameterBinding>& parameter_bindings() {
  static const std::vector<ParameterBinding> bindings = make_bindings();
  return bindings;
}

const ParameterBinding* find_parameter(const std::string& section, const std::string& key) {
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.section == section && b.key == key) return &b;
  }
  return nullptr;
}

void check_parameter_value(const ParameterBinding& b, double value) {
  const std::string where = describe(b) + " = " + format_number(value);
  if (!std::isfinite(value)) throw InputError(where + ": must be a finite number in " + b.range.text());
  if (b.integer && value != std::floor(value))
    throw InputError(where + ": must be a whole number in " + b.range.text());
  if (!b.range.contains(value)) throw InputError(where + ": must be in " + b.range.text());
}

void validate_configuration(const Configuration& config) {
  Configuration copy = config;  // the bindings hand out pointers into a mutable configuration
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.text) continue;
    check_parameter_value(b, b.real ? *b.real(copy) : static_cast<double>(*b.integer(copy)));
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
  // Each joint's own limit obeys the same rules as [safety] angle_limit_deg: above every trajectory
  // (none may be built that crosses a guard), within the rig's range (the engine's guard acts first).
  for (std::size_t j = 0; j < config.safety.joint_angle_limit_deg.size(); ++j) {
    const double limit_deg = config.safety.joint_angle_limit_deg[j];
    if (limit_deg == 0.0) continue;
    const std::string key = "[arm_joint" + std::to_string(j + 1) + "] angle_limit_deg = " + format_number(limit_deg);
    if (config.trajectory.max_abs_angle_deg >= limit_deg) {
      throw InputError(key + ": must be above [trajectory] max_abs_angle_deg = " +
                       format_number(config.trajectory.max_abs_angle_deg));
    }
    if (limit_deg > config.lcm.rig_angle_limit_deg) {
      throw InputError(key + ": must not be above [lcm] rig_angle_limit_deg = " +
                       format_number(config.lcm.rig_angle_limit_deg) + ": the engine's guard acts first");
    }
  }
  if (config.device.kind != "sim" && config.device.kind != "lcm" && config.device.kind != "t7") {
    throw InputError("[device] kind = '" + config.device.kind + "': unknown device (known: sim, lcm, t7)");
  }
  if (!config.arm.preset.empty() &&
      std::find(kArmPresets.begin(), kArmPresets.end(), config.arm.preset) == kArmPresets.end()) {
    std::string known;
    for (std::string_view preset : kArmPresets) known += (known.empty() ? "" : ", ") + std::string(preset);
    throw InputError("[arm] preset = '" + config.arm.preset + "': unknown arm (known: " + known +
                     "; empty: one joint)");
  }
  if (config.arm.joints == 1)
    throw InputError("[arm] joints = 1: a chain has 2 to 4 joints (leave [arm] out for one joint)");
  if (config.arm.joints > 0 && !config.arm.preset.empty()) {
    throw InputError("[arm] preset and [arm] joints both name the arm: keep one");
  }
  if (config.arm.has_chain() && config.plant.fault != "none") {
    throw InputError("[plant] fault = '" + config.plant.fault +
                     "': the simulated arm of several joints ([arm]) injects no faults; leave [plant] fault at none");
  }
  if (config.lcm.seq_window > 1000000) {
    throw InputError("[lcm] seq_window = " + std::to_string(config.lcm.seq_window) + ": must be at most 1000000");
  }
  if (config.lcm.rig_pressure_margin_bar < config.safety.pressure_margin_bar) {
    throw InputError(
        "[lcm] rig_pressure_margin_bar must not be below [safety] pressure_margin_bar: the engine's guard acts first");
  }
  if (config.lcm.rig_angle_limit_deg < config.safety.angle_limit_deg || config.lcm.rig_angle_limit_deg > 180.0) {
    throw InputError("[lcm] rig_angle_limit_deg = " + format_number(config.lcm.rig_angle_limit_deg) +
                     ": must be in [[safety] angle_limit_deg, 180]: the engine's guard acts first");
  }
  if (config.safety.sensor_min_bar >= config.safety.sensor_max_bar) {
    throw InputError("[safety] sensor_min_bar must be below [safety] sensor_max_bar");
  }
  if (config.identify.chirp_start_hz >= config.identify.chirp_end_hz) {
    throw InputError("[identify] chirp_start_hz must be below [identify] chirp_end_hz");
  }
  if (config.identify.amplitude_deg >= config.identify.max_abs_angle_deg) {
    throw InputError("[identify] amplitude_deg must be below [identify] max_abs_angle_deg");
  }
  if (config.plant.integration_step_s > config.plant.pwm_period_s) {
    throw InputError("[plant] integration_step_s must not exceed [plant] pwm_period_s");
  }
  const std::vector<std::string> laws = learning_law_names();
  if (std::find(laws.begin(), laws.end(), config.ilc.law) == laws.end()) {
    std::string known;
    for (const std::string& law : laws) known += (known.empty() ? "" : ", ") + law;
    throw InputError("[ilc] law = '" + config.ilc.law + "': unknown learning law (known: " + known + ")");
  }
  if (std::find(kJointModels.begin(), kJointModels.end(), config.ilc.joint_model) == kJointModels.end()) {
    std::string known;
    for (const std::string_view model : kJointModels) known += (known.empty() ? "" : ", ") + std::string(model);
    throw InputError("[ilc] joint_model = '" + config.ilc.joint_model + "': unknown (known: " + known + ")");
  }
  validation_signal(config.identify.signal);  // throws for anything but chirp and steps
  // The Q-filters of the law in use; the other laws' keys may hold anything in range.
  if (config.ilc.law == "pd") check_below_nyquist("pd_q_cutoff_hz", config.ilc.pd_q_cutoff_hz, config.timing);
  if (config.ilc.law == "inverse")
    check_below_nyquist("inverse_q_cutoff_hz", config.ilc.inverse_q_cutoff_hz, config.timing);
  // The norm-optimal cost must be positive definite: the dense form factors P'MP + S + D'WD, the
  // Riccati forms also accept S = W = 0 with M > 0 (the plain inverse).
  const IlcParameters& ilc = config.ilc;
  const bool dense = ilc.law == "noilc-dense", riccati = ilc.law == "noilc" || ilc.law == "noilc-constrained";
  if ((dense && !(ilc.s + ilc.w > 0.0)) || (riccati && !(ilc.s + ilc.w > 0.0) && !(ilc.m > 0.0))) {
    throw InputError(std::string("[ilc] s, w") + (dense ? "" : " and m") + " are all 0: law '" + ilc.law +
                     "' needs a positive definite cost");
  }
  if (config.ilc.law == "noilc-constrained" && !(config.ilc.limit_margin_bar < config.controller.p_max_bar - ambient)) {
    throw InputError("[ilc] limit_margin_bar = " + format_number(config.ilc.limit_margin_bar) +
                     ": leaves no room below [controller] p_max_bar");
  }
  check_configuration_cost(config);
}

}  // namespace bellows
