// The simulated arm of J joints with its bellows (../shared/spec/multi-joint.md): the chain's
// mechanics (engine/model/arm_chain, the rigid-body coupling, gravity, creep and stops) driven by each
// joint's bellows pair exactly as the single-joint simulated arm's (engine/model/bellows_pneumatics: the
// switching valves' PWM timing, ISO 6358 flow, each joint's chamber volumes depending on its own
// angle with the full gas law), with each joint's quantized encoder, noisy chamber pressure sensors and
// one supply. With one joint, no gravity and the plant's parameters (pneumatic_chain_of) it is the
// single-joint simulated arm (devices/simulated_arm) to rounding: the same inputs give the same
// readings.
//
// One RK4 integration of all 5J states (angle, rate, creep and two chamber pressures per joint) at
// the fixed internal step, the steps ending on every valve's switching edges. Deterministic for a
// seed; state() written back with set_state() resumes bit for bit. Parameters are set up once in
// the constructor; the step allocates nothing (fixed-capacity vectors). devices/simulated_arm_chain
// puts it behind the engine's Device interface.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "engine/model/arm_chain.hpp"
#include "engine/model/bellows_pneumatics.hpp"
#include "engine/base/gaussian_noise.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"

namespace bellows {

class PneumaticArmChain {
 public:
  using ChamberPressures = std::array<double, 2>;  // A (index 0) and B (index 1)

  /// Everything that evolves: physics, the PWM period in progress and the noise generator.
  struct State {
    double time_s = 0.0;
    JointVector angle_rad, velocity_rad_per_s, creep_rad;   // q, q_dot, z
    std::array<ChamberPressures, kMaxJoints> chamber_Pa{};  // per joint
    double pwm_phase_s = 0.0;                               // time since the current PWM period began
    std::array<BellowsDuties, kMaxJoints> duties{};         // per joint, for the current period
    GaussianNoise::State noise{};
  };

  /// One reading of every sensor.
  struct Reading {
    double time_s = 0.0;
    JointVector angle_rad;                                   // each joint's encoder, quantized
    std::array<ChamberPressures, kMaxJoints> chamber_bar{};  // absolute, noisy
    double supply_bar = 0.0;                                 // absolute, noisy
    double temperature_K = 0.0;
  };

  /// Validates (validate_pneumatic_chain, InputError); starts at rest, stretched out, chambers at
  /// ambient, valves vented.
  explicit PneumaticArmChain(const PneumaticChainParameters& parameters, std::uint64_t seed = 1);

  int joints() const { return mechanics_.joints(); }
  const PneumaticChainParameters& parameters() const { return parameters_; }
  /// The chain's mechanics (its rigid-body terms, inertias, holding pressures); its own state is unused.
  const ArmChain& mechanics() const { return mechanics_; }

  /// Every sensor: per joint the quantized angle and both chambers' pressures, then the supply; the
  /// noise is drawn in that order (joint 1 A, B, joint 2 A, B, ..., supply).
  Reading read_sensors();
  /// The duties of each joint's valves for the coming PWM period (one entry per joint, else
  /// InputError), clamped to [0, 1]; a non-finite inlet duty closes the inlet, a non-finite outlet
  /// duty opens the outlet. A new command starts a new PWM period.
  void write_valves(std::span<const BellowsDuties> duties);
  /// Every inlet closed, every outlet open.
  void vent();
  /// Lets dt_s of physics pass.
  void advance(double dt_s);

  State state() const;
  /// Throws InputError when the angle, rate and creep vectors do not have joints() entries.
  void set_state(const State& state);

  double supply_Pa() const { return supply_Pa_; }
  void set_supply_bar(double supply_bar) { supply_Pa_ = supply_bar * 1e5; }
  /// Volume of joint `joint`'s chamber `chamber` (0 = A) at its current angle (m^3).
  double chamber_volume_m3(int joint, int chamber) const;
  /// Air mass in joint `joint`'s two chambers (kg).
  double air_mass_kg(int joint) const;

 private:
  template <int J>
  void advance_fixed(double dt_s);

  PneumaticChainParameters parameters_;
  ArmChain mechanics_;
  std::array<BellowsPneumatics, kMaxJoints> bellows_{};
  double supply_Pa_;
  State state_;
  GaussianNoise noise_;
};

}  // namespace bellows
