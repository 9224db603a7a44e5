#include "engine/model/pneumatic_arm_chain_parameters.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "engine/base/errors.hpp"

namespace bellows {

PneumaticChainParameters pneumatic_chain_preset(std::string_view name) {
  PneumaticChainParameters parameters;
  parameters.chain = chain_preset(name);
  // multi-joint.md section 2: "the shoulder carries it, with bellows of twice the volume (0.9 L) and
  // twice the valve conductance per chamber"; the elbow and wrist are paper-type joints.
  BellowsParameters& shoulder = parameters.bellows[0];
  shoulder.volume_l = 2.0 * BellowsParameters{}.volume_l;
  shoulder.valve_conductance_m3_per_sPa = 2.0 * BellowsParameters{}.valve_conductance_m3_per_sPa;
  return parameters;
}

PneumaticChainParameters pneumatic_chain_of(const PlantParameters& plant) {
  PneumaticChainParameters parameters;
  ChainParameters& chain = parameters.chain;
  chain.joints = 1;
  chain.gravity = false;
  ChainLink& link = chain.links[0];
  // Only the joint's inertia matters (no gravity): K = w0^2 I, any K; the paper's elbow's.
  link.stiffness_Nm_per_rad = 0.60;
  link.inertia_kg_m2 = link.stiffness_Nm_per_rad / (plant.omega0_rad_per_s * plant.omega0_rad_per_s);
  link.kappa_rad_per_bar = plant.kappa_rad_per_bar;
  link.omega0_straight_rad_per_s = plant.omega0_rad_per_s;
  link.damping_ratio = plant.damping;
  link.creep_gain = plant.creep_gain;
  link.creep_tau_s = plant.creep_tau_s;
  link.hard_stop_deg = plant.hard_stop_deg;
  chain.hard_stop_stiffness_per_s2 = plant.hard_stop_stiffness_per_s2;
  chain.hard_stop_damping_per_s = plant.hard_stop_damping_per_s;
  chain.integration_step_s = plant.integration_step_s;
  parameters.bellows[0] = bellows_of(plant);
  parameters.supply_bar = plant.supply_bar;
  parameters.encoder_resolution_deg = plant.encoder_resolution_deg;
  parameters.pressure_noise_bar = plant.pressure_noise_bar;
  parameters.pwm_period_s = plant.pwm_period_s;
  parameters.gas = plant.gas;
  return parameters;
}

PneumaticChainParameters pneumatic_chain_of(const PlantParameters& plant, const ArmParameters& arm) {
  if (!arm.has_chain()) return pneumatic_chain_of(plant);
  PneumaticChainParameters parameters;
  if (!arm.preset.empty()) {
    parameters = pneumatic_chain_preset(arm.preset);
  } else {
    parameters.chain = chain_of(arm);
    for (int j = 0; j < arm.joints; ++j) {
      const double scale = arm.joint[static_cast<std::size_t>(j)].bellows_scale;
      BellowsParameters& bellows = parameters.bellows[static_cast<std::size_t>(j)];
      bellows.volume_l *= scale;
      bellows.valve_conductance_m3_per_sPa *= scale;
    }
  }
  const PneumaticChainParameters shared = pneumatic_chain_of(plant);
  parameters.supply_bar = shared.supply_bar;
  parameters.encoder_resolution_deg = shared.encoder_resolution_deg;
  parameters.pressure_noise_bar = shared.pressure_noise_bar;
  parameters.pwm_period_s = shared.pwm_period_s;
  parameters.gas = shared.gas;
  parameters.chain.integration_step_s = shared.chain.integration_step_s;
  parameters.chain.hard_stop_stiffness_per_s2 = shared.chain.hard_stop_stiffness_per_s2;
  parameters.chain.hard_stop_damping_per_s = shared.chain.hard_stop_damping_per_s;
  return parameters;
}

void validate_pneumatic_chain(const PneumaticChainParameters& parameters) {
  validate_chain(parameters.chain);
  auto check = [](bool ok, int joint, const char* what, double value) {
    if (!ok) throw InputError("arm joint " + std::to_string(joint + 1) + ": " + what + " = " + std::to_string(value));
  };
  for (int i = 0; i < parameters.chain.joints; ++i) {
    const BellowsParameters& b = parameters.bellows[static_cast<std::size_t>(i)];
    check(b.volume_l > 0.0 && std::isfinite(b.volume_l), i, "volume_l must be > 0", b.volume_l);
    check(b.valve_conductance_m3_per_sPa > 0.0 && std::isfinite(b.valve_conductance_m3_per_sPa), i,
          "valve_conductance_m3_per_sPa must be > 0", b.valve_conductance_m3_per_sPa);
    check(b.valve_critical_ratio >= 0.0 && b.valve_critical_ratio < 1.0, i, "valve_critical_ratio must be in [0, 1)",
          b.valve_critical_ratio);
    check(b.valves_per_port >= 1, i, "valves_per_port must be >= 1", b.valves_per_port);
    const double reach_rad =
        1.5 * parameters.chain.links[static_cast<std::size_t>(i)].hard_stop_deg * std::numbers::pi / 180.0;
    check(std::isfinite(b.volume_gain_per_rad) && std::abs(b.volume_gain_per_rad) * reach_rad < 1.0, i,
          "volume_gain_per_rad empties a chamber within 1.5 x the stops", b.volume_gain_per_rad);
  }
  const GasParameters& gas = parameters.gas;
  const bool ok = parameters.supply_bar > 0.0 && std::isfinite(parameters.supply_bar) &&
                  parameters.pwm_period_s > 0.0 && std::isfinite(parameters.pwm_period_s) &&
                  parameters.encoder_resolution_deg >= 0.0 && parameters.pressure_noise_bar >= 0.0 &&
                  gas.gas_constant_J_per_kgK > 0.0 && gas.temperature_K > 0.0 &&
                  gas.reference_density_kg_per_m3 > 0.0 && gas.ambient_bar > 0.0;
  if (!ok) {
    throw InputError(
        "arm: supply_bar, pwm_period_s and the gas constants must be > 0, the encoder resolution and "
        "pressure noise >= 0");
  }
}

}  // namespace bellows
