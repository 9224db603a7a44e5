// A drill for rig bring-up (`bellows io-sim --swapped-chambers`): the arm with the tubes of
// chambers A and B swapped at every joint, so that each valve command drives the other chamber.
// The arm then runs away from every set point, as on a rig whose hoses or valve lines are crossed;
// `bellows rig check --device lcm` must name it, and a run must end with the rig's own trip.
#pragma once

#include <utility>

#include "engine/control/device.hpp"

namespace bellows {

class SwappedChambers final : public Device {
 public:
  explicit SwappedChambers(Device& arm) : arm_(arm) {}
  SensorReading read_sensors() override { return arm_.read_sensors(); }
  void write_valves(const ValveCommand& command) override {
    ValveCommand crossed = command;
    for (JointValves& j : crossed.joint) {
      std::swap(j.inlet_duty[0], j.inlet_duty[1]);
      std::swap(j.outlet_duty[0], j.outlet_duty[1]);
    }
    arm_.write_valves(crossed);
  }
  void vent() override { arm_.vent(); }
  void advance(double dt_s) override { arm_.advance(dt_s); }
  bool time_follows_ticks() const override { return arm_.time_follows_ticks(); }
  const char* name() const override { return arm_.name(); }

 private:
  Device& arm_;
};

}  // namespace bellows
