// The parameters of the simulated J-joint arm with its bellows (../shared/spec/multi-joint.md): the
// chain's mechanics (engine/model/arm_chain_parameters) plus, per joint, the single-joint arm's bellows and
// valves (reference-system.md section 4), and the supply, PWM and sensors they share.
#pragma once

#include <array>
#include <string_view>

#include "engine/model/arm_chain_parameters.hpp"
#include "engine/model/bellows_pneumatics.hpp"
#include "engine/base/parameters.hpp"

namespace bellows {

struct PneumaticChainParameters {
  ChainParameters chain;
  std::array<BellowsParameters, kMaxJoints> bellows{};  // per joint; the paper's bellows by default
  double supply_bar = 3.0;                              // absolute, one supply for every joint
  double encoder_resolution_deg = 0.1;                  // every joint's encoder
  double pressure_noise_bar = 0.5e-3;                   // sigma of every pressure sensor's Gaussian noise
  double pwm_period_s = 1.0 / 200.0;                    // every valve's PWM period
  GasParameters gas{};
};

/// "arm2" or "arm3" (chain_preset) with the spec's bellows: the shoulder's of twice the volume (0.9 L)
/// and twice the valve conductance per chamber, the other joints the paper's. InputError otherwise.
PneumaticChainParameters pneumatic_chain_preset(std::string_view name);

/// The single-joint simulated arm (PlantParameters) as a chain of one joint: no gravity, the link's
/// inertia about the joint K / w0^2, damping, creep, stops, bellows, valves, supply, sensors, PWM and
/// integration step the plant's. Fault settings are not part of the chain.
PneumaticChainParameters pneumatic_chain_of(const PlantParameters& plant);

/// The simulated arm `[arm]` names: one joint gives pneumatic_chain_of(plant); a preset gives its
/// links and bellows (a chain of its own keys: its links, each joint the paper's bellows times its
/// bellows_scale) with [plant]'s supply, sensors, PWM period, gas, integration step and hard-stop
/// stiffness and damping. InputError for an unknown preset.
PneumaticChainParameters pneumatic_chain_of(const PlantParameters& plant, const ArmParameters& arm);

/// validate_chain, then per joint a positive finite bellows volume, conductance and valve count, a
/// critical ratio in [0, 1), |beta| small enough that no chamber empties within 1.5 x the joint's
/// stops; a positive supply, PWM period and gas; a non-negative encoder resolution and noise. Throws
/// one InputError naming the joint and the value.
void validate_pneumatic_chain(const PneumaticChainParameters& parameters);

}  // namespace bellows
