// The simulated arm of J joints (engine/model/pneumatic_arm_chain, ../shared/spec/multi-joint.md) behind the
// engine's Device interface: readings with joint_count J (each joint's encoder and chambers, one
// supply), commands of J joints' valves. In process, so its time follows the engine's ticks. A
// command for another joint count is meant for another arm: every joint is vented, as the
// single-joint simulated arm does. With one joint (pneumatic_chain_of(plant)) it reads as
// devices/simulated_arm to rounding. The chain's own Reading and duties stay its own (its tests and
// benchmark use them); this maps them, allocation-free.
#pragma once

#include <array>
#include <cstdint>

#include "engine/control/device.hpp"
#include "engine/model/pneumatic_arm_chain.hpp"

namespace bellows {

class SimulatedArmChain final : public Device {
 public:
  /// Throws InputError for parameters the chain cannot simulate (validate_pneumatic_chain).
  explicit SimulatedArmChain(const PneumaticChainParameters& parameters, std::uint64_t seed = 1);

  SensorReading read_sensors() override;
  void write_valves(const ValveCommand& command) override;
  void vent() override;
  void advance(double dt_s) override;
  bool time_follows_ticks() const override { return true; }  // in-process: physics advances per tick
  const char* name() const override { return "sim"; }

  int joints() const { return chain_.joints(); }
  /// The simulated chain itself: its state (to save and resume), volumes, air masses, supply.
  PneumaticArmChain& chain() { return chain_; }
  const PneumaticArmChain& chain() const { return chain_; }

 private:
  PneumaticArmChain chain_;
  std::array<BellowsDuties, kMaxJoints> duties_{};  // the command being mapped (no allocation)
};

}  // namespace bellows
