// Every physics and control number of the reference system, with the spec's defaults.
// The engine reads these; loading them from TOML is app/'s business (engine knows no files).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

namespace bellows {

/// Physical constants of air, shared by the plant and the controller's valve model.
struct GasParameters {
  double gas_constant_J_per_kgK = 287.05;
  double temperature_K = 293.15;
  double reference_density_kg_per_m3 = 1.185;  // rho0 of ISO 6358
  double ambient_bar = 1.01325;                // p0
};

/// The simulated arm (spec section 4): the truth the controllers do not know exactly.
struct PlantParameters {
  double kappa_rad_per_bar = 7.91;
  double omega0_rad_per_s = 14.14;
  double damping = 0.31;
  double volume_l = 0.45;                        // V0, average volume of one bellows
  double volume_gain_per_rad = 0.35;             // beta: V = V0 (1 +- beta alpha)
  double valve_conductance_m3_per_sPa = 3.0e-9;  // C of one valve
  double valve_critical_ratio = 0.35;            // b
  int valves_per_port = 2;                       // 2 inlets and 2 outlets per actuator
  double creep_gain = 0.25;                      // c_z
  double creep_tau_s = 0.8;                      // tau_z
  double supply_bar = 3.0;                       // absolute supply pressure
  double encoder_resolution_deg = 0.1;
  double pressure_noise_bar = 0.5e-3;  // sigma of the Gaussian pressure-sensor noise
  double hard_stop_deg = 95.0;
  double hard_stop_stiffness_per_s2 = 1.0e4;  // stiff spring beyond the stop (angular accel per rad)
  double hard_stop_damping_per_s = 140.0;
  double integration_step_s = 1.0e-4;  // fixed internal step
  double pwm_period_s = 1.0 / 200.0;
  // Fault injection for tests and drills: which fault, at what device time.
  std::string fault = "none";
  double fault_at_s = 0.0;
  double spike_bar = 1.0;  // size of a pressure-sensor spike
  double spike_s = 0.01;   // its duration
  GasParameters gas{};
};

/// The nominal model (spec section 2) that the ILC and the diagnostics use.
struct ModelParameters {
  double kappa_rad_per_bar = 7.91;
  double omega0_rad_per_s = 14.14;
  double damping = 0.31;
  // beta of the bellows' volumes V = V0 (1 +- beta alpha). The pressure loop does not compensate the
  // volume change, so moving the arm changes dp against the motion ("bounce-back"): extra damping
  // that the convergence prediction includes (docs/learning-laws.md).
  double volume_gain_per_rad = 0.35;
};

/// Controllers (spec section 3).
struct ControllerParameters {
  // PID with feed-forward at the ILC rate, normalized units (angle/pi, pressure/1 bar).
  double k_ff = 0.4;
  double k_p = 0.3;
  double k_i_per_s = 0.3;
  double k_d_s = 0.01;
  double integrator_limit_bar = 0.4;  // anti-windup bound on k_i * integral(e)
  // Pressure controllers at the tick rate.
  double tau_p_s = 1.0 / 50.0;
  double p_max_bar = 1.4;
  int filter_samples = 4;  // moving-average length on the measured pressure
  // The controller's own valve model (nominal data sheet values, not the plant's truth).
  double valve_conductance_m3_per_sPa = 3.0e-9;
  double valve_critical_ratio = 0.35;
  int valves_per_port = 2;
  double volume_l = 0.45;
  GasParameters gas{};
};

/// The learning law and its parameters. Norm-optimal weights (spec section 5): M = m I, S = s I, W = w I.
struct IlcParameters {
  std::string law = "noilc";  // which learning law runs between trials (engine/config/learning_law_factory)
  double m = 1.0;
  double s = 0.1;
  double w = 2.0e-5;
  // noilc-constrained: ADMM on the pressure-limit bounds
  double admm_rho = 1.0;  // penalty of the ADMM splitting (same units as s)
  int admm_max_iterations = 2000;
  double admm_tolerance = 1.0e-7;  // bar, on the primal and dual residuals
  double limit_margin_bar = 0.0;   // keep u_pid + u_ilc this far inside the pressure limits
  // After an input sample whose set point sat on the pressure limit in the last trial, the errors of
  // this long are not weighted: the valves' flow limit, not the correction, shaped them, and the
  // nominal model mispredicts them (docs/learning-laws.md). 0 = the plain bounded optimum.
  double limit_recovery_s = 0.08;
  // pd: u_{j+1} = Q[u_j + k_p e + k_d de/dt]
  // (defaults: the best tuning on the paper scenario among those predicted to converge on the
  // nominal model, see docs/learning-laws.md)
  double pd_kp = 0.3;
  double pd_kd_s = 0.01;
  double pd_q_cutoff_hz = 3.5;
  // gradient: u_{j+1} = u_j + (step / ||P||^2) P' e
  double gradient_step = 1.0;
  // inverse: u_{j+1} = Q[u_j + gain P^-1 e]
  double inverse_gain = 0.3;
  double inverse_q_cutoff_hz = 8.0;
  // convergence prediction before a run: grid of kappa and omega0 errors
  double prediction_model_error = 0.3;  // +-30 %
  int prediction_grid_points = 5;       // per parameter
  // (Last, so that aggregate initializers of the fields above keep their order.) Several joints: the model of the
  // J-joint norm-optimal update (engine/config/joint_learning_factory): "coupled" (the chain linearized stretched out)
  // or "independent" (each joint's own model).
  std::string joint_model = "coupled";
  // noilc-learned: norm-optimal ILC on the closed-loop model refined from the session's trials
  // (engine/learning/noilc_learned; defaults tuned on the paper, steps and sine trajectories).
  double learned_s = 0.1;           // S = s I of its update (M and W are m and w above)
  double learned_forgetting = 1.0;  // weight of an older trial's data per trial in the refit (1: all trials count)
  double learned_ridge = 1e-3;      // ridge of the refit, relative to the data's scale
  double learned_guard = 0.25;      // a trial whose ||e||^2 rose by more than this over the best falls back
  int learned_taps = 8;             // FIR taps of the learned correction per joint
  // Several joints only (one joint ignores both): 1 lets the refit model plan an update when it predicted the last
  // trial better than the prior (0: the prior plans every update; the refit still learns and reports), and 1 zeroes
  // the limit-shaped errors in the update as one joint does (0: only the refit leaves them out). 0 measured better on
  // arm2/paper2 and arm3/paper3 (docs/learning-laws.md).
  int learned_joints_refit_plans = 0;
  int learned_joints_zero_limited = 0;
  // Several joints only: a trial within this fraction above the best trial's ||e||^2 counts as a descent (planned
  // from, the step kept) instead of replaying a halved step from the best trial; at most learned_guard.
  double learned_joints_descent_slack = 0.05;
};

/// Model identification (`bellows identify`): the PID tracks a bounded excitation while the arm's
/// angle and chamber pressures are recorded; kappa, omega0 and delta are fitted to them.
struct IdentificationParameters {
  std::string signal = "chirp";     // "chirp" or "steps"; the other one is the held-out validation trial
  double amplitude_deg = 20.0;      // excitation amplitude of the reference angle
  double max_abs_angle_deg = 60.0;  // the trial is aborted (valves vented) beyond this angle
  double duration_s = 20.0;
  double chirp_start_hz = 0.1;
  double chirp_end_hz = 3.0;
  double step_hold_s = 1.0;  // time between steps of the step sequence
};

/// Timing of the loop: the tick (pressure controllers, PWM) and the ILC sample (PID, ILC).
struct TimingParameters {
  double tick_s = 1.0 / 200.0;
  int ticks_per_sample = 4;  // 200 Hz / 50 Hz
  double settle_s = 1.0;     // hold at the trajectory's start before each trial
  // After settle_s, hold on while a joint is farther than settle_tolerance_deg from its first set
  // point, up to settle_max_s in all (no longer than settle_s when settle_max_s <= settle_s).
  double settle_max_s = 0.0;
  double settle_tolerance_deg = 0.5;
  double longest_settle_s() const { return settle_max_s > settle_s ? settle_max_s : settle_s; }
  double sample_s() const { return tick_s * ticks_per_sample; }
  /// Whether telemetry recorded at `other`'s ticks has this timing's shape (tick_s x ticks_per_sample
  /// rows a sample): a session is only continued at the ticks it was recorded at.
  bool same_ticks(const TimingParameters& other) const {
    return std::abs(tick_s - other.tick_s) <= 1e-12 && ticks_per_sample == other.ticks_per_sample;
  }
};

/// The LCM rig protocol (docs/lcm-protocol.md); the engine itself knows no LCM.
struct LcmParameters {
  double rig_timeout_s = 0.05;            // a rig vents by itself when commands stop for this long
  double connect_timeout_s = 5.0;         // `run --device lcm` waits this long for a rig to answer
  double lockstep_timeout_s = 1.0;        // `run --clock lockstep`: a tick waits this long for the rig's answer
  std::string key_file;                   // shared key authenticating commands and states ("": none)
  int seq_window = 100;                   // largest step a rig accepts between a session's sequence numbers
  double rig_pressure_margin_bar = 0.35;  // a rig vents a chamber above [controller] p_max_bar + this
  double rig_angle_limit_deg = 100.0;     // a rig vents and drops its session beyond this angle
  double tick_phase_lead = 0.5;     // wall clock: the engine reads each rig state this share of a tick after it arrives
  double tick_phase_step_s = 1e-4;  // largest shift of one tick's deadline towards that phase; 0: no lock
};

/// Which rig the commands drive (`[device]`; `--device`, `--lcm`, `--t7`, `--rig-profile` override
/// it). The engine never looks at it: app/device_factory opens the device it names.
struct DeviceParameters {
  std::string kind = "sim";  // sim (the simulated arm in-process), lcm (a rig over LCM), t7 (a LabJack T7)
  std::string lcm_url;       // the rig's LCM bus; empty: the default udpm URL
  std::string t7_address;    // HOST[:PORT] of the T7 (Modbus TCP, port 502 by default)
  std::string rig_profile;   // the rig profile file (t7); empty: the shipped profile of the paper's rig
};

/// Which simulated arm (`[arm]`): the single joint of [plant], or a chain of several joints from
/// ../shared/spec/multi-joint.md (engine/model/pneumatic_arm_chain_parameters: pneumatic_chain_of).
/// One link of a chain given by its own keys (`[arm_joint1]` .. `[arm_joint4]`), in the spec's
/// terms (multi-joint.md section 1). Each joint defaults to a paper-type joint (the elbow of `arm2`).
struct ArmJointParameters {
  double mass_kg = 0.10;                     // m_i
  double length_m = 0.30;                    // l_i, joint to the next joint
  double center_of_mass_m = 0.15;            // c_i, from the joint
  double inertia_kg_m2 = 7.5e-4;             // I_i, about the link's centre of mass
  double tip_mass_kg = 0.0;                  // m_a,i, at the distal end (the next joint's bellows)
  double stiffness_Nm_per_rad = 0.60;        // K_i
  double kappa_rad_per_bar = 7.91;           // torque per bar K_i kappa_i
  double omega0_straight_rad_per_s = 14.14;  // w0 with the arm straight (damping D_i = 2 delta w0 M_ii(0))
  double damping_ratio = 0.31;               // delta
  double bellows_scale = 1.0;                // the paper's bellows volume and valve conductance times this
};

struct ArmParameters {
  std::string preset;                         // "" (absent): one joint or the chain's own keys; else one of kArmPresets
  int joints = 0;                             // a chain of the [arm_jointK] keys (2..kMaxJoints joints); 0: none
  int gravity = 1;                            // that chain: 1 in a vertical plane, 0 in the horizontal plane
  std::array<ArmJointParameters, 4> joint{};  // [arm_joint1] .. [arm_joint4] (kMaxJoints)

