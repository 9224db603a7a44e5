#include "devices/simulated_arm_chain.hpp"

#include <span>

namespace bellows {

SimulatedArmChain::SimulatedArmChain(const PneumaticChainParameters& parameters, std::uint64_t seed)
    : chain_(parameters, seed) {}

SensorReading SimulatedArmChain::read_sensors() {
  const PneumaticArmChain::Reading r = chain_.read_sensors();
  SensorReading out;
  out.time_s = r.time_s;
  out.joint_count = joints();
  for (int j = 0; j < joints(); ++j) {
    JointReading& joint = out.joint[static_cast<std::size_t>(j)];
    joint.angle_rad = r.angle_rad(j);
    joint.chamber_bar = r.chamber_bar[static_cast<std::size_t>(j)];
  }
  out.supply_bar = r.supply_bar;
  out.temperature_K = r.temperature_K;
  return out;
}

void SimulatedArmChain::write_valves(const ValveCommand& command) {
  if (command.joint_count != joints()) {
    vent();
    return;
  }
  for (int j = 0; j < joints(); ++j) {
    const JointValves& valves = command.joint[static_cast<std::size_t>(j)];
    duties_[static_cast<std::size_t>(j)] = BellowsDuties{valves.inlet_duty, valves.outlet_duty};
  }
  chain_.write_valves(std::span<const BellowsDuties>(duties_.data(), static_cast<std::size_t>(joints())));
}

void SimulatedArmChain::vent() { chain_.vent(); }

void SimulatedArmChain::advance(double dt_s) { chain_.advance(dt_s); }

}  // namespace bellows