  /// Whether the arm is a chain of several joints (a preset or its own keys), not [plant]'s joint.
  bool has_chain() const { return !preset.empty() || joints > 0; }
  /// "arm2", or "[arm] joints = 3" for a chain of its own keys; "" for one joint.
  std::string name() const {
    return !preset.empty() ? preset : joints > 0 ? "[arm] joints = " + std::to_string(joints) : "";
  }
};

/// The coupled model `bellows identify` fitted on an arm of several joints (`[identified_joint1]` ..
/// `[identified_joint4]`, written by `identify --write-model`; engine/model/coupled_joint_dynamics): joint
/// i's row of q_ddot = per_angle q + per_velocity q_dot + per_bar dp, entry k for joint k + 1.
/// `[ilc] joint_model = "identified"` learns with it. All zero: none identified.
struct IdentifiedJointRow {
  std::array<double, 4> per_angle_per_s2{};    // d q_ddot_i / d q_k
  std::array<double, 4> per_velocity_per_s{};  // d q_ddot_i / d q_dot_k
  std::array<double, 4> per_bar_rad_per_s2{};  // d q_ddot_i / d dp_k (rad/s^2 per bar)
};
struct IdentifiedArmParameters {
  std::array<IdentifiedJointRow, 4> joint{};  // (kMaxJoints)
};

/// The chains engine/model/arm_chain_parameters knows by name (chain_preset).
inline constexpr std::array<std::string_view, 2> kArmPresets = {"arm2", "arm3"};
/// The `[ilc] joint_model` names: how the learning of several joints models the arm.
inline constexpr std::array<std::string_view, 3> kJointModels = {"coupled", "independent", "identified"};

/// The valve test of the first day at the bench (`bellows rig check`, the console's Rig screen):
/// each valve opened alone for `valve_pulse_s`, the chamber pressures compared before and after.
struct RigCheckParameters {
  double vent_s = 1.0;           // both outlets open before each valve, so every test starts at ambient
  double fill_s = 0.03;          // both inlets open before an outlet's test: air for the outlet to let out
  double valve_pulse_s = 0.03;   // the valve under test alone, fully open
  double min_change_bar = 0.01;  // a chamber "moved": at least this much, and this much more than the other
  // A valve that moved nothing is pulsed again (vented first), up to this many pulses in all: a link
  // or a host that held the command back for the pulse moves nothing once, a dead valve every time.
  int valve_pulse_attempts = 2;
  int zero_readings = 20;  // `--zero-angle` averages this many fresh readings (0.1 s at 200 Hz), the arm at rest
  // `rig check --device lcm`: the rig's command timeout, provoked, must act within [lcm] rig_timeout_s
  // +- this (its state period, the transport and both hosts' scheduling)
  double timeout_tolerance_s = 0.025;
};

/// A LabJack T7 over Modbus TCP (docs/labjack-t7.md); the engine itself knows no Modbus.
struct T7Parameters {
  double response_timeout_s = 0.004;  // one Modbus request waits this long for its answer (under a tick)
  double connect_timeout_s = 2.0;     // opening the TCP connection and configuring the T7
  int watchdog_timeout_s = 1;         // the T7 vents by itself after this much silence (whole s, >= 1)
  double command_timeout_s = 0.05;    // the I/O thread vents when the engine sends no command this long
};

}  // namespace bellows
